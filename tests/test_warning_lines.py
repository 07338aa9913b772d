"""Every library warning about the user's input names the user's line (the first frame
outside the package, :func:`ddwmmr.user_warnings.warn_user`), whichever public path
issued it: ``simulate``, a controller's ``reset``, the scenarios runner, a plant's
constructor, loading a trajectory or a robot. A warning issued while the library runs a
plug-in's code that calls the library names the plug-in's line."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, SampledTrajectory, load_trajectory, make_controller, simulate
from ddwmmr.commands import WheelForces
from ddwmmr.controllers import StepInfo
from ddwmmr.plants import ThesisPlant, make_plant
from ddwmmr.provenance import file_sha256, trajectory_from_record, trajectory_record
from ddwmmr.resolution.reference import start_configuration
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.trajectories import read_csv

HEAVY = Robot(base_mass=60.0, base_inertia=3.0, wheel_mass=2.0)  # not the thesis robot
SHORT = {"duration": 0.05}


def _start() -> np.ndarray:
    return start_configuration(Robot(), Ellipse())


class Pusher:
    """A plug-in controller with the deprecated ``interface`` attribute outside its
    declared ``interfaces``."""

    name, interface, interfaces = "pusher", "force", ("velocity",)

    def __init__(self) -> None:
        self.last = StepInfo()

    def reset(self, trajectory, q0) -> None:
        pass

    def command(self, t, q, pose_d, velocity_d, base_velocity=None):
        return WheelForces(0.0, 0.0, 0.0, 0.0)


class Disagreeing(Ellipse):
    """A trajectory whose ``sample`` does not give the numbers of ``pose``."""

    def sample(self, times):
        poses, velocities = super().sample(times)
        return poses + 1.0, velocities


class Underived(Ellipse):
    """A trajectory whose ``velocity`` is twice the derivative of its ``pose``."""

    def velocity(self, t):
        return 2.0 * super().velocity(t)

    def sample(self, times):
        poses, velocities = super().sample(times)
        return poses, 2.0 * velocities


def _csv(tmp_path: Path, scale: float = 1.0, heading: bool = False) -> Path:
    times = np.linspace(0.0, 10.0, 11)
    rows = [[t, scale * 0.1 * t, 0.0] + ([9.0 * t] if heading else []) for t in times]
    path = tmp_path / "path.csv"
    header = "t,x,y,phi" if heading else "t,x,y"
    path.write_text("\n".join([header, *(",".join(f"{v:g}" for v in row) for row in rows)]))
    return path


def _gone_record() -> dict:
    shipped = load_trajectory("figure8")
    digest = file_sha256(Path(load_trajectory.__code__.co_filename).parent / "data/figure8.csv")
    return trajectory_record(shipped, Path("/gone/figure8.csv"), digest)


# (the words the warning contains, what issues it through a public path)
CASES = {
    "qp floor, simulate": (
        "stability floor",
        lambda tmp: simulate(Robot(), Ellipse(), "qp", stability_min=3, **SHORT),
    ),
    "qp floor, reset": (
        "stability floor",
        lambda tmp: make_controller("qp", Robot(), stability_min=3).reset(Ellipse(), _start()),
    ),
    "mpc floor, reset": (
        "stability floor",
        lambda tmp: make_controller("mpc", Robot(), stability_min=3).reset(Ellipse(), _start()),
    ),
    "mpc keep-out, reset": (
        "keep-out",
        lambda tmp: make_controller("mpc", Robot(), obstacles=[(0.0, 0.0, 0.1)]).reset(
            Ellipse(), np.array([0.0, 0.3, 0.0, *_start()[3:]])
        ),
    ),
    "qp floor, scenarios": (
        "stability floor",
        lambda tmp: run_scenario(
            generate(1)[0], RunConfig(controller="qp", plant="kinematic", qp_stability_min=3.0)
        ),
    ),
    "other robot, simulate": (
        "another robot",
        lambda tmp: simulate(Robot(), Ellipse(), make_controller("ats", HEAVY), **SHORT),
    ),
    "tipped start, simulate": (
        "simulating anyway",
        lambda tmp: simulate(Robot().with_payload(20.0), Ellipse(), "ats", **SHORT),
    ),
    "gain step, simulate": (
        "K dt",
        lambda tmp: simulate(Robot(), Ellipse(), "clrrmc-ts", dt=1.0, duration=2.0),
    ),
    "interface attribute, simulate": (
        "deprecated",
        lambda tmp: simulate(Robot(), Ellipse(), Pusher(), plant="thesis", **SHORT),
    ),
    "sample disagrees, simulate": (
        "disagrees",
        lambda tmp: simulate(Robot(), Disagreeing(), "ats", **SHORT),
    ),
    "velocity no derivative, simulate": (
        "not the time derivative",
        lambda tmp: simulate(Robot(), Underived(), "ats", **SHORT),
    ),
    "thesis plant, constructor": ("derived for this robot", lambda tmp: ThesisPlant(HEAVY)),
    "thesis plant, make_plant": (
        "derived for this robot",
        lambda tmp: make_plant("thesis", HEAVY),
    ),
    "thesis plant, simulate": (
        "derived for this robot",
        lambda tmp: simulate(HEAVY, Ellipse(), "ats", plant="thesis", **SHORT),
    ),
    "robot, from_dict": (
        "degrees",
        lambda tmp: Robot.from_dict({"joint_limits": [[-360.0, 360.0], [-360.0, 360.0]]}),
    ),
    "robot, from_toml": (
        "degrees",
        lambda tmp: Robot.from_toml(
            _write(tmp / "r.toml", "joint_limits = [[-360.0, 360.0], [-360.0, 360.0]]\n")
        ),
    ),
    "heading, SampledTrajectory": (
        "degrees",
        lambda tmp: SampledTrajectory(
            np.linspace(0.0, 10.0, 11),
            np.column_stack([np.linspace(0, 1, 11), np.zeros(11), np.linspace(0, 90, 11)]),
        ),
    ),
    "heading, read_csv": ("degrees", lambda tmp: read_csv(_csv(tmp, heading=True))),
    "millimetres, read_csv": ("spans", lambda tmp: read_csv(_csv(tmp, scale=1000.0))),
    "millimetres, load_trajectory": (
        "spans",
        lambda tmp: load_trajectory(str(_csv(tmp, scale=1000.0))),
    ),
    "gone file, trajectory_from_record": (
        "is gone",
        lambda tmp: trajectory_from_record(_gone_record()),
    ),
}


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@pytest.mark.parametrize("case", CASES)
def test_a_library_warning_names_the_users_line(case: str, tmp_path: Path) -> None:
    words, issue = CASES[case]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        issue(tmp_path)
    found = [w for w in caught if words in str(w.message)]
    assert found, [str(w.message) for w in caught]
    assert [(w.filename, w.category) for w in found] == [
        (__file__, found[0].category) for _ in found
    ], [f"{w.filename}:{w.lineno}" for w in found]


class Wrapper:
    """A plug-in controller that runs the library's ``qp`` inside its own methods."""

    name = "wrapper"

    def __init__(self) -> None:
        self.inner = make_controller("qp", Robot(), stability_min=3)
        self.last = StepInfo()
        self.line = 0

    def reset(self, trajectory, q0) -> None:
        self.line = sys._getframe().f_lineno + 1
        self.inner.reset(trajectory, q0)

    def command(self, t, q, pose_d, velocity_d, base_velocity=None):
        return self.inner.command(t, q, pose_d, velocity_d, base_velocity)


def test_a_warning_from_a_plug_ins_call_names_the_plug_ins_line() -> None:
    """The library runs the plug-in's ``reset``, which calls the library's: the first
    frame outside the package is the plug-in's line, not the ``simulate`` call."""
    wrapper = Wrapper()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(Robot(), Ellipse(), wrapper, **SHORT)
    found = [w for w in caught if "stability floor" in str(w.message)]
    assert [(w.filename, w.lineno) for w in found] == [(__file__, wrapper.line)]


@pytest.mark.parametrize("category", [UserWarning, FutureWarning])
def test_an_error_filter_still_raises_the_warning(category: type[Warning]) -> None:
    """``-W error`` (a filter) turns the warning into its exception, of its category."""
    issue = (
        (lambda: make_controller("qp", Robot(), stability_min=3).reset(Ellipse(), _start()))
        if category is UserWarning
        else (lambda: simulate(Robot(), Ellipse(), Pusher(), plant="thesis", **SHORT))
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", category)
        with pytest.raises(category) as raised:
            issue()
    assert type(raised.value) is category


def test_the_default_filter_shows_a_warning_once_per_user_line() -> None:
    """The once-per-location registry is the user's module's, as for ``warnings.warn``:
    the same warning from the same line is shown once."""
    controller = make_controller("qp", Robot(), stability_min=3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        for _ in range(3):
            controller.reset(Ellipse(), _start())
    assert len(caught) == 1 and caught[0].filename == __file__
