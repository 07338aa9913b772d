"""The public API's hints, as a user's type checker reads them (the package ships
py.typed). ``make lint`` type-checks tests/typecheck/user_api.py against them with mypy; here
the hints are checked to exist at all (a parameter without one is ``Any`` to a checker, and
mypy's strict mode does not report a call to a partly hinted function), and the one
runtime change they needed, ``SampledTrajectory``'s written-out constructor, is checked to
behave as the dataclass's did."""

from __future__ import annotations

import dataclasses
import inspect
import warnings

import numpy as np
import pytest

import ddwmmr
from ddwmmr import ParameterError, SampledTrajectory

#: Wave samples of docs/api.md, as lists (the docs' way) and as arrays.
TIMES = [0.0, 5.0, 10.0, 15.0]
POINTS = [[0, 0], [1, 0.2], [2, 0], [3, -0.2]]


def unhinted(function: object) -> list[str]:
    """The parameters of ``function`` (and its return) that have no annotation."""
    signature = inspect.signature(function)  # type: ignore[arg-type]
    missing = [
        name
        for name, p in signature.parameters.items()
        if name not in ("self", "cls") and p.annotation is inspect.Parameter.empty
    ]
    if signature.return_annotation is inspect.Signature.empty:
        missing.append("return")
    return missing


def public_callables() -> dict[str, object]:
    """Every public function of the package's top level, and every public method (and the
    constructor) of its public classes, inherited ones of the package included, by dotted
    name."""
    found: dict[str, object] = {}
    for name in ddwmmr.__all__:
        value = getattr(ddwmmr, name)
        if inspect.isfunction(value):
            found[name] = value
        elif inspect.isclass(value) and not issubclass(value, Exception):
            own = [k for k in reversed(value.__mro__) if k.__module__.startswith("ddwmmr")]
            members = {m: a for klass in own for m, a in vars(klass).items()}
            for member, attribute in members.items():
                if isinstance(attribute, classmethod | staticmethod):
                    attribute = attribute.__func__
                public = not member.startswith("_") or member == "__init__"
                if public and inspect.isfunction(attribute):
                    found[f"{name}.{member}"] = attribute
    return found


def test_every_public_function_and_method_is_hinted():
    missing = {name: m for name, f in public_callables().items() if (m := unhinted(f))}
    assert missing == {}
    assert {"Robot.fk", "Robot.stability", "load_trajectory", "simulate"} <= set(public_callables())


def test_sampled_trajectory_takes_array_likes_in_its_hints():
    parameters = inspect.signature(SampledTrajectory).parameters
    assert list(parameters) == ["times", "points", "name"]
    assert parameters["times"].annotation == "npt.ArrayLike"
    assert parameters["points"].annotation == "SampleRows"
    assert parameters["name"].default == "sampled"


@pytest.mark.parametrize("convert", [list, np.array], ids=["lists", "arrays"])
def test_sampled_trajectory_stores_the_checked_float_arrays(convert):
    samples = SampledTrajectory(convert(TIMES), convert(POINTS), name="wave")
    assert samples.times.dtype == samples.points.dtype == np.float64
    np.testing.assert_array_equal(samples.times, TIMES)
    np.testing.assert_array_equal(samples.points, np.array(POINTS, dtype=float))
    assert samples.name == "wave" and samples.duration == 15.0
    np.testing.assert_allclose(samples.pose(5.0)[:2], [1.0, 0.2], rtol=0, atol=1e-12)


def test_sampled_trajectory_is_still_the_same_dataclass():
    samples = SampledTrajectory(times=TIMES, points=POINTS, name="wave")
    names = [f.name for f in dataclasses.fields(samples) if f.init]
    assert names == ["times", "points", "name"]
    renamed = dataclasses.replace(samples, name="again")
    assert renamed.name == "again" and renamed.samples == 3
    np.testing.assert_array_equal(renamed.points, samples.points)
    assert repr(samples).startswith("SampledTrajectory(times=array([ 0.,  5., 10., 15.])")
    with pytest.raises(dataclasses.FrozenInstanceError):
        samples.name = "changed"  # type: ignore[misc]


def test_sampled_trajectory_refuses_as_before():
    with pytest.raises(ParameterError, match="need at least 3 rows"):
        SampledTrajectory([0.0, 1.0], [[0, 0], [1, 0]])
    with pytest.raises(ParameterError, match="points must be"):
        SampledTrajectory(TIMES, [[0, 0, 0, 0]] * 4)


def test_the_heading_warning_still_names_the_caller():
    """The constructor adds no frame: the degrees warning points at the line that built
    the trajectory (the first frame outside the package)."""
    times = np.linspace(0.0, 10.0, 11)
    points = np.column_stack([times * 0.1, np.zeros(11), np.linspace(0.0, 90.0, 11)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        SampledTrajectory(times, points)
    assert len(caught) == 1 and "degrees" in str(caught[0].message)
    assert caught[0].filename == __file__
