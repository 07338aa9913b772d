"""make_controller's options: every parameter of the class's and its parents' __init__.

Found before: ``ats``/``ap`` rejected ``damping`` (the signature read stopped at ``**kwargs``).
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot
from ddwmmr.controllers import available_methods, make_controller, method_options
from ddwmmr.registry import CONTROLLERS

#: Options each resolution method documents (docs/theory.md, docs/cli.md), written out here
#: independently of the code that discovers them.
DOCUMENTED = {
    "pi": {"singularity_threshold", "damping"},
    "ats": {"aux", "singularity_threshold", "damping"},
    "ap": {"K1", "K2", "K3", "singularity_threshold", "damping"},
    "clrrmc-ts": {"tau", "aux", "singularity_threshold", "damping"},
    "clrrmc-cs": {"tau", "aux", "reference_step"},
    "qp": {"stability_min", "manipulability_weight", "obstacles", "solver", "mode", "tau"},
}
PAIRS = [(m, o) for m in available_methods() for o in method_options(m)]


@pytest.mark.parametrize("method", sorted(DOCUMENTED))
def test_documented_options_are_accepted(method):
    assert DOCUMENTED[method] <= set(method_options(method))


def _first_command(controller) -> np.ndarray:
    trajectory = Ellipse()
    q = np.array([1.4, -0.2, 1.7, -0.3, 0.6])
    controller.reset(trajectory, q.copy())
    return controller.command(0.0, q, trajectory.pose(0.0), trajectory.velocity(0.0))


@pytest.mark.parametrize(("method", "option"), PAIRS, ids=[f"{m}-{o}" for m, o in PAIRS])
def test_every_option_with_its_default_changes_nothing(method, option):
    default = method_options(method)[option]
    assert default is not inspect.Parameter.empty, "every option has a default"
    given = make_controller(method, Robot(), **{option: default})
    np.testing.assert_array_equal(_first_command(given), _first_command(make_controller(method)))


def test_options_reach_the_parent_class():
    assert make_controller("ats", damping=0.2).damping == 0.2
    assert make_controller("ap", singularity_threshold=0.1, K3=0.0).threshold == 0.1


def test_unknown_option_lists_the_accepted_ones():
    with pytest.raises(ParameterError, match=r"unknown option 'tau' \(accepted: aux, damping, "):
        make_controller("ats", tau=1.0)


def test_mro_walk_most_derived_default_wins(registered):
    class Parent:
        def __init__(self, robot, a=1.0, b=2.0, *args):
            self.a, self.b = a, b

    class Child(Parent):
        def __init__(self, robot, c=3.0, b=5.0, **kwargs):
            super().__init__(robot, b=b, **kwargs)
            self.c = c

    registered(CONTROLLERS, "tmp-child", Child)
    assert method_options("tmp-child") == {"c": 3.0, "b": 5.0, "a": 1.0}
    assert make_controller("tmp-child", a=7.0).a == 7.0
    with pytest.raises(ParameterError, match="unknown option 'kwargs'"):
        make_controller("tmp-child", kwargs=1)


@pytest.mark.parametrize("method", [*available_methods(), "thesis"])
def test_a_non_finite_option_is_refused_naming_its_range(method):
    """Audit: ``damping=nan`` was refused as "must be a number (got 'nan')", with no range;
    qp's obstacle_margin took nan. Every number option of every method now refuses nan
    (and inf, where inf is not a documented value) with the allowed range in the message."""
    import math
    import re

    from ddwmmr.controllers.option_specs import option_specs, parse_option

    range_words = re.compile(r"[<>]=? ?\d|\bin [\[(]|integer in")
    for spec in option_specs(method):
        if spec.kind != "number":
            continue
        for text in ("nan", "inf"):
            name, value = parse_option(method, f"{spec.name}={text}")
            if text == "inf" and spec.name == "tau":
                continue  # inf disables a channel (documented)
            with pytest.raises(ParameterError) as info:
                make_controller(method, **{name: value})
            message = str(info.value)
            assert "\n" not in message and message.replace(" ", "_").startswith(spec.name)
            assert range_words.search(message), (spec.name, message)
            assert f"(got {text})" in message and not math.isfinite(float(text))


@pytest.mark.parametrize("method", [*available_methods(), "thesis"])
def test_a_non_numeric_option_is_refused_naming_its_range(method):
    """Audit: ``damping=abc`` was refused as "damping must be a number (got 'abc')", with
    no range. The text is passed on to the method's own check, as nan is: every number
    option of every method refuses it in the words of its nan message, quoting the text."""
    from ddwmmr.controllers.option_specs import option_specs, parse_option

    for spec in option_specs(method):
        if spec.kind != "number":
            continue
        messages = []
        for text in ("nan", "abc"):
            name, value = parse_option(method, f"{spec.name}={text}")
            with pytest.raises(ParameterError) as info:
                make_controller(method, **{name: value})
            messages.append(str(info.value))
        refused_nan, refused_text = messages
        assert "\n" not in refused_text and refused_text.endswith("(got 'abc')"), refused_text
        assert refused_text == refused_nan.replace("(got nan)", "(got 'abc')"), spec.name


def test_a_method_without_a_check_refuses_non_numeric_text_itself(registered):
    """A method that takes the text unchecked (a plug-in) still never receives it."""
    from ddwmmr.controllers.option_specs import parse_option

    class Unchecked:
        def __init__(
            self, robot, gain: float = 1.0, scale: float = 1.0, real: float = 0.0, steps: int = 5
        ):
            self.gain = gain
            self.scale = 2.0 * scale  # computes with it right away: a TypeError for text
            self.real = real.real  # an AttributeError for text
            self.steps = steps

    registered(CONTROLLERS, "tmp-unchecked", Unchecked)
    cases = [
        ("gain=abc", "gain must be a number (got 'abc')"),
        ("scale=abc", "scale must be a number (got 'abc')"),
        ("real=abc", "real must be a number (got 'abc')"),
        ("gain=1,2", "gain must be one number (got '1,2')"),
        ("steps=1.5", "steps must be an integer (got '1.5')"),
    ]
    for text, message in cases:
        name, value = parse_option("tmp-unchecked", text)
        with pytest.raises(ParameterError) as info:
            make_controller("tmp-unchecked", **{name: value})
        assert str(info.value) == message
    assert make_controller("tmp-unchecked", gain=3.0).gain == 3.0
