"""Scenario generator, protocol (success rule, metrics) and executors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr.errors import MAX_OBSTACLES, ParameterError
from ddwmmr.model import Robot
from ddwmmr.scenarios import RunConfig, Scenario, generate, place_obstacles, run_scenario
from ddwmmr.scenarios.executors import run_many
from ddwmmr.scenarios.protocol import _Tally
from ddwmmr.scenarios.report import metrics_csv, summarize
from ddwmmr.scenarios.studies import obstacle_scenarios

ROBOT = Robot().with_payload(3.0)


# -- generator ----------------------------------------------------------------------------
def test_generator_is_deterministic_and_prefix_stable():
    a, b = generate(20, seed=7), generate(20, seed=7)
    assert a == b
    assert generate(5, seed=7) == a[:5]
    assert generate(5, seed=8) != a[:5]
    points = np.array([s.waypoints for s in a])
    assert points.shape == (20, 5, 2)
    assert np.all(np.abs(points) <= 4.0)
    # uniform over the square: mean near 0, sd near 8 / sqrt(12) = 2.31 (200 values)
    assert abs(points.mean()) < 0.5
    assert points.std() == pytest.approx(8.0 / math.sqrt(12.0), rel=0.1)


def test_generator_rejects_bad_count():
    with pytest.raises(ParameterError, match=r"n must be an integer in \[1, 100000\] \(got 0\)"):
        generate(0)


def test_path_length_by_hand():
    s = Scenario(0, ((3.0, 4.0), (3.0, 0.0), (0.0, 0.0), (0.0, 1.0), (1.0, 1.0)))
    assert s.path_length() == pytest.approx(5.0 + 4.0 + 3.0 + 1.0 + 1.0)


def test_obstacles_on_legs_keep_clear_of_waypoints():
    scenarios = obstacle_scenarios(generate(10, 0))
    assert [s.index for s in scenarios] == [0, 2, 6, 9]
    for s in scenarios:
        assert len(s.obstacles) == 2
        for ox, oy, r in s.obstacles:
            assert r == 0.3
            for p in [(0.0, 0.0), *s.waypoints]:
                assert math.dist(p, (ox, oy)) >= 1.0
        (ax, ay, _), (bx, by, _) = s.obstacles
        assert math.hypot(ax - bx, ay - by) >= 2.0  # the base can pass between them
    assert place_obstacles(scenarios[0]) == scenarios[0]


@pytest.mark.parametrize(
    ("count", "got"),
    [(-1, "-1"), (2.5, "2.5"), (True, "True"), (10**9, "1000000000"), ("2", "'2'")],
)
def test_place_obstacles_refuses_a_count_outside_0_to_the_cap(count, got):
    """A negative, fractional, boolean or huge count placed obstacles anyway (all five
    legs' worth, or one for True); now it is a one-line error with the allowed range."""
    with pytest.raises(ParameterError) as info:
        place_obstacles(generate(1)[0], count=count)
    assert str(info.value) == f"count must be an integer in [0, {MAX_OBSTACLES}] (got {got})"


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("keep_out", math.nan, "keep_out must be a finite number >= 0 (got nan)"),
        ("keep_out", -1.0, "keep_out must be >= 0 (got -1)"),
        ("separation", math.nan, "separation must be a finite number >= 0 (got nan)"),
        ("separation", -0.5, "separation must be >= 0 (got -0.5)"),
        ("radius", 0.0, "radius must be in [1e-06, 1000] m (got 0)"),
        ("radius", math.nan, "radius must be a finite number in [1e-06, 1000] m (got nan)"),
        ("radius", math.inf, "radius must be a finite number in [1e-06, 1000] m (got inf)"),
    ],
)
def test_place_obstacles_refuses_a_bad_radius_keep_out_or_separation(name, value, message):
    """Only count was checked: a NaN keep_out or separation compared false with every
    distance, so obstacles went on the waypoints (or on one another); a NaN or 0 radius
    made a Scenario the run then refused as "obstacles", far from the call."""
    with pytest.raises(ParameterError) as info:
        place_obstacles(generate(1)[0], **{name: value})
    assert str(info.value) == message


def test_place_obstacles_keeps_its_defaults_and_takes_zero_keep_out_and_separation():
    scenario = generate(1)[0]
    assert place_obstacles(scenario) == place_obstacles(
        scenario, count=2, radius=0.3, keep_out=1.0, separation=2.0
    )
    assert len(place_obstacles(scenario, keep_out=0.0, separation=0.0).obstacles) == 2


def test_place_obstacles_of_count_0_places_none_and_a_count_beyond_the_legs_all_it_can():
    """count = 0 placed one obstacle (the count was compared after the first placement)."""
    scenario = generate(1)[0]
    assert place_obstacles(scenario, count=0).obstacles == ()
    assert len(place_obstacles(scenario, count=1).obstacles) == 1
    most = place_obstacles(scenario, count=MAX_OBSTACLES).obstacles
    assert 2 <= len(most) <= len(scenario.waypoints)  # at most one per leg
    assert place_obstacles(scenario, count=len(most)).obstacles == most


# -- success rule -------------------------------------------------------------------------
def test_waypoint_tolerance_and_order():
    s = Scenario(0, ((1.0, 0.0), (2.0, 0.0), (3.0, 0.0), (4.0, 0.0), (5.0, 0.0)))
    tally = _Tally(ROBOT, s, RunConfig())
    assert not tally.advance(2.0, 0.0)  # waypoint 2 first does not count: order
    assert tally.index == 0
    assert not tally.advance(1.0101, 0.0)  # 1.01 cm away: not reached
    assert not tally.advance(1.0099, 0.0)
    assert tally.index == 1
    for x in (2.0, 3.0, 4.0):
        assert not tally.advance(x, 0.0)
    assert tally.advance(5.0, 0.005) and tally.reason == "ok"


def test_stability_at_or_below_one_fails():
    tally = _Tally(ROBOT, generate(1)[0], RunConfig())
    stretched_left = (0.0, 0.0, 0.0, math.pi / 2, 0.0)  # 3 kg, full sideways: S = 1.0
    assert ROBOT.stability(stretched_left)[2] == pytest.approx(1.0)
    assert tally.check(stretched_left)
    assert tally.reason == "tipped"
    ok = _Tally(ROBOT, generate(1)[0], RunConfig())
    assert not ok.check((0.0, 0.0, 0.0, math.pi / 2, 0.3))


def test_payload_choice_thesis_payload_never_tips_3kg_can():
    """With 1.25 kg min S over all arm poses is 1.56; with 3.0 kg it reaches 1.0.

    docs/theory.md, "Tip-over stability".
    """
    grid = np.linspace(-math.pi, math.pi, 181)
    light = Robot().with_payload(1.25)
    worst_light = min(light.stability((0, 0, 0, a, b))[2] for a in grid for b in grid)
    worst_heavy = min(ROBOT.stability((0, 0, 0, a, b))[2] for a in grid for b in grid)
    assert worst_light == pytest.approx(0.175 / ((2.75 * 0.35 + 1.75 * 0.30) / 13.25), rel=1e-3)
    assert worst_light > 1.55
    assert worst_heavy == pytest.approx(1.0, abs=1e-3)


def test_run_config_validation():
    with pytest.raises(ParameterError, match=r"dt must be in \(0, 0\.1\] s"):
        RunConfig(dt=0.0)
    with pytest.raises(ParameterError, match="controller must be one of"):
        RunConfig(controller="pid")


def test_collision_fails():
    s = Scenario(0, generate(1)[0].waypoints, ((1.0, 0.0, 0.3),))
    tally = _Tally(ROBOT, s, RunConfig())
    assert not tally.check((0.4, 0.0, 0.0, -0.7, 1.57))  # 0.6 m > 0.3 + 0.285
    assert tally.check((0.42, 0.0, 0.0, -0.7, 1.57))
    assert tally.reason == "collision"


def test_thesis_run_metrics_are_consistent():
    s = generate(1, 0)[0]
    m = run_scenario(s, RunConfig()).metrics
    assert m["success"] and m["reason"] == "ok" and m["waypoints_reached"] == 5
    parts = m["time_base_s"] + m["time_arm_s"] + m["time_manipulability_s"]
    parts += m["time_stability_s"] + m["time_obstacle_s"]
    assert parts == pytest.approx(m["time_s"], abs=1e-9)
    assert m["speed_m_s"] == pytest.approx(s.path_length() / m["time_s"])
    assert m["min_stability"] > 1.0
    assert m["sim_steps"] == round(m["time_s"] / 0.01)


def test_timeout_is_a_failure():
    m = run_scenario(generate(1, 0)[0], RunConfig(time_limit=5.0)).metrics
    assert (m["success"], m["reason"], m["time_s"]) == (False, "timeout", pytest.approx(5.0))
    assert m["waypoints_reached"] < 5


def test_high_threshold_without_hysteresis_oscillates_in_stability():
    m = run_scenario(generate(1, 0)[0], RunConfig(stability=(1.5, 1.5), time_limit=20)).metrics
    assert m["transitions_stability"] > 20  # thesis 5.3.2: many re-entries without hysteresis


def test_qp_controller_runs_on_both_plants_with_state_metrics_not_applicable():
    s = Scenario(0, ((1.0, 0.5), (1.5, 1.0), (1.0, 1.5), (0.5, 1.0), (1.0, 0.5)))
    for plant in ("kinematic", "thesis"):
        m = run_scenario(s, RunConfig(controller="qp", plant=plant, time_limit=30.0)).metrics
        assert m["success"], (plant, m["reason"])
        assert m["min_stability"] > 1.0
        assert math.isnan(m["time_stability_s"]) and math.isnan(m["transitions_stability"])
        assert 0.0 < m["time_base_s"] <= m["time_s"] + 1e-9


def test_velocity_loop_tracks_commanded_speeds_on_thesis_plant():
    """The qp adapter: damping feed-forward gives exact steady-state tracking."""
    from ddwmmr.plants.thesis import ThesisPlant, ThesisState, VelocityServo

    plant = ThesisPlant(ROBOT)
    loop = VelocityServo(plant)
    state = ThesisState(0.0, 0.0, 0.0, -0.7, 1.57)
    for _ in range(300):  # 3 s = 30 loop time constants
        plant.advance(state, *loop.forces(state, 0.5, 0.3), (-0.7, 1.57), 0.01)
    assert (state.v, state.w) == pytest.approx((0.5, 0.3), abs=1e-6)
    # beyond the force limit the base settles at its top speed 20 N / c1
    for _ in range(1000):
        plant.advance(state, *loop.forces(state, 3.0, 0.0), (-0.7, 1.57), 0.01)
    assert state.v == pytest.approx(20.0 / 15.0, rel=1e-4)  # 10 s = 10 time constants m/c1


# -- executors ----------------------------------------------------------------------------
def _metrics(outcomes):
    return metrics_csv(outcomes)  # text compare: NaN fields compare equal


def test_local_executor_job_count_does_not_change_results():
    scenarios = generate(4, 3)
    config = RunConfig(time_limit=8.0)
    one = run_many(scenarios, config, jobs=1)
    two = run_many(scenarios, config, jobs=2)
    assert _metrics(one) == _metrics(two)
    assert [o.metrics["scenario"] for o in two] == [1, 2, 3, 4]


def test_dask_local_cluster_gives_identical_results():
    scenarios = generate(3, 3)
    config = RunConfig(time_limit=8.0)
    local = run_many(scenarios, config, jobs=1)
    done = []
    dask = run_many(
        scenarios,
        config,
        jobs=1,
        executor="dask",
        cluster_options={"processes": False},
        on_done=done.append,
    )
    assert _metrics(dask) == _metrics(local)
    assert sum(done) == 3


def test_dask_scheduler_address_path():
    """``--scheduler ADDRESS``: connect to a running cluster instead of starting one."""
    from dask.distributed import LocalCluster

    from test_cli_dask import NO_FIXED_PORT

    scenarios = generate(2, 5)
    config = RunConfig(time_limit=6.0)
    with LocalCluster(
        n_workers=1, processes=False, dashboard_address=None, scheduler_kwargs=NO_FIXED_PORT
    ) as cluster:
        remote = run_many(scenarios, config, executor="dask", scheduler=cluster.scheduler_address)
    assert _metrics(remote) == _metrics(run_many(scenarios, config))


def test_summary_mean_and_sample_sd():
    outcomes = run_many(generate(3, 3), RunConfig(time_limit=8.0), jobs=1)
    summary = summarize(outcomes, wall_time_s=2.0)
    times = [o.metrics["time_s"] for o in outcomes]
    assert summary["mean_time_s"] == pytest.approx(sum(times) / 3)
    assert summary["sd_time_s"] == pytest.approx(float(np.std(times, ddof=1)))
    assert summary["failed"] == 3  # 8 s is too short for five waypoints
    assert summary["sim_seconds_per_wall_second"] == pytest.approx(sum(times) / 2.0)
