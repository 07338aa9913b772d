"""Bad input to the controller and plant APIs called directly is one ParameterError naming the
parameter, the state is left as it was, and the qp's step info holds no NaN.

Covers ``Controller.command`` / ``reset`` with integers beyond a float, ``reset`` and
``step`` of the three built-in plants, the MuJoCo plant's timestep range and its cap on
engine steps per control step, and the ``slack`` of the qp's fallback steps.
"""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, make_controller
from ddwmmr.commands import WheelForces
from ddwmmr.plants import KinematicPlant, MujocoPlant, PlantNotResetError, ThesisPlant
from ddwmmr.qp.controller import QPController
from ddwmmr.qp.limits import Limit
from ddwmmr.trajectories import Ellipse
from one_line import one_line

ROBOT = Robot()
TRAJECTORY = Ellipse()
Q = np.array([0.0, 0.0, 0.3, -0.3, 0.6])
HUGE = 10**400  # a Python integer no float can hold
METHODS = ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp", "mpc"]


def _refused(call, match: str) -> str:
    with pytest.raises(ParameterError, match=match) as info:
        call()
    return one_line(info)


# -- controllers ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def controllers():
    built = {}
    for method in METHODS:
        controller = make_controller(method, ROBOT)
        controller.reset(TRAJECTORY, Q)
        built[method] = controller
    return built


def _with_huge(argument: str, form: str) -> dict:
    """``command``'s arguments with an integer beyond a float in ``argument`` (its second
    entry, held in a list or an object array; ``t`` itself)."""
    args = {
        "t": 0.0,
        "q": Q,
        "pose_d": TRAJECTORY.pose(0.0),
        "velocity_d": TRAJECTORY.velocity(0.0),
    }
    if argument == "t":
        args["t"] = HUGE
        return args
    values = [float(v) for v in args[argument]]
    values[1] = HUGE
    args[argument] = values if form == "list" else np.array(values, dtype=object)
    return args


HUGE_CASES = [("t", "int")] + [
    (argument, form)
    for argument in ("q", "pose_d", "velocity_d")
    for form in ("list", "object array")
]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(("argument", "form"), HUGE_CASES)
def test_command_refuses_an_integer_beyond_a_float(controllers, method, argument, form):
    args = _with_huge(argument, form)
    message = _refused(lambda: controllers[method].command(**args), f"^{argument} must be")
    assert "finite" in message


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("entry", ["0.3", True, None])
def test_command_refuses_text_and_booleans_as_numbers(controllers, method, entry):
    """numpy reads "0.3" and True as numbers; a command built from them would be a guess."""
    args = _with_huge("q", "list")
    args["q"][1] = entry
    message = _refused(lambda: controllers[method].command(**args), "^q must be 5 finite")
    assert repr(entry) in message


@pytest.mark.parametrize("method", METHODS)
def test_every_reset_names_q0(method):
    controller = make_controller(method, ROBOT)
    for q0 in ([0.0, 0.0, HUGE, 0.0, 0.0], [0.0, 0.0, math.nan, 0.0, 0.0], [0.0, 0.0, 0.0]):
        message = _refused(lambda q0=q0: controller.reset(TRAJECTORY, q0), "^q0 must be 5")
        assert "[x, y, phi, th1, th2]" in message
    controller.reset(TRAJECTORY, Q.tolist())  # a list of floats is a start as an array is


# -- plants --------------------------------------------------------------------------------
@pytest.fixture(scope="module", params=["kinematic", "thesis", "mujoco"])
def plant(request):
    return {"kinematic": KinematicPlant, "thesis": ThesisPlant, "mujoco": MujocoPlant}[
        request.param
    ](ROBOT)


def _state(plant):
    obs = plant.observe()
    return (*obs.values, obs.v, obs.w)


@pytest.mark.parametrize(
    "q0",
    [
        [0.0, 0.0, math.nan, -0.3, 0.6],
        [0.0, 0.0, math.inf, -0.3, 0.6],
        [0.0, 0.0, HUGE, -0.3, 0.6],
        [0.0, 0.0, 0.3],
        np.zeros((5, 1)),
        "abcde",
        None,
        [0.0, 0.0, "0.3", -0.3, 0.6],
        [0.0, 0.0, True, -0.3, 0.6],
    ],
)
def test_plant_reset_names_q0_and_keeps_the_state(plant, q0):
    plant.reset(Q, 0.02)
    before = _state(plant)
    message = _refused(lambda: plant.reset(q0, 0.02), "^q0 must be 5 finite numbers")
    assert "[x, y, phi, th1, th2]" in message
    assert _state(plant) == before


@pytest.mark.parametrize("dt", [0.0, -0.02, math.nan, math.inf, "0.02", None])
def test_plant_reset_names_dt(plant, dt):
    _refused(lambda: plant.reset(Q, dt), "^dt must be")


VELOCITY_FORM = r"4 finite numbers u = \[v, w, th1dot, th2dot\] \(m/s, rad/s, rad/s, rad/s\)"


@pytest.mark.parametrize(
    "command",
    [
        np.array([math.nan, 0.0, 0.0, 0.0]),
        np.array([0.0, math.inf, 0.0, 0.0]),
        [0.1, 0.0, -math.inf, 0.0],
        (HUGE, 0.0, 0.0, 0.0),
        np.zeros(3),
        np.zeros((4, 1)),
        np.zeros(5),
        "abcd",
        None,
        [True, 0.0, 0.0, 0.0],
        WheelForces(math.nan, 0.0, 0.0, 0.0),
        WheelForces("1", 0.0, 0.0, 0.0),
    ],
)
def test_plant_step_names_the_command_and_keeps_the_state(plant, command):
    plant.reset(Q, 0.02)
    plant.step(0.0, np.array([0.2, 0.1, 0.05, -0.05]), 0.02)
    before = _state(plant)
    message = _refused(lambda: plant.step(0.02, command, 0.02), f"^command must be {VELOCITY_FORM}")
    assert ("WheelForces(left, right" in message) == ("force" in plant.interfaces)
    assert _state(plant) == before


def test_a_non_finite_command_names_the_command(plant):
    plant.reset(Q, 0.02)
    for command in (np.array([0.0, math.nan, 0.0, 0.0]), [math.inf, 0.0, 0.0, 0.0]):
        with pytest.raises(ParameterError, match=r"^command must be"):
            plant.step(0.0, command, 0.02)


def test_kinematic_plant_refuses_wheel_forces():
    plant = KinematicPlant(ROBOT)
    plant.reset(Q, 0.02)
    message = _refused(
        lambda: plant.step(0.0, WheelForces(1.0, 1.0, 0.0, 0.0), 0.02), "^command must be"
    )
    assert "WheelForces(left" not in message.split("(got")[0]


@pytest.mark.parametrize(
    ("t", "dt", "name"),
    [
        (math.nan, 0.02, "t"),
        ("0", 0.02, "t"),
        (0.0, 0.0, "dt"),
        (0.0, -0.02, "dt"),
        (0.0, math.nan, "dt"),
        (0.0, "0.02", "dt"),
    ],
)
def test_plant_step_names_t_and_dt(plant, t, dt, name):
    plant.reset(Q, 0.02)
    before = _state(plant)
    _refused(lambda: plant.step(t, np.zeros(4), dt), f"^{name} must be")
    assert _state(plant) == before


@pytest.mark.parametrize(
    ("kind", "name"),
    [(KinematicPlant, "kinematic"), (ThesisPlant, "thesis"), (MujocoPlant, "mujoco")],
)
def test_a_step_before_the_first_reset_says_to_reset(kind, name):
    # The kinematic and thesis plants ran from q = 0 without a word; mujoco said
    # "reset(q0, dt) must be called before step" (no plant named).
    plant = kind(ROBOT)  # new: the module's plants have been reset
    with pytest.raises(PlantNotResetError) as info:
        plant.step(0.0, np.zeros(4), 0.02)
    assert isinstance(info.value, RuntimeError)
    assert one_line(info) == f"{name} plant: call reset(q0, dt) before step"
    plant.reset(Q, 0.02)  # then it steps, from the reset's state
    plant.step(0.0, np.zeros(4), 0.02)
    assert _state(plant)[:5] == pytest.approx(tuple(Q), abs=1e-3)


def test_valid_commands_of_any_sequence_type_give_the_same_state(plant):
    """Lists, tuples, float32 arrays and float64 arrays of the same numbers step alike."""
    states = []
    for form in (np.array, list, tuple, lambda u: np.array(u, dtype=np.float32)):
        plant.reset(Q, 0.02)
        for k in range(3):
            plant.step(0.02 * k, form([0.25, -0.5, 0.5, -0.25]), 0.02)  # float32-exact
        states.append(_state(plant))
    assert all(state == states[0] for state in states)
    if "force" in plant.interfaces:
        plant.reset(Q, 0.02)
        plant.step(0.0, WheelForces(3.0, 2.0, -0.2, 0.7), 0.02)
        assert all(math.isfinite(v) for v in _state(plant))


# -- the MuJoCo plant's timestep -----------------------------------------------------------
@pytest.mark.parametrize("timestep", [1e-7, 5e-6, 0.02, 1.0])
def test_mujoco_timestep_outside_its_range_is_refused(timestep):
    message = _refused(
        lambda: MujocoPlant(ROBOT, timestep=timestep, contact_time_constant=10.0),
        r"^timestep must be in \[1e-05, 0.01\] s",
    )
    assert f"{timestep:g}" in message


def test_mujoco_timestep_at_the_ends_of_its_range_builds():
    for timestep in (1e-5, 0.01):
        assert (
            MujocoPlant(ROBOT, timestep=timestep, contact_time_constant=0.05).timestep == timestep
        )


def test_mujoco_control_step_of_too_many_engine_steps_is_refused():
    plant = MujocoPlant(ROBOT)
    plant.reset(Q, 0.02)
    before = _state(plant)
    for dt in (20.002, 2000.0, 2e6):  # 10,001 and more engine steps of 2 ms
        message = _refused(lambda dt=dt: plant.reset(Q, dt), r"^dt must be a whole multiple")
        assert r"in [0.002, 20] s" in message
        _refused(lambda dt=dt: plant.step(0.0, np.zeros(4), dt), r"in \[0.002, 20\] s")
    assert _state(plant) == before
    plant.reset(Q, 0.2)  # 100 engine steps: within the cap


# -- the qp's slack on fallback steps --------------------------------------------------------
class _Contradiction(Limit):
    """A limit row with lower > upper: every solve fails, the fallback commands."""

    rows = 1

    def compute(self, ctx, G, lower, upper, lb, ub):
        G[0] = (1.0, 0.0, 0.0, 0.0)
        lower[0], upper[0] = 2.0, 1.0


@pytest.mark.parametrize("mode", ["weighted", "hierarchical"])
@pytest.mark.parametrize("track_orientation", [True, False])
def test_qp_fallback_reports_a_finite_slack(mode, track_orientation):
    q = np.array([0.0, 0.0, 0.0, -0.3, 0.6])  # S well above the floor: the arm stays still
    pose, velocity = ROBOT.fk(q), np.array([0.3, -0.1, 0.5])
    controller = QPController(
        ROBOT, limits=[_Contradiction()], mode=mode, track_orientation=track_orientation
    )
    controller.reset(TRAJECTORY, q)
    u = controller.command(0.0, q, pose, velocity)
    assert controller.last.fallback and np.array_equal(u, np.zeros(4))
    slack = controller.last.extra["slack"]
    # stopped on the pose itself: the whole feed-forward demand is missed, the phiE row's
    # only where the orientation is tracked
    expected = 0.5 if track_orientation else 0.3
    assert math.isfinite(slack) and slack == pytest.approx(expected, abs=1e-9)


def test_qp_slack_is_the_tracking_shortfall_of_its_command():
    """The number a fallback reports is what a QP answer's slack is, for its command."""
    controller = QPController(ROBOT)
    q = np.array([0.1, -0.2, 0.4, -0.5, 0.9])
    controller.reset(TRAJECTORY, q)
    u = controller.command(
        0.0, q, ROBOT.fk(q) + np.array([0.05, 0.02, 0.1]), np.array([2.0, 1.0, 2.0])
    )
    info = controller.last
    assert not info.fallback and info.extra["arm_scale"] == 1.0  # u is the QP's answer
    assert info.extra["slack"] > 1e-3  # a demand beyond the limits: the slack is used
    shortfall = controller.tracking_shortfall(controller.ctx, u)
    assert shortfall == pytest.approx(info.extra["slack"], rel=1e-6)
