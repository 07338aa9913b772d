"""The speed budget: v and w of a damped, force-limited base share one wheel-force budget.

Before it, the ``qp`` failed 6 of the 100 thesis scenarios on the MuJoCo plant by timeout:
at a corner of its (v, w) speed box a wheel servo saturates, the base keeps its speed but
loses its yaw (commanded 1.2 rad/s, measured 0.13) and drives in wide loops (44 m of base
path for 33 m of waypoints in scenario 10).
"""

import math

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, make_controller, simulate
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError
from ddwmmr.plants.mujoco import MujocoPlant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState, damped_base_envelope
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits import SpeedBudgetLimit
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.protocol import make_scenario_plant

ROBOT = Robot().with_payload(3.0)


def _budget(plant: ThesisPlant) -> tuple[float, float]:
    return damped_base_envelope(
        plant.force_limit, plant.c1, plant.c2, plant.mass, 0.5 * ROBOT.base_width, 1.0,
        speed_budget=True,
    )["speed_budget"]  # fmt: skip


@pytest.mark.parametrize("ratio", [-1.0, -0.6, 0.0, 0.35, 1.0])
def test_budget_edge_is_where_one_wheel_force_is_at_its_limit(ratio):
    # Independent check through the plant's own dynamics: hold the right wheel at its force
    # limit and the left at a share of it; the base settles on the budget's edge.
    plant = ThesisPlant(ROBOT)
    v_top, w_top = _budget(plant)
    state = ThesisState()
    for _ in range(4000):
        plant.advance(state, ratio * plant.force_limit, plant.force_limit, (0.0, 0.0), 0.01)
    assert abs(state.v) / v_top + abs(state.w) / w_top == pytest.approx(1.0, rel=1e-6)


def test_rows_accept_exactly_the_diamond():
    limit = SpeedBudgetLimit((2.0, 0.5))
    G, lower, upper = np.zeros((2, 4)), np.zeros(2), np.zeros(2)
    limit.compute(StepContext(ROBOT, 0.01), G, lower, upper, np.zeros(4), np.zeros(4))
    rng = np.random.default_rng(3)
    for v, w in rng.uniform([-3.0, -0.8], [3.0, 0.8], size=(500, 2)):
        rows = G @ np.array([v, w, 0.7, -0.4])
        inside_rows = bool(np.all(rows >= lower) and np.all(rows <= upper))
        assert inside_rows == (abs(v) / 2.0 + abs(w) / 0.5 <= 1.0)


@pytest.mark.parametrize("bad", [(1.0,), (0.0, 1.0), (1.0, -2.0), (math.nan, 1.0), "ab", 3.0])
def test_bad_speed_budget_is_refused(bad):
    with pytest.raises(ParameterError, match="speed_budget"):
        make_controller("qp", ROBOT, speed_budget=bad)


def test_commands_stay_within_the_budget_and_use_it():
    envelope = damped_base_envelope(20.0, 15.0, 4.0, 40.0, 0.175, 3.0, speed_budget=True)
    v_top, w_top = envelope["speed_budget"]
    controller = make_controller(
        "qp", ROBOT, track_orientation=False, max_speed=1.0, dt=0.01, **envelope
    )
    q = np.array([0.0, 0.0, 0.0, 0.0, 1.2])
    controller.reset(None, q)
    used = []
    for k in range(600):
        goal = np.array([4.0, 0.0, 0.0]) if k < 250 else np.array([2.0, 3.0, 0.0])
        u = controller.command(k * 0.01, q, goal, np.zeros(3))
        used.append(abs(u[0]) / v_top + abs(u[1]) / w_top)
        q = q + 0.01 * np.array([u[0] * math.cos(q[2]), u[0] * math.sin(q[2]), *u[1:]])
    assert max(used) <= 1.0 + 1e-6
    assert max(used) > 0.99  # driving fast, then turning: the budget binds


def test_mujoco_envelope_carries_the_budget_and_the_thesis_plant_does_not():
    plant = make_scenario_plant(ROBOT, RunConfig(plant="mujoco"))
    assert isinstance(plant, MujocoPlant)
    force = ROBOT.wheel_torque_limit / ROBOT.wheel_radius  # per wheel (N)
    v_top, w_top = plant.velocity_envelope()["speed_budget"]
    assert v_top == pytest.approx(2 * force / 15.0)
    assert w_top == pytest.approx(2 * force * 0.5 * ROBOT.base_width / 4.0)
    # Its servo turns with priority: corners of the speed box cost speed, not yaw.
    assert "speed_budget" not in ThesisPlant(ROBOT).velocity_envelope()


def test_previously_looping_scenario_completes_on_the_physics_plant():
    scenario = generate(100, seed=0)[9]  # scenario 10: 33 m of waypoints
    outcome = run_scenario(scenario, RunConfig(controller="qp", plant="mujoco", record=True))
    assert outcome.metrics["success"], outcome.metrics["reason"]
    assert outcome.metrics["min_stability"] > 1.25
    trace = outcome.trace
    base_path = float(np.sum(np.hypot(np.diff(trace["x"]), np.diff(trace["y"]))))
    assert base_path < 1.2 * scenario.path_length()  # was 1.35 x, in loops


@pytest.mark.parametrize(
    ("budget", "message"),
    [
        ((1e-300, 1e-300), "speed_budget v_top must be >= 1e-06 m/s"),
        ((5e-324, 1.0), "speed_budget v_top must be >= 1e-06 m/s"),
        ((1.0, 1e-300), "speed_budget w_top must be >= 1e-06 rad/s"),
    ],
)
def test_a_top_too_small_for_the_solvers_is_refused(tmp_path, capsys, budget, message):
    """With tops of 1e-300 the rows' coefficients 1/top overflowed the solvers: DAQP
    dropped the rows (the base drove at 0.24 m/s through a 1e-300 m/s budget and the run
    "tracked"), OSQP raised its own error from inside the run."""
    with pytest.raises(ParameterError, match=f"^{message}, a row the QP solvers can hold"):
        make_controller("qp", ROBOT, speed_budget=budget)
    out = tmp_path / "run"
    text = ",".join(repr(top) for top in budget)
    args = ["--method", "qp", "--traj", "ellipse", "--option", f"speed_budget={text}"]
    assert track([*args, "--no-plots", "--out", str(out)]) == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith(f"error: {message}")
    assert not out.exists()


def test_the_least_top_is_held():
    """At the least tops the rows still hold: the base stays within the budget."""
    budget = (1e-6, 1e-6)
    result = simulate(ROBOT, load_trajectory("ellipse"), "qp", duration=0.2, speed_budget=budget)
    v, w = result.timeseries["v"], result.timeseries["w"]
    assert np.max(np.abs(v) / budget[0] + np.abs(w) / budget[1]) <= 1.0 + 1e-6
