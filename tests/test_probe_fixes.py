"""Newcomer probe fixes: a plant object for another robot warns; compare figures' width and
obstacles; qualifiers said once; bench wording; the physics plot's log axis from the data."""

from __future__ import annotations

import warnings

import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.plants import KinematicPlant, ThesisPlant


def _plant_warnings(plant: object) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(Robot(), Ellipse(), "ats", duration=0.05, plant=plant)
    return [str(w.message) for w in caught if issubclass(w.category, UserWarning)]


@pytest.mark.parametrize("cls", [KinematicPlant, ThesisPlant])
def test_plant_object_for_another_robot_warns(cls: type) -> None:
    messages = _plant_warnings(cls(Robot().with_payload(5.0)))
    assert len(messages) == 1
    assert messages[0].startswith("plant: the plant object was built for another robot")
    assert "payload 5.0 vs 1.25" in messages[0]


@pytest.mark.parametrize("cls", [KinematicPlant, ThesisPlant])
def test_plant_object_for_the_same_robot_is_silent(cls: type) -> None:
    assert _plant_warnings(cls(Robot())) == []


def test_mujoco_plant_object_for_another_robot_warns() -> None:
    pytest.importorskip("mujoco")
    from ddwmmr.plants import MujocoPlant

    messages = _plant_warnings(MujocoPlant(Robot().with_payload(5.0)))
    assert [m for m in messages if m.startswith("plant: the plant object")] == messages
    assert len(messages) == 1 and "payload 5.0 vs 1.25" in messages[0]


OBSTACLES = [(-0.2, 1.05, 0.3)]


@pytest.fixture(scope="module")
def one_series() -> dict:
    return {"qp": simulate(Robot(), Ellipse(), "ats", duration=2.0).timeseries}


def _inside_figure(fig, artist) -> bool:
    box = artist.get_window_extent(fig.canvas.get_renderer())
    return box.x0 >= 0.0 and box.x1 <= fig.bbox.width and box.y0 >= 0.0


def test_one_method_small_multiples_hold_title_and_legend(one_series: dict) -> None:
    from ddwmmr.reports import compare_plots as cp

    fig = cp.plot_small_multiples(one_series, {"qp": "C0"}, Robot(), "ellipse")
    fig.canvas.draw()
    assert fig.get_figwidth() == pytest.approx(cp.MIN_MULTIPLES_WIDTH_IN)
    assert _inside_figure(fig, fig._suptitle)
    assert all(_inside_figure(fig, legend) for legend in fig.legends)


def _discs(ax) -> list[tuple[float, float, float]]:
    return [(p.center[0], p.center[1], p.radius) for p in ax.patches if hasattr(p, "radius")]


def test_compare_figures_draw_the_obstacles(one_series: dict) -> None:
    from ddwmmr.reports import compare_plots as cp

    colors = {"qp": "C0"}
    paths = cp.plot_paths(one_series, colors, "paths", [("A", 0.0, 0.1)], obstacles=OBSTACLES)
    multiples = cp.plot_small_multiples(one_series, colors, Robot(), "m", obstacles=OBSTACLES)
    for ax in (paths.axes[0], multiples.axes[0]):
        assert _discs(ax) == [pytest.approx((-0.2, 1.05, 0.3))]
        assert ax.get_xlim()[0] < -0.5 and ax.get_ylim()[1] > 1.35  # the disc is in frame


@pytest.mark.parametrize(
    ("text", "field", "mujoco_words"),
    [
        ("link_masses = [1.0, 0.0]\n", "link_masses[2] must be > 0", 1),
        ("base_inertia = 0.01\n", "base_inertia must be >", 1),
        # every plant's S needs the base centre inside the support polygon: a Robot error
        ("caster_positions = [[0.2, 0.0]]\n", "caster_positions: the base centre", 0),
    ],
)
def test_mujoco_robot_file_errors_say_their_qualifiers_once(
    tmp_path, text, field, mujoco_words
) -> None:
    pytest.importorskip("mujoco")
    import argparse

    from ddwmmr.cli.common import robot_from_arguments
    from ddwmmr.errors import ParameterError

    path = tmp_path / "r.toml"
    path.write_text(text)
    with pytest.raises(ParameterError) as info:
        robot_from_arguments(argparse.Namespace(robot=str(path), payload=None), ("mujoco",))
    message = str(info.value)
    assert message.startswith(f"robot: {path}: {field}")
    assert message.count("MuJoCo plant") == mujoco_words and message.count("robot:") == 1


def _bench_report(labels: list[str]) -> dict:
    row = {"step_us": 5.0, "step_p90_us": 6.0, "step_p99_us": 7.0, "step_ratio": 0.1}
    row.update(steps_per_s=1000.0, run_speedup=2.0, meets_target=True)
    return {
        "config": {
            "trajectory": "ellipse",
            "calls": 5,
            "run_duration_s": 0.1,
            "integrator": "rk4",
            "repeats": 1,
        },
        "rows": [{"label": label, **row} for label in labels],
        "target_step_ratio": 0.25,
        "baseline": "naive-pinv",
        "step_budgets_us": {"qp": 60.0, "mpc": 2000.0},
        "pairs": [],
        "skipped": {},
        "scenarios": [
            {
                "scenarios": 1,
                "jobs": 1,
                "controller": "qp",
                "sim_seconds_per_wall_second": 50.0,
                "sim_time_s": 40.0,
                "wall_time_s": 0.8,
                "failed": 0,
            }
        ],
    }


def test_bench_table_names_only_measured_budgets_and_counts_in_the_singular() -> None:
    from ddwmmr.bench.report import format_table

    text = format_table(_bench_report(["naive-pinv", "ats"]))
    assert "target for" not in text
    assert "(1 scenario, seed 0, 1 worker;" in text
    text = format_table(_bench_report(["naive-pinv", "qp"]))
    assert "target for qp: step <= 60 us" in text and "target for mpc" not in text


def test_qp_phases_line_shows_a_negative_rest_and_says_why() -> None:
    from ddwmmr.bench.report import format_qp_phases

    phases = {"build": 7.0, "solve": 4.0, "check": 0.5, "rest": 0.0}
    line = format_qp_phases({"phases": phases, "rows": {"qp": {"median_us": 11.0}}})
    assert "rest -0.50 (the phase medians add up to more than the step median 11.00" in line
    phases["rest"] = 1.5
    line = format_qp_phases({"phases": phases, "rows": {"qp": {"median_us": 13.0}}})
    assert line == "    qp phases (median): build 7.00, solve 4.00, check 0.50, rest 1.50"


def test_plant_error_axis_stops_below_the_data() -> None:
    import numpy as np

    from ddwmmr.reports import compare_plots as cp

    t = np.linspace(0.0, 4.0, 41)
    kinematic = {"qp": {"t": t, "position_error_m": np.geomspace(0.04, 2e-5, t.size)}}
    plant = {"qp": {"t": t, "position_error_m": np.geomspace(0.04, 2e-3, t.size)}}
    fig = cp.plot_plant_errors(kinematic, plant, {"qp": "C1"}, "mujoco", "ellipse")
    assert fig.axes[0].get_ylim()[0] == pytest.approx(1e-5, rel=1e-9)
    converged = {"qp": {"t": t, "position_error_m": np.zeros(t.size)}}
    fig = cp.plot_plant_errors(converged, plant, {"qp": "C1"}, "mujoco", "ellipse")
    assert fig.axes[0].get_ylim()[0] == pytest.approx(cp.ERROR_FLOOR / 2, rel=1e-9)


@pytest.mark.parametrize("parameter", ["method", "plant"])
def test_an_object_for_another_robot_is_warned_at_the_callers_line(parameter: str) -> None:
    """The warning names the line that called ``simulate`` (as Python's own warnings
    name the caller), whether the controller or the plant holds the other robot."""
    from ddwmmr import make_controller

    other = Robot().with_payload(5.0)
    given = {"method": make_controller("ats", other)} if parameter == "method" else {}
    if parameter == "plant":
        given = {"method": "ats", "plant": KinematicPlant(other)}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(Robot(), Ellipse(), duration=0.05, **given)
    found = [w for w in caught if "another robot" in str(w.message)]
    assert [w.filename for w in found] == [__file__]
