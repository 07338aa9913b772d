"""Where a plug-in meets the library (docs/api.md, "Extending"): its step info, a plant's
summary and extra columns, a reset that fails in a scenario batch, the wording of an
arbiter's error and a class registered without a docstring, each answered in one line
naming the plug-in."""

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.controllers import StepInfo
from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.plants import KinematicPlant
from ddwmmr.registry import CONTROLLERS, PLANTS
from ddwmmr.scenarios import RunConfig, generate, run_scenario


class _Plain:
    """A plug-in controller that stands still (both tasks)."""

    def __init__(self, robot):
        self.last = StepInfo()

    @classmethod
    def waypoint_options(cls, run):
        return {}

    def reset(self, trajectory, q0):
        pass

    def command(self, t, q, pose_d, velocity_d):
        return np.zeros(4)


class _DictInfo(_Plain):
    """Its step info is a dict."""

    def command(self, t, q, pose_d, velocity_d):
        self.last = {"singular": False}
        return np.zeros(4)


def test_a_step_info_that_is_no_step_info_is_one_line(registered):
    registered(CONTROLLERS, "my-info", _DictInfo)
    with pytest.raises(ParameterError) as error:
        simulate(Robot(), Ellipse(), "my-info", duration=0.1)
    assert str(error.value) == (
        "method: my-info.last must be a StepInfo(singular, nonholonomic_residual, fallback, "
        "extra) (got {'singular': False} after the command of step 0, t = 0 s)"
    )


def test_a_controller_without_last_reports_nothing(registered):
    class NoLast(_Plain):
        def __init__(self, robot):
            pass

    registered(CONTROLLERS, "my-nolast", NoLast)
    result = simulate(Robot(), Ellipse(), "my-nolast", duration=0.1)
    assert result.summary["steps"] == 5


class _SummaryList(KinematicPlant):
    """Its summarize() returns a list."""

    def summarize(self, timeseries):
        return ["not", "a", "mapping"]


class _ShortExtras(KinematicPlant):
    """It declares two extra columns and gives one value."""

    extra_columns = ("a_n", "b_n")

    def extra_values(self):
        return (1.0,)


def test_a_plant_summary_that_is_no_mapping_is_one_line(registered):
    registered(PLANTS, "my-summary", _SummaryList)
    with pytest.raises(ParameterError) as error:
        simulate(Robot(), Ellipse(), "ats", plant="my-summary", duration=0.1)
    assert str(error.value) == (
        "plant: my-summary.summarize() must return a mapping of summary keys (a dict, {} "
        "for none; got ['not', 'a', 'mapping'])"
    )


def test_extra_values_of_another_length_than_extra_columns_is_one_line(registered):
    registered(PLANTS, "my-extras", _ShortExtras)
    with pytest.raises(ParameterError) as error:
        simulate(Robot(), Ellipse(), "ats", plant="my-extras", duration=0.1)
    assert str(error.value) == (
        "plant: my-extras.extra_values() must return 2 numbers, one per extra_columns name "
        "(a_n, b_n) (got (1.0,))"
    )


class _ResetRaises(_Plain):
    """Its reset raises."""

    def reset(self, trajectory, q0):
        raise KeyError("boom")


class _PlantResetRaises(KinematicPlant):
    """A plug-in plant whose reset raises."""

    def reset(self, q0, dt):
        raise KeyError("boom")


def _reasons(config):
    return [run_scenario(s, config).metrics["reason"] for s in generate(2, 0)]


def test_a_raising_controller_reset_fails_each_scenario_not_the_batch(registered):
    registered(CONTROLLERS, "my-reset", _ResetRaises, tasks=("tracking", "waypoints"))
    reason = (
        "controller error: PluginError: method: my-reset.reset() raised KeyError: \"'boom'\" "
        "before the first step"
    )
    assert _reasons(RunConfig(controller="my-reset", time_limit=1.0)) == [reason, reason]


def test_a_raising_plant_reset_fails_each_scenario_not_the_batch(registered):
    registered(PLANTS, "my-plant-reset", _PlantResetRaises)
    reason = (
        "controller error: PluginError: plant: my-plant-reset.reset() raised KeyError: "
        "\"'boom'\" before the first step"
    )
    config = RunConfig(controller="qp", plant="my-plant-reset", time_limit=1.0)
    outcomes = [run_scenario(s, config) for s in generate(2, 0)]
    assert [o.metrics["reason"] for o in outcomes] == [reason, reason]
    assert [o.metrics["sim_steps"] for o in outcomes] == [0, 0]


def test_the_scenarios_tool_records_a_raising_reset_and_goes_on(tmp_path, registered):
    import json

    from ddwmmr.cli.scenarios import main

    registered(CONTROLLERS, "my-reset", _ResetRaises, tasks=("tracking", "waypoints"))
    out = tmp_path / "batch"
    argv = ["--controller", "my-reset", "--n", "2", "--time-limit", "1", "--jobs", "1"]
    assert main([*argv, "--no-progress", "--out", str(out)]) == 0
    text = (out / "summary.json").read_text()
    assert text.count("method: my-reset.reset() raised KeyError") == 2, json.loads(text)


def test_a_tracking_run_still_raises_a_raising_reset(registered):
    registered(CONTROLLERS, "my-reset", _ResetRaises)
    with pytest.raises(PluginError, match=r"^method: my-reset\.reset\(\) raised KeyError"):
        simulate(Robot(), Ellipse(), "my-reset", duration=0.1)


def test_a_class_without_a_docstring_is_listed_with_no_description(registered):
    from ddwmmr.controllers import method_description

    undocumented = registered(CONTROLLERS, "my-nodoc", type("NoDoc", (_Plain,), {"__doc__": None}))
    assert method_description("my-nodoc") == "(no description)"
    # registered again (a reload): its class, traits and description replace the entry's
    undocumented.__doc__ = "Documented now."
    CONTROLLERS.register("my-nodoc", tasks=("tracking", "waypoints"))(undocumented)
    assert method_description("my-nodoc") == "Documented now."
    assert CONTROLLERS.traits("my-nodoc")["tasks"] == ("tracking", "waypoints")
