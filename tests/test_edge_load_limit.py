"""Minimum edge load as a constraint: the qp's rows and the mpc's, against the model."""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, simulate
from ddwmmr.commands import PlantTraits, traits_of
from ddwmmr.controllers import make_controller
from ddwmmr.model import symbolic as sym
from ddwmmr.model.support_loads import EdgeLoadModel
from ddwmmr.mpc.models import LaggedArmPrediction
from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP
from ddwmmr.mpc.options import MPCOptions
from ddwmmr.plants import KinematicPlant, MujocoPlant, ThesisPlant
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import INF, Limit
from ddwmmr.qp.limits.edge_loads import EdgeLoadLimit
from ddwmmr.qp.problem import QPProblem
from ddwmmr.trajectories.parametric import Rectangle

ROBOT = Robot().with_payload(3.0)
MODEL = EdgeLoadModel.from_robot(ROBOT)
TAU = 0.02


def _step(rng, dt=0.02):
    """A limit with a random measured motion and its step context."""
    limit = EdgeLoadLimit(ROBOT, 0.1, TAU, (12.8, 33.3))
    ctx = StepContext(ROBOT, dt)
    q = np.array([*rng.uniform(-2, 2, 3), *rng.uniform(-2.5, 2.5, 2)])
    ctx.update(0.0, q, np.zeros(3), np.zeros(3))
    limit.observe(*rng.uniform(-1, 1, 2))
    limit.rates = tuple(rng.uniform(-2, 2, 2))
    return limit, ctx


def test_each_row_is_the_edge_load_of_the_lagged_servos_response(rng):
    """L0 + G u is the model's edge load with the servos' mean accelerations over the
    step, ``(u - rate)(1 - exp(-dt/tau))/dt``, and the lateral acceleration v w
    linearised at the measured (v, w): exact, for any command."""
    for _ in range(20):
        dt = rng.uniform(0.005, 0.05)
        limit, ctx = _step(rng, dt)
        u = rng.uniform(-1.5, 1.5, 4)
        limit.rows_and_floors(ctx)
        predicted = limit.predict(u.tolist())
        k = (1.0 - math.exp(-dt / TAU)) / dt
        v, w, (r1, r2) = limit.v, limit.w, limit.rates
        expected = MODEL.loads(
            ctx.th1,
            ctx.th2,
            (r1, r2),
            ((u[2] - r1) * k, (u[3] - r2) * k),
            ((u[0] - v) * k, v * u[1] + w * u[0] - v * w),
            w,
            (u[1] - w) * k,
        )
        assert predicted == pytest.approx(expected, abs=1e-9 * MODEL.weight)


def test_the_compiled_writer_writes_what_compute_does(rng):
    limit, ctx = _step(rng)
    """The fast path (the problem's compiled writer) and ``compute`` fill the same rows,
    bounds and joint window; the bound asks for at most half of what the box lets the
    row reach."""
    limit, ctx = _step(rng)
    box_limit = _BoxLimit()
    fast = QPProblem([], [box_limit, limit])
    assert fast._all_compiled
    fast.build(ctx)
    G, lower, upper = np.zeros((4, 4)), np.zeros(4), np.zeros(4)
    lb, ub = np.full(4, -1.0), np.full(4, 1.0)
    limit.compute(ctx, G, lower, upper, lb, ub)
    assert fast.C[:, :4] == pytest.approx(G, abs=1e-12)
    assert fast.cl == pytest.approx(lower, abs=1e-12)
    assert fast.box[:4] == pytest.approx(lb.tolist()) and fast.box[4:] == pytest.approx(ub)
    window = limit.joint_window()
    for j in (2, 3):  # the joints' commands within rate +- a tau, inside the box
        assert max(-1.0, window[j - 2][0]) == pytest.approx(lb[j])
        assert min(1.0, window[j - 2][1]) == pytest.approx(ub[j])
    box = [*lb, *ub]
    for row, floor, bound in zip(*limit.rows_and_floors(ctx), lower):
        reach = sum(max(g * box[j], g * box[4 + j]) for j, g in enumerate(row))
        assert bound == pytest.approx(min(floor, 0.5 * reach))
    assert EdgeLoadLimit.capped([1.0, 2.0, 0.0, 0.0], 5.0, [-INF] * 4 + [INF] * 4) == 5.0


class _BoxLimit(Limit):
    """The box +-1 on every input (compiled), standing for the wheel and joint limits."""

    rows = 0
    name = "unit box"

    def compute(self, ctx, G, lower, upper, lb, ub):
        lb[:] = np.maximum(lb, -1.0)
        ub[:] = np.minimum(ub, 1.0)

    def compile(self, block):
        def write(ctx):
            for j in range(4):
                block.box[j] = max(block.box[j], -1.0)
                block.box[4 + j] = min(block.box[4 + j], 1.0)

        return write


def test_the_advance_follows_the_first_order_lag():
    limit = EdgeLoadLimit(ROBOT, 0.1, TAU)  # no acceleration limit: the lag alone
    for _ in range(200):
        limit.advance([0.0, 0.0, 1.0, -0.5], 0.01)
    assert limit.rates == pytest.approx((1.0, -0.5), abs=1e-12)
    limit.reset()
    limit.advance([0.0, 0.0, 1.0, 0.0], TAU)
    assert limit.rates[0] == pytest.approx(1.0 - math.exp(-1.0))
    saturated = EdgeLoadLimit(ROBOT, 0.1, TAU, (12.8, 33.3))
    saturated.advance([0.0, 0.0, 2.0, -2.0], 0.01)  # the motors' most in 10 ms
    assert saturated.rates == pytest.approx((0.128, -0.333))


@pytest.mark.parametrize("value", [-0.1, 0.5, 1.0, float("nan"), "0.1", True])
def test_a_bad_min_edge_load_is_one_line_naming_the_option(value):
    for make in (
        lambda: make_controller("qp", ROBOT, min_edge_load=value),
        lambda: MPCOptions(min_edge_load=value),
    ):
        with pytest.raises(
            ParameterError, match=r"min_edge_load must be a share of the weight in \[0, 0\.5\)"
        ) as error:
            make()
        assert "\n" not in str(error.value)


def test_the_qp_keeps_edge_loads_where_the_plant_has_physics():
    qp = make_controller("qp", ROBOT)
    for plant in (KinematicPlant(ROBOT), ThesisPlant(ROBOT)):
        qp.adopt_plant(traits_of(plant))
        assert qp.edge_loads is None and not qp.wants_base_velocity
    qp.adopt_plant(traits_of(MujocoPlant(ROBOT)))
    assert qp.edge_loads is not None and qp.wants_base_velocity
    assert qp.edge_loads.floor_n == pytest.approx(0.1 * MODEL.weight)
    assert qp.limits.count(qp.edge_loads) == 1
    qp.adopt_plant(traits_of(MujocoPlant(ROBOT)))  # again: still one
    assert sum(isinstance(limit, EdgeLoadLimit) for limit in qp.limits) == 1
    off = make_controller("qp", ROBOT, min_edge_load=None)
    off.adopt_plant(PlantTraits(("velocity",), True, 0.02))
    assert off.edge_loads is None


def test_the_mpc_rows_are_the_edge_loads_of_its_force_model(rng):
    """The OCP's first-interval edge loads (what the summary reports) are the model's
    with the lagged arm's accelerations and the force model's base accelerations."""
    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    model = LaggedArmPrediction(ROBOT, dynamics, TAU, (12.8, 33.3))
    config = OCPConfig(intervals=4, control_interval=0.02, horizon=1.0, dynamic_stability=True)
    ocp = ShootingOCP(ROBOT, model, config)
    import casadi as ca

    for _ in range(5):
        w = rng.uniform(-1.0, 1.0, ocp.nw)
        p = rng.uniform(-1.0, 1.0, ocp.np)
        loads = ocp.first_edge_loads(w, p).full().ravel()
        x0, u0 = w[ocp.x_slices[0]], w[ocp.u_slices[0]]
        rate = ca.DM(model.rhs(ca.DM(x0), ca.DM(u0))).full().ravel()
        v, yaw = x0[5], x0[6]
        rates = x0[7:9]
        accelerations = (u0[2:4] - rates) / TAU
        expected = MODEL.loads(x0[3], x0[4], rates, accelerations, (rate[5], v * yaw), yaw, rate[6])
        assert loads[:4] == pytest.approx(expected, abs=1e-9 * MODEL.weight)


def test_the_mpc_bounds_every_edge_in_metres_with_the_stability_slacks():
    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    model = LaggedArmPrediction(ROBOT, dynamics, TAU, (12.8, 33.3))
    config = OCPConfig(intervals=3, horizon=1.0, dynamic_stability=True, min_edge_load=0.2)
    ocp = ShootingOCP(ROBOT, model, config)
    # every edge at both ends of each of the 3 intervals and once more at the last node
    # with the arm braked to rest, its floor 0.2 D_e in metres
    expected = sorted(0.2 * d for d in MODEL.polygon.depths.tolist() * (2 * 3 + 1))
    assert sorted(ocp.lbg[ocp.lbg > 0.0].tolist()) == pytest.approx(expected)
    static = ShootingOCP(ROBOT, model, OCPConfig(intervals=3, horizon=1.0))
    assert static.first_edge_loads is None


RECTANGLE = Rectangle(T=10.0)  # corners every 2.5 s: the base brakes and turns hard


def _rectangle(method: str, duration: float = 10.0, **options):
    """``duration`` s (default: one lap, 10 s) of the fast rectangle on MuJoCo (3 kg, the
    scenarios' base damping)."""
    return simulate(
        ROBOT,
        RECTANGLE,
        method,
        stability_min=1.25,
        plant="mujoco",
        dt=0.02,
        duration=duration,
        plant_options={"base_damping": (15.0, 4.0)},
        **options,
    ).summary


def test_the_qp_keeps_the_edge_loaded_that_lifts_without_the_constraint():
    """Without the edge rows an edge unloads at a corner (0 N measured); with them the
    measured load stays above 10 N and the predicted one at the floor (14.7 N)."""
    off = _rectangle("qp", min_edge_load=None)
    on = _rectangle("qp")
    assert off["min_edge_load_n"] < 1.0 and off["unloaded_time_s"] > 0.0
    assert on["unloaded_time_s"] == 0.0 and on["min_edge_load_n"] > 10.0
    assert on["min_predicted_edge_load_n"] >= 0.1 * MODEL.weight - 1e-6
    assert on["min_edge_load_floor_n"] == pytest.approx(0.1 * MODEL.weight)
    assert off["min_predicted_edge_load_n"] is None and not on["tipped"]


def test_the_mpc_keeps_the_edges_loaded_that_lift_without_the_floor():
    """The mpc's edge rows at 0 (the centre of pressure merely inside the polygon) leave
    an edge unloaded for a while at the first corner; at the default 10 % of the weight
    far less, and the plans predict at least about the floor. The first corner is at
    2.5 s: 3.5 s of the lap see it through."""
    bare = _rectangle("mpc", 3.5, min_edge_load=0.0)
    floor = _rectangle("mpc", 3.5)
    assert bare["unloaded_time_s"] >= 0.1
    assert floor["unloaded_time_s"] <= 0.5 * bare["unloaded_time_s"]
    assert floor["min_predicted_edge_load_n"] > 0.09 * MODEL.weight
    assert bare["min_predicted_edge_load_n"] > -1.0  # the plans hold the floor they have
