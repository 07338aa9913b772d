"""The simulator app's parts without a window: option specs from constructor signatures,
trajectory placement, settings checks, plants, the background worker."""

import math
import threading

import numpy as np
import pytest

import ddwmmr.sim
from ddwmmr import ParameterError, available_methods, load_trajectory
from ddwmmr.controllers.base import NumberText
from ddwmmr.gui.options import method_options, option_spec, plant_keywords, plant_names
from ddwmmr.gui.settings import (
    Settings,
    build_trajectory,
    check_settings,
    control_step,
    geometry_of,
    place_samples,
)
from ddwmmr.gui.worker import Worker
from ddwmmr.trajectories import SampledTrajectory

# -- method options -------------------------------------------------------------------


def test_every_method_offers_the_options_its_constructor_takes():
    for method in available_methods():
        names = [spec.name for spec in method_options(method)]
        assert "robot" not in names
        assert len(names) == len(set(names))
    # the class's own options, then its parents' (the resolved-rate base's damping)
    assert [s.name for s in method_options("ats")] == ["aux", "singularity_threshold", "damping"]
    assert {"tau", "aux"} <= {s.name for s in method_options("clrrmc-ts")}
    assert {"tau", "aux", "reference_step"} <= {s.name for s in method_options("clrrmc-cs")}
    qp = {s.name: s for s in method_options("qp")}
    assert {"stability_min", "manipulability_weight", "obstacles", "tau"} <= set(qp)
    # User task/limit objects cannot be typed into a field: not offered.
    assert "tasks" not in qp and "limits" not in qp
    assert qp["stability_min"].kind == "number" and qp["stability_min"].default == 1.25
    assert qp["obstacles"].kind == "text"
    assert qp["mode"].kind == "choice" and set(qp["mode"].choices) == {"weighted", "hierarchical"}
    assert qp["track_orientation"].choices == (True, False)
    assert qp["warm_start"].choices == (None, True, False)


def test_option_kinds_follow_defaults_and_annotations():
    several = option_spec("tau", 0.5, "float | Sequence[float]")
    assert several.parse("0.3") == 0.3
    assert several.parse("0.1, 0.2 0.3") == (0.1, 0.2, 0.3)
    assert several.parse("inf") == math.inf
    optional = option_spec("max_speed", None, "float | None")
    assert optional.optional and optional.parse("  ") is None and optional.parse("2") == 2.0
    integer = option_spec("horizon", 10, "int")
    assert integer.parse("12") == 12 and isinstance(integer.parse("12"), int)
    # not one number of the option's kind: passed on, as nan is, for the method's check to
    # refuse naming the range (make_controller)
    for spec, text in [(integer, "1.5"), (optional, "1 2"), (several, "fast"), (integer, "")]:
        value = spec.parse(text)
        assert isinstance(value, NumberText) and value == text
    aux = option_spec("aux", "shoulder", "str")
    assert aux.kind == "choice" and aux.parse("sum") == "sum"
    with pytest.raises(ParameterError, match="aux must be one of sum, shoulder"):
        aux.parse("elbow")
    assert option_spec("tasks", (), "Sequence[Task]") is None
    assert option_spec("points", (), "Sequence[Point]") is None  # "int" inside a word
    assert option_spec("flag", True, "bool").format(False) == "off"


def test_a_newly_registered_method_brings_its_options(registered):
    from ddwmmr.registry import CONTROLLERS

    class Horizon:
        """Test method with an MPC-like horizon."""

        def __init__(self, robot, horizon: int = 10, weight: float = 1.0, **kwargs):
            self.robot, self.horizon, self.weight = robot, horizon, weight

    registered(CONTROLLERS, "mpc-test", Horizon, description="test")
    method_options.cache_clear()
    try:
        specs = method_options("mpc-test")
        assert [(s.name, s.kind, s.default) for s in specs] == [
            ("horizon", "number", 10),
            ("weight", "number", 1.0),
        ]
        assert "mpc-test" in available_methods()
    finally:
        method_options.cache_clear()


# -- plants ------------------------------------------------------------------------------


def test_plant_list_comes_from_the_engine_when_it_has_one(monkeypatch):
    if not hasattr(ddwmmr.sim, "available_plants"):
        assert plant_names() == ["kinematic"]
    monkeypatch.setattr(
        ddwmmr.sim, "available_plants", lambda: ["kinematic", "thesis"], raising=False
    )
    assert plant_names() == ["kinematic", "thesis"]


def test_integrator_goes_to_the_kinematic_plant_only():
    assert plant_keywords("kinematic", "euler") == {"plant": "kinematic", "integrator": "euler"}
    assert plant_keywords("mujoco", "euler") == {"plant": "mujoco"}
    assert set(plant_names()) >= {"kinematic", "thesis", "mujoco"}


# -- trajectories --------------------------------------------------------------------


def test_parametric_geometry_is_passed_to_the_shape():
    settings = Settings(trajectory="rectangle", geometry={"a": 1.2, "T": 25.0, "N": 500})
    trajectory = build_trajectory(settings)
    assert (trajectory.a, trajectory.b, trajectory.T, trajectory.N) == (1.2, 1.5, 25.0, 500)
    assert trajectory.name == "rectangle"
    assert control_step(settings, trajectory) is None  # simulate's own T / N
    with pytest.raises(ParameterError, match=r"T must be in \[1e-06, 1e\+09\] s"):
        build_trajectory(settings.replace(geometry={"T": -1.0}))


def test_sampled_file_unchanged_without_geometry():
    base = load_trajectory("figure8")
    trajectory = build_trajectory(Settings(trajectory="figure8"))
    np.testing.assert_array_equal(trajectory.points, base.points)
    np.testing.assert_array_equal(trajectory.times, base.times)
    own = geometry_of(base)
    xy = base.points[:, :2]
    assert own["a"] == pytest.approx((xy[:, 0].max() - xy[:, 0].min()) / 2)
    # N: the run's steps at the default step (rows 0.25 s apart, steps of 0.02 s)
    assert own["N"] == round(base.duration / 0.02) == 3000
    assert own["T"] == pytest.approx(base.duration)


def test_sampled_placement_is_the_affine_map_of_the_samples():
    base = load_trajectory("figure8")
    own = geometry_of(base)
    geometry = {**own, "x0": 1.0, "y0": -0.5, "a": 2 * own["a"], "b": own["b"], "beta": 0.4}
    geometry["T"] = 2 * own["T"]
    placed = place_samples(base, geometry)
    c, s = math.cos(0.4), math.sin(0.4)
    rotation = np.array([[c, -s], [s, c]])
    scale = np.array([2.0, 1.0])
    # C1 Hermite interpolation commutes with affine maps of the samples and a uniform
    # time stretch, so the map holds between samples too (not only at them).
    for t in np.linspace(0.0, base.duration, 37):
        expected = rotation @ ((base.pose(t)[:2] - [own["x0"], own["y0"]]) * scale) + [1.0, -0.5]
        np.testing.assert_allclose(placed.pose(2 * t)[:2], expected, atol=1e-12)
        expected_rate = rotation @ (base.velocity(t)[:2] * scale) / 2
        np.testing.assert_allclose(placed.velocity(2 * t)[:2], expected_rate, atol=1e-12)
    assert placed.duration == pytest.approx(2 * base.duration)


def test_uniform_placement_turns_the_orientation_by_beta():
    base = load_trajectory("sideways_reach")  # has a phi column
    own = geometry_of(base)
    placed = place_samples(base, {**own, "beta": 0.3})
    for t in (0.0, 1.7, base.duration):
        assert placed.pose(t)[2] == pytest.approx(base.pose(t)[2] + 0.3)
    tangent = load_trajectory("figure8")
    own = geometry_of(tangent)
    turned = place_samples(tangent, {**own, "beta": 0.3})
    for t in (0.3, 11.0, 40.2):
        turn = turned.pose(t)[2] - tangent.pose(t)[2]
        assert math.remainder(turn - 0.3, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_sampled_resolution_sets_the_step():
    settings = Settings(trajectory="figure8", geometry={"N": 100})
    trajectory = build_trajectory(settings)
    assert isinstance(trajectory, SampledTrajectory)
    assert control_step(settings, trajectory) == pytest.approx(trajectory.duration / 100)
    assert control_step(settings.replace(dt=0.05), trajectory) == 0.05


def test_check_settings_names_the_bad_value(tmp_path):
    with pytest.raises(ParameterError, match="integrator must be one of"):
        check_settings(Settings(integrator="rk45"))
    with pytest.raises(ParameterError, match="duration must be > 0"):
        check_settings(Settings(duration=-2.0))
    with pytest.raises(ParameterError, match="method: unknown method 'nope'"):
        check_settings(Settings(methods=("nope", None)))
    with pytest.raises(ParameterError, match="tau must be > 0"):
        check_settings(Settings(methods=("clrrmc-ts", None), options=({"tau": -1.0}, {})))
    note = tmp_path / "note.csv"
    note.write_text("hello,world\n1,2\n")
    with pytest.raises(ParameterError, match=r"traj: .* unknown column\(s\) 'hello', 'world'"):
        check_settings(Settings(trajectory=str(note)))


def test_options_at_their_default_are_not_passed():
    settings = Settings(methods=("qp", "ats")).with_option(0, "stability_min", 1.5)
    assert settings.options == ({"stability_min": 1.5}, {})
    assert settings.with_option(0, "stability_min", 1.25).options == ({}, {})
    # Switching a slot's method drops that slot's options only.
    switched = settings.with_option(1, "aux", "sum").with_method(0, "pi")
    assert switched.options == ({}, {"aux": "sum"})


# -- worker ---------------------------------------------------------------------------


def test_worker_reports_progress_over_parts_and_returns_the_result():
    seen = []

    def job(progress):
        progress(0, 10, 10)
        seen.append(worker.fraction)
        progress(1, 5, 10)
        seen.append(worker.fraction)
        return 42

    worker = Worker(job, parts=2)
    worker.start()
    worker.join()
    assert seen == [0.5, 0.75]
    assert (worker.state, worker.result, worker.fraction) == ("done", 42, 1.0)


def test_worker_pauses_at_a_progress_report_and_cancels():
    reached = threading.Event()
    returned = []

    def job(progress):
        reached.set()
        progress(0, 1, 10)
        returned.append(True)
        return "finished"

    worker = Worker(job)
    worker.pause()
    worker.start()
    assert reached.wait(10)
    worker.join(timeout=0.2)  # blocked in the progress report: still alive
    assert worker.state == "paused" and not worker.finished and not returned
    worker.cancel()
    worker.join()
    assert worker.state == "cancelled" and worker.result is None and not returned


def test_worker_turns_errors_into_one_line():
    def bad_input(progress):
        raise ParameterError("dt must be <= duration (1 s) (got 5)")

    def crash(progress):
        raise RuntimeError("boom\nsecond line")

    first, second = Worker(bad_input), Worker(crash)
    for worker in (first, second):
        worker.start()
        worker.join()
    assert first.state == "failed" and first.bad_input
    assert first.error == "dt must be <= duration (1 s) (got 5)"
    assert second.state == "failed" and not second.bad_input
    assert second.error == "run failed: RuntimeError: boom"


def test_the_summary_line_says_what_the_physics_plant_judged():
    """On the MuJoCo plant the window's summary line gives the tip-over verdict of the
    contact forces; on the other plants it says nothing about physics."""
    from types import SimpleNamespace

    from ddwmmr.gui.app import _summary_line

    base = {
        "rms_position_error_m": 0.01, "max_position_error_m": 0.02,
        "rms_orientation_error_rad": 0.1, "max_wheel_speed_rad_s": 5.0,
        "min_stability": 1.3, "min_manipulability": 0.8, "saturated_steps": 0,
        "fallback_steps": 0,
    }  # fmt: skip
    assert "physics" not in _summary_line("A", SimpleNamespace(summary=base))
    tipped = {**base, "tipped": True, "tip_time_s": 1.234, "min_physics_stability": 0.0}
    assert "TIPPED at 1.23 s (physics)" in _summary_line("A", SimpleNamespace(summary=tipped))
    stood = {**base, "tipped": False, "tip_time_s": None, "min_physics_stability": 1.21}
    line = _summary_line("A", SimpleNamespace(summary=stood))
    assert "stood (physics: min physics stability 1.21)" in line


def test_the_mpc_options_carry_their_units():
    """The mpc's horizon is in seconds (the field said steps), its force-model options in
    N and rad/s^2."""
    mpc = {spec.name: spec for spec in method_options("mpc")}
    expected = {
        "horizon": "s",
        "first_interval": "s",
        "arm_time_constant": "s",
        "wheel_force_limit": "N",
        "joint_acceleration_limit": "rad/s2",
        "brake_slack": "m",
    }
    assert {name: mpc[name].unit for name in expected} == expected
    assert mpc["joint_acceleration_limit"].parse("5 8") == (5.0, 8.0)


def test_each_method_offers_its_own_solver_choices():
    """The mpc's solver button cycles through the mpc's solvers (it showed the qp's, which
    the mpc refuses); a mapping option (another controller's options) is not a field."""
    from ddwmmr.mpc.solvers import QP_SOLVERS, SOLVERS
    from ddwmmr.qp.solve import installed_solvers

    mpc = {spec.name: spec for spec in method_options("mpc")}
    qp = {spec.name: spec for spec in method_options("qp")}
    assert mpc["solver"].choices == SOLVERS and mpc["solver"].default == "rti"  # all here
    assert mpc["qp_solver"].kind == "choice" and mpc["qp_solver"].choices == QP_SOLVERS
    assert mpc["model"].choices == (None, "kinematic", "thesis")  # None shows as "auto"
    assert mpc["model"].parse("auto") is None and mpc["model"].parse("thesis") == "thesis"
    assert "fallback_options" not in mpc
    assert set(qp["solver"].choices) == set(installed_solvers())
    assert option_spec("fallback_options", None, "dict[str, Any] | None") is None
