"""The mpc's dynamic tip-over margin and lagged arm: the model's integration, the options,
and the physics plant's verdict with and without them."""

import math
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, simulate
from ddwmmr.commands import traits_of
from ddwmmr.controllers import make_controller
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc.models import LaggedArmPrediction
from ddwmmr.plants import MujocoPlant, ThesisPlant
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.protocol import make_scenario_controller, make_scenario_plant
from mpc_plans import converged_reach_plan

ROBOT = Robot().with_payload(3.0)


def test_the_lagged_arm_is_integrated_like_its_own_ode():
    """The exact lag plus RK4 for the base (with the arm's yaw reaction) against classical
    RK4 on the full 9-state ODE in 2000 steps."""
    model = LaggedArmPrediction(ROBOT, sym.ThesisDynamics.from_robot(ROBOT), tau=0.02)
    x, u = ca.SX.sym("x", 9), ca.SX.sym("u", 4)
    rhs = ca.Function("rhs", [x, u], [model.rhs(x, u)])
    step = ca.Function("step", [x, u], [model.integrate(x, u, 0.4, 40)])
    coarse = ca.Function("coarse", [x, u], [model.integrate(x, u, 0.4, 2)])
    x0 = np.array([0.1, -0.2, 0.3, -0.8, 1.2, 0.4, -0.6, 1.5, -1.0])
    u0 = np.array([6.0, -3.0, -2.0, 1.0])
    state, h = x0.copy(), 0.4 / 2000
    for _ in range(2000):
        k1 = np.asarray(rhs(state, u0)).ravel()
        k2 = np.asarray(rhs(state + 0.5 * h * k1, u0)).ravel()
        k3 = np.asarray(rhs(state + 0.5 * h * k2, u0)).ravel()
        k4 = np.asarray(rhs(state + h * k3, u0)).ravel()
        state = state + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    exact = np.asarray(step(x0, u0)).ravel()
    np.testing.assert_allclose(exact[[3, 4, 7, 8]], state[[3, 4, 7, 8]], atol=1e-10)
    np.testing.assert_allclose(exact, state, atol=1e-6)
    # the OCP's two 0.2 s sub-steps after a 3.5 rad/s jump of the commanded rates
    np.testing.assert_allclose(np.asarray(coarse(x0, u0)).ravel(), state, atol=0.03)
    assert exact[7:9] == pytest.approx(u0[2:4] + (x0[7:9] - u0[2:4]) * math.exp(-20.0))


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"model": "kinematic", "dynamic_stability": True}, "dynamic_stability"),
        ({"model": "kinematic", "arm_time_constant": 0.02}, "arm_time_constant"),
        ({"model": "thesis", "arm_time_constant": 5e-4}, "arm_time_constant"),
        ({"model": "thesis", "arm_time_constant": 5.0}, "arm_time_constant"),
        ({"model": "thesis", "dynamic_stability": "yes"}, "dynamic_stability"),
        ({"model": "kinematic", "wheel_force_limit": 5.0}, "wheel_force_limit"),
        ({"model": "thesis", "wheel_force_limit": 0.0}, "wheel_force_limit"),
        ({"wheel_force_limit": math.nan}, "wheel_force_limit"),
    ],
)
def test_bad_options_are_refused(options, match):
    with pytest.raises(ParameterError, match=match):
        make_controller("mpc", ROBOT, **options)


def test_the_physics_plant_gets_the_dynamic_margin_and_the_lagged_arm():
    """The loop hands the mpc its plant's traits: on a plant that takes forces and judges
    tipping by its physics, the options not given become the force-level model, the
    dynamic margin and the plant's joint lag; options given win; other plants change
    nothing."""
    scenario = generate(1, 0)[0]
    physics = make_scenario_plant(ROBOT, RunConfig(plant="mujoco"))
    traits = traits_of(physics)
    mpc = make_controller("mpc", ROBOT)
    assert mpc.model_name == "kinematic" and mpc.interface == "velocity"  # not known yet
    mpc.adopt_plant(traits)
    assert (mpc.model_name, mpc.interface, mpc.wants_base_velocity) == ("thesis", "force", True)
    assert mpc.dynamic_stability and mpc.arm_time_constant == physics.joint_time_constant
    config = RunConfig(controller="mpc", plant="mujoco")
    protocol = make_scenario_controller(ROBOT, scenario, config, physics)
    protocol.adopt_plant(traits)
    assert protocol.dynamic_stability and protocol.arm_time_constant == physics.joint_time_constant
    static = make_controller("mpc", ROBOT, dynamic_stability=False, arm_time_constant=0.0)
    static.adopt_plant(traits)
    assert static.model_name == "thesis" and not static.dynamic_stability
    assert static.arm_time_constant is None  # 0: no lag
    asked = make_controller("mpc", ROBOT, dynamic_stability=True)  # what it would choose
    assert asked.model_name == "thesis"  # a force-model option implies the force model
    asked.adopt_plant(traits)
    assert asked.arm_time_constant == physics.joint_time_constant
    floor_only = make_controller("mpc", ROBOT, dynamic_stability=False)
    floor_only.adopt_plant(traits)  # the lag is the plant's all the same
    assert floor_only.arm_time_constant == physics.joint_time_constant
    kinematic = make_controller("mpc", ROBOT, model="kinematic")
    kinematic.adopt_plant(traits)
    assert kinematic.model_name == "kinematic" and not kinematic.dynamic_stability
    thesis = make_scenario_plant(ROBOT, RunConfig())
    plain = make_scenario_controller(ROBOT, scenario, RunConfig(controller="mpc"), thesis)
    plain.adopt_plant(traits_of(thesis))
    assert plain.model_name == "thesis" and not plain.dynamic_stability
    assert plain.arm_time_constant is None
    default = make_controller("mpc", ROBOT)
    default.adopt_plant(traits_of(thesis))  # takes forces, but its tipping is the formula's
    assert default.model_name == "kinematic"


def test_the_force_model_takes_the_plants_own_base():
    """The force model assumes the base the plant reports: its damping (none on the bare
    MuJoCo base, then its envelope caps no speed; the thesis damping where the plant
    carries it; the thesis plant's own c1, c2), the wheels' lever (MuJoCo: half the
    track) and on the thesis plant its ``force_limit``; the thesis plant's values when the
    plant says nothing."""
    bare = MujocoPlant(ROBOT)
    assert traits_of(bare).base_damping == (0.0, 0.0)
    mpc = make_controller("mpc", ROBOT)
    mpc.adopt_plant(traits_of(bare))
    assert (mpc.dynamics.c1, mpc.dynamics.c2) == (0.0, 0.0)
    envelope = mpc.dynamics.velocity_envelope()
    assert "max_base_speed" not in envelope and "max_yaw_rate" not in envelope
    assert envelope["max_acceleration"] == pytest.approx(0.8 * 2 * 10.0 / mpc.dynamics.mass)
    damped = make_scenario_plant(ROBOT, RunConfig(plant="mujoco"))
    mpc.adopt_plant(traits_of(damped))
    assert (mpc.dynamics.c1, mpc.dynamics.c2) == (15.0, 4.0)
    assert mpc.dynamics.top_speed == pytest.approx(2 * 10.0 / 15.0)
    narrow = Robot(track_width=0.3).with_payload(3.0)  # wheels inside the 0.35 m footprint
    on_narrow = make_controller("mpc", narrow)
    on_narrow.adopt_plant(traits_of(MujocoPlant(narrow)))
    assert on_narrow.dynamics.half_width == pytest.approx(0.15, rel=1e-12)
    thesis = ThesisPlant(ROBOT, c1=20.0, c2=5.0, force_limit=7.0)
    forced = make_controller("mpc", ROBOT, model="thesis")
    forced.adopt_plant(traits_of(thesis))  # the model is this plant's: its own limit
    assert (forced.dynamics.c1, forced.dynamics.c2) == (20.0, 5.0)
    assert forced.dynamics.force_limit == 7.0
    assert forced.dynamics.half_width == pytest.approx(0.5 * ROBOT.base_width, rel=1e-12)
    unknown = make_controller("mpc", ROBOT, model="thesis")  # no plant yet
    assert (unknown.dynamics.c1, unknown.dynamics.c2) == (15.0, 4.0)
    assert unknown.dynamics.force_limit == 10.0


def test_the_force_model_plans_within_the_motors_and_the_thesis_force_on_physics():
    """On a plant that judges tipping physically the force model plans with the thesis's
    10 N by default (the motors' 20.5 N tipped 27 of 100 scenarios), a limit asked for
    is taken, more than the plant's motors give is refused; asking for a limit implies the
    force model."""
    physics = traits_of(MujocoPlant(ROBOT))
    default = make_controller("mpc", ROBOT)
    default.adopt_plant(physics)
    assert default.dynamics.force_limit == 10.0
    motor_force = ROBOT.wheel_torque_limit / ROBOT.wheel_radius
    assert physics.wheel_force_limit == pytest.approx(motor_force, rel=1e-12)
    asked = make_controller("mpc", ROBOT, wheel_force_limit=15.0)
    assert asked.model_name == "thesis" and asked.dynamics.force_limit == 15.0
    asked.adopt_plant(physics)
    assert asked.dynamics.force_limit == 15.0
    too_much = make_controller("mpc", ROBOT, wheel_force_limit=50.0)
    with pytest.raises(ParameterError, match=r"must be <= the plant's motors, 20.51 N"):
        too_much.adopt_plant(physics)
    full = make_controller("mpc", ROBOT, wheel_force_limit=motor_force)
    full.adopt_plant(physics)
    assert full.dynamics.force_limit == motor_force
    weak = Robot(wheel_torque_limit=0.5).with_payload(3.0)  # 5.1 N motors
    on_weak = make_controller("mpc", weak)
    on_weak.adopt_plant(traits_of(MujocoPlant(weak)))
    # the thesis's share of its motors (10 N of 20.5 N), as the thesis plant derives it
    assert on_weak.dynamics.force_limit == pytest.approx(2.5, rel=1e-12)
    strong_thesis = make_controller("mpc", ROBOT, wheel_force_limit=12.0)
    with pytest.raises(ParameterError, match="wheel_force_limit must be <= the plant's"):
        strong_thesis.adopt_plant(traits_of(ThesisPlant(ROBOT)))  # its 10 N motors


def test_simulate_on_the_physics_plant_runs_the_force_model_with_the_dynamic_margin():
    """``simulate(..., plant=MujocoPlant)`` with the mpc's defaults: the loop's traits make
    it the force-level mpc with the dynamic margin (the kinematic model there planned
    velocity jumps the torque-limited base could not follow: on the whole ellipse a wheel
    slipped at 1.6 m/s and an edge of the support polygon lost its load)."""
    plant = MujocoPlant(ROBOT)
    result = simulate(ROBOT, Ellipse(T=1.0, N=50), "mpc", plant=plant)
    summary = result.summary
    assert summary["mpc_model"] == "thesis" and summary["mpc_dynamic_stability"]
    assert summary["command_interface"] == "force"  # chosen for this plant
    assert summary["mpc_arm_time_constant_s"] == plant.joint_time_constant
    assert summary["mpc_wheel_force_limit_n"] == 10.0  # the thesis's force, within 20.5 N
    assert not summary["tipped"] and summary["mpc_fallbacks"] == 0


def test_the_static_floor_tips_the_physics_plant_and_the_dynamic_margin_does_not():
    """Scenario 7 (seed 0): turning at 1.5 rad/s with the payload swung out, the static
    floor alone lets the outer edge take all the load within 0.6 s; holding the zero
    moment point with the lagged arm, the robot stays on all its supports: for 1.5 s,
    2.5 times the static run's tipping time."""
    scenario = generate(7, 0)[6]
    static = (("dynamic_stability", False), ("arm_time_constant", 0.0))
    config = RunConfig(controller="mpc", plant="mujoco", time_limit=1.5)
    tipped = run_scenario(scenario, replace(config, controller_options=static))
    assert tipped.metrics["reason"] == "tipped (physics)" and tipped.metrics["time_s"] < 0.8
    assert tipped.metrics["min_stability"] > 1.2  # the static margin saw nothing wrong
    held = run_scenario(scenario, config).metrics
    assert held["reason"] == "timeout" and held["waypoints_reached"] == 0
    assert held["unloaded_time_s"] < 0.2 * held["time_s"]


def test_a_swinging_arm_turns_a_free_base_as_the_momentum_balance_says():
    """MuJoCo, wheels without torque, the arm swinging at (1.5, -1) rad/s: the base yaws the
    other way, at the rate that keeps ``I(th2) w + H_arm`` zero (within 10 %: the base also
    translates under the arm's linear momentum, and the wheels spin). The thesis plant's
    arm has no such reaction; the lagged-arm prediction does."""
    from ddwmmr.commands import WheelForces
    from ddwmmr.plants.mujoco import MujocoPlant

    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    plant = MujocoPlant(ROBOT)
    plant.reset(np.array([0.0, 0.0, 0.0, -1.0, 0.8]), 0.01)
    for k in range(30):
        q = plant.observe().q
        plant.step(k * 0.01, WheelForces(0.0, 0.0, q[3] + 0.015, q[4] - 0.01), 0.01)
    obs = plant.observe()
    th2 = float(obs.q[4])
    predicted = -dynamics.arm_momentum(th2, (1.5, -1.0)) / dynamics.inertia(th2)
    assert predicted < -0.5  # a large reaction the base model without it calls zero
    assert obs.w == pytest.approx(predicted, rel=0.1)
    # the reaction term is the time derivative of that balance (finite differences)
    w, rates, accelerations = 0.3, (1.2, -0.7), (4.0, -3.0)
    h = 1e-6

    def balance(t):
        angle = 0.8 + rates[1] * t + 0.5 * accelerations[1] * t * t
        now = (rates[0] + accelerations[0] * t, rates[1] + accelerations[1] * t)
        return dynamics.inertia(angle), dynamics.arm_momentum(angle, now)

    (i0, h0), (i1, h1) = balance(-h), balance(h)
    # d/dt (I w + H) = I wdot_reaction + dI/dt w + dH/dt = 0 with wdot = the reaction
    reaction = dynamics.arm_yaw_reaction(0.8, w, rates, accelerations)
    assert dynamics.inertia(0.8) * reaction == pytest.approx(
        -((i1 - i0) * w + (h1 - h0)) / (2 * h), rel=1e-6
    )


def test_the_wheel_lever_from_the_traits_turns_the_physics_base_as_it_does():
    """Opposite wheel forces of 5 N for 0.1 s on MuJoCo bases with the wheels at the
    footprint's edge and inside it: the yaw rate the force model predicts with the
    plant's lever (``wheel_lever``, half the track) matches the physics within 1.5 %; the
    footprint's half-width would overstate it by 40 % on the narrow track."""
    from ddwmmr.commands import WheelForces

    q0 = np.array([0.0, 0.0, 0.0, -0.7, 1.57])
    for track in (0.35, 0.25):
        robot = Robot(track_width=track).with_payload(3.0)
        plant = MujocoPlant(robot)
        plant.reset(q0, 0.01)
        for k in range(10):
            plant.step(k * 0.01, WheelForces(-5.0, 5.0, q0[3], q0[4]), 0.01)
        lever = traits_of(plant).wheel_lever
        assert lever == pytest.approx(0.5 * track, rel=1e-12)
        model = sym.ThesisDynamics.from_robot(robot, 0.0, 0.0, half_width=lever)
        predicted = 2 * 5.0 * lever / model.inertia(q0[4]) * 0.1
        assert plant.observe().w == pytest.approx(predicted, rel=0.015)
    # the model's default lever is the track's too; the footprint's would be 40 % long
    assert sym.ThesisDynamics.from_robot(robot, 0.0, 0.0).half_width == lever
    assert 0.5 * robot.base_width / lever == pytest.approx(1.4, rel=1e-12)


def test_the_physics_plants_joint_acceleration_limit_is_what_its_shoulder_motor_gives():
    """On a base too heavy to yield, a shoulder rate step with the arm stretched and 3 kg
    at the tip accelerates at the plant's stated limit (torque limit over the stretched
    arm's inertia, 20 N m / 1.566 kg m^2) within 2 %, while the motor is saturated."""
    robot = Robot(base_mass=500.0, base_inertia=200.0).with_payload(3.0)
    plant = MujocoPlant(robot)
    shoulder, elbow = traits_of(plant).joint_acceleration_limit
    assert shoulder == pytest.approx(20.0 / 1.5658333, rel=1e-6)
    assert elbow == pytest.approx(10.0 / 0.3, rel=1e-9)
    plant.reset(np.zeros(5), 0.01)
    angles = [0.0]
    for k in range(7):
        plant.step(0.01 * k, np.array([0.0, 0.0, 2.0, 0.0]), 0.01)
        angles.append(float(plant.observe().q[3]))
    rates = np.diff(angles) / 0.01
    accelerations = np.diff(rates[1:]) / 0.01  # after the first step's settling
    np.testing.assert_allclose(accelerations, shoulder, rtol=0.02)


def test_the_lagged_arm_plans_within_the_joint_acceleration_limit():
    """The mpc takes the physics plant's limit with its lagged arm, and its first command
    after a rate of 1.5 rad/s keeps (u - rate) / tau within it; 0 turns it off, a bad value
    is refused, and without a lag it is refused once the plant is known. (The scenarios'
    MuJoCo plant: its problem is the held run's of scenario 7 above, built once.)"""
    physics = traits_of(make_scenario_plant(ROBOT, RunConfig(plant="mujoco")))
    mpc = make_controller("mpc", ROBOT, dt=0.01)
    mpc.adopt_plant(physics)
    assert mpc.joint_acceleration_limit == physics.joint_acceleration_limit
    mpc.reset(None, np.zeros(5))
    mpc._predicted_rates = (1.5, -1.0)  # the lagged joints' rates (no sensor reports them)
    q = np.array([0.0, 0.0, 0.0, -0.7, 1.5])
    command = mpc.command(0.0, q, np.array([2.0, -1.0, 0.0]), np.zeros(3), base_velocity=(0, 0))
    tau = mpc.arm_time_constant
    rates = ((command.th1_target - q[3]) / 0.01, (command.th2_target - q[4]) / 0.01)
    for rate, start, limit in zip(rates, (1.5, -1.0), physics.joint_acceleration_limit):
        assert abs(rate - start) / tau <= limit * (1 + 1e-6)
    off = make_controller("mpc", ROBOT, joint_acceleration_limit=0)
    off.adopt_plant(physics)
    assert off.joint_acceleration_limit is None
    given = make_controller("mpc", ROBOT, joint_acceleration_limit=(5.0, 8.0))
    given.adopt_plant(physics)
    assert given.joint_acceleration_limit == (5.0, 8.0) and given.model_name == "thesis"
    with pytest.raises(ParameterError, match="joint_acceleration_limit must be in"):
        make_controller("mpc", ROBOT, joint_acceleration_limit=1e9)
    with pytest.raises(ParameterError, match="one number or two"):
        make_controller("mpc", ROBOT, joint_acceleration_limit=(1.0, 2.0, 3.0))
    unlagged = make_controller("mpc", ROBOT, joint_acceleration_limit=5.0)
    with pytest.raises(ParameterError, match="needs the lagged arm"):
        unlagged.adopt_plant(traits_of(ThesisPlant(ROBOT)))


def _held_braking_stop(state, step, limits, tau):
    """Joint angles where the controller's braking step (``braking_input``'s joint
    commands, each held ``step`` s through the exact lag) brings the arm of ``state`` (9,)
    to rest."""
    from ddwmmr.mpc.braking import braking_input

    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    decay = math.exp(-step / tau)
    angles, moving = np.array(state[3:5], dtype=float), np.array(state[7:9], dtype=float)
    for _ in range(2000):
        command = braking_input(dynamics, 1.2, (0.0, 0.0), moving, limits, tau)[2:]
        angles += command * step + (moving - command) * tau * (1.0 - decay)
        moving = command + (moving - command) * decay
    assert np.all(np.abs(moving) < 1e-9)
    return angles


def test_the_stopping_configuration_is_where_the_lagged_arm_comes_to_rest_braked_at_its_limit():
    """Closed form ``th + rate |rate| / (2 a)`` against the lag ODE integrated in 1e-5 s
    steps with the command leading the rate down at the limit (``u = rate -/+ a tau``) until
    it stops: within 1e-4 rad for both joints and both signs. The controller's braking
    step, which holds each command for a 10 ms step, stops further (at most 1.6 times as
    far: the row is optimistic for it, a known limit). At rest nothing moves; a model
    without an acceleration limit has no stopping configuration (its joints stop at once)."""
    limits, tau = (12.8, 33.3), 0.02
    model = LaggedArmPrediction(ROBOT, sym.ThesisDynamics.from_robot(ROBOT), tau, limits)
    x = ca.SX.sym("x", 9)
    stop = ca.Function("stop", [x], [model.stopping_configuration(x)])
    for rates in ((2.0, -1.5), (-0.7, 1.9)):
        state = np.array([0.3, -0.1, 0.5, -0.8, 1.2, 0.6, 0.2, *rates])
        angles, moving, h = state[3:5].copy(), np.array(rates), 1e-5
        for j in range(2):
            while abs(moving[j]) > 0.0:
                command = moving[j] - math.copysign(limits[j] * tau, moving[j])
                rate = moving[j] + (command - moving[j]) * h / tau
                if rate * moving[j] <= 0.0:  # stops within this step
                    angles[j] += 0.5 * moving[j] * h
                    break
                angles[j] += 0.5 * (moving[j] + rate) * h
                moving[j] = rate
        q = np.asarray(stop(state)).ravel()
        np.testing.assert_allclose(q[:3], state[:3], atol=0.0)
        np.testing.assert_allclose(q[3:5], angles, atol=1e-4)
        # the controller's braking step holds each command 10 ms: it stops further
        angles = _held_braking_stop(state, 0.01, limits, tau)
        travelled, row = np.abs(angles - state[3:5]), np.abs(q[3:5] - state[3:5])
        assert np.all(travelled >= row) and np.all(travelled <= 1.6 * row + 0.01)
    resting = np.array([0.0, 0.0, 0.0, -0.8, 1.2, 0.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(np.asarray(stop(resting)).ravel(), resting[:5], atol=1e-12)
    unbounded = LaggedArmPrediction(ROBOT, sym.ThesisDynamics.from_robot(ROBOT), tau)
    assert unbounded.stopping_configuration(x) is None


def test_a_reach_plan_ends_where_the_arm_can_still_brake_above_the_floor():
    """The shoulder swings at 2 rad/s towards the stability floor and the target lies just
    before it (0.26 rad on): a minimum-time plan passes the target with the arm still
    moving. With the joint acceleration limit the plan's last node is one from which the
    arm, braked at that limit, stops with S >= floor + margin (converged, no slack); the
    same plan without the limit (no such row) ends with a momentum that carries the arm
    below the floor. S of the stopping pose from the numeric model, not the OCP's rows."""
    limits = (12.8, 33.3)
    x0 = np.array([0.0, 0.0, 0.0, -2.75, 1.0, 0.0, 0.0, 2.0, 0.0])
    target = ROBOT.fk(x0[:5] + np.array([0.0, 0.0, 0.0, 0.26, 0.0]))[:2]

    def stopping_stability(acceleration_limit):
        dynamics = sym.ThesisDynamics.from_robot(ROBOT)
        model = LaggedArmPrediction(ROBOT, dynamics, 0.02, acceleration_limit)
        ocp, w = converged_reach_plan(ROBOT, model, x0, target)
        assert ocp.max_slack(w) < 1e-9 and ocp.horizon_of(w) < 0.2
        last = ocp.trajectories(w)[0][-1]
        rates = last[7:9]
        stop = np.concatenate(
            [last[:3], last[3:5] + rates * np.abs(rates) / (2 * np.array(limits))]
        )
        return ROBOT.stability(stop)[2], np.abs(rates).max()

    braked, rate = stopping_stability(limits)
    # it still passes the target moving (slower than 1 rad/s since the last node also
    # keeps every edge loaded under the turn the braked arm's momentum gives the base)
    assert braked >= 1.26 - 1e-6 and rate > 0.5
    assert stopping_stability(None)[0] < 1.25


def _shoulder_at_its_limit_qp(
    soft: bool, reach: bool = False, obstacles: tuple = (), elbow: float = 1.0, reference=None
):
    """One tracking QP of the lagged arm (the MuJoCo plant's model) whose measured shoulder
    is 2 mrad past its +pi limit and still turning outwards at 1 rad/s: no plan keeps
    node 1 inside the box (the command may lead the rate down by at most 12.8 rad/s^2 times
    the 0.02 s lag at the start of each interval).
    ``soft``: the joint box as the OCP builds it for this model (a slackened row); else as
    bounds, as it was. ``reach``: the free-horizon layout (one more node state);
    ``obstacles``: circles (one more slack, before the joints'); ``elbow``: its angle (rad);
    ``reference``: the end effector's (x, y, phi) at every node, default where it is now.
    Returns (ocp, solution or the SolverFailure)."""
    from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP
    from ddwmmr.mpc.solvers import GaussNewtonSQP, SolverFailure

    model = LaggedArmPrediction(ROBOT, sym.ThesisDynamics.from_robot(ROBOT), 0.02, (12.8, 33.3))
    model.joints_stop_at_once = not soft
    config = OCPConfig(
        intervals=10,
        control_interval=0.01,
        first_interval=0.05,
        horizon=1.0,
        reach=reach,
        obstacles=obstacles,
    )
    ocp = ShootingOCP(ROBOT, model, config)
    x0 = np.array([0.0, 0.0, 0.0, math.pi + 0.002, elbow, 0.0, 0.0, 1.0, 0.0])
    pose = ROBOT.fk(x0[:5]) if reference is None else reference
    node = np.concatenate([x0, [1.0]]) if reach else x0
    guess = ocp.pack(np.tile(node, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))
    p = ocp.parameters(np.tile(pose, (ocp.N, 1)), np.zeros(4), horizon_prev=1.0)
    lbw, ubw = ocp.bounds(x0)
    try:
        return ocp, GaussNewtonSQP(ocp, "hpipm", iterations=5).solve(
            guess, p, lbw, ubw, ocp.lbg, ocp.ubg
        )
    except SolverFailure as failure:
        return ocp, failure


@pytest.mark.parametrize("layout", ["tracking", "reach, far obstacle"])
def test_a_joint_past_its_limit_is_brought_back_by_the_slackened_joint_box(layout):
    """The lagged arm's joint box is a row with a slack: a QP whose measured shoulder has
    overrun its limit (MuJoCo lets a joint pass its range by a few mrad) and cannot stop
    at once is solved; the slack is the plan's largest overrun, and the plan brakes the
    shoulder and turns it back inside. With the box as bounds HPIPM fails on it (its
    return status 2, the mpc's fallback steps on MuJoCo before). The elbow, which has its
    own slack, stays inside its box."""
    from ddwmmr.mpc.solvers import SolverFailure
    from ddwmmr.qp.limits.obstacles import Circle

    options = {} if layout == "tracking" else {"reach": True, "obstacles": (Circle(9, 9, 0.1),)}
    ocp, w = _shoulder_at_its_limit_qp(soft=True, **options)
    assert isinstance(w, np.ndarray) and np.all(np.isfinite(w))
    overrun = ocp.max_joint_slack(w)
    states = ocp.trajectories(w)[0]
    shoulder = states[:, 3]
    assert 0.002 < overrun < 0.2
    assert shoulder.max() - math.pi == pytest.approx(overrun, abs=1e-6)
    assert np.all(np.diff(states[:5, 7]) < 0)  # braking from the start
    assert shoulder[-1] <= math.pi + 1e-6  # back inside by the end of the plan
    assert np.all(states[:, 4] <= math.pi + 1e-6)
    assert max(w[s][-1] for s in ocp.slack_slices) < 1e-6  # the elbow's slack
    assert ocp.max_slack(w) < 1e-6  # the stability rows need none: the joint is all it is
    hard_ocp, failure = _shoulder_at_its_limit_qp(soft=False, **options)
    assert hard_ocp.ns == ocp.ns - 2 and hard_ocp.max_joint_slack(np.zeros(hard_ocp.nw)) == 0.0
    assert isinstance(failure, SolverFailure) and "status 2" in str(failure)


def test_each_joint_has_its_own_slack():
    """While the shoulder is past its limit the elbow may not pass its own for free: an
    elbow whose reference lies 0.3 rad beyond its limit stops at the limit (a slack shared
    by the joints let it overrun by the shoulder's 0.09 rad)."""
    beyond = ROBOT.fk(np.array([0.0, 0.0, 0.0, math.pi + 0.002, math.pi + 0.3]))
    ocp, w = _shoulder_at_its_limit_qp(soft=True, elbow=math.pi - 0.3, reference=beyond)
    states = ocp.trajectories(w)[0]
    assert ocp.max_joint_slack(w) > 0.01  # the shoulder's overrun
    assert states[:, 4].max() <= math.pi + 1e-5
    assert states[:, 4].max() > math.pi - 0.01  # it goes to the limit, towards the reference


def test_models_whose_joints_stop_at_once_keep_the_joint_box_as_bounds():
    """The kinematic and thesis models command the joint rates: a rate of 0 keeps any node
    inside the box, so the box stays bounds of the nodes (no slack)."""
    from ddwmmr.mpc.models import KinematicPrediction, ThesisPrediction
    from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP

    config = OCPConfig(intervals=4, horizon=0.4)
    for model in (
        KinematicPrediction(ROBOT),
        ThesisPrediction(ROBOT, sym.ThesisDynamics.from_robot(ROBOT)),
    ):
        ocp = ShootingOCP(ROBOT, model, config)
        assert not ocp.soft_joints and ocp.ns == 2
        for s in ocp.x_slices[1:]:
            np.testing.assert_array_equal(ocp.w_lower[s][3:5], [-math.pi, -math.pi])
            np.testing.assert_array_equal(ocp.w_upper[s][3:5], [math.pi, math.pi])
    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    lagged = ShootingOCP(ROBOT, LaggedArmPrediction(ROBOT, dynamics, 0.02), config)
    assert lagged.soft_joints and lagged.ns == 4
    for s in lagged.x_slices[1:]:
        assert np.all(np.isinf(lagged.w_lower[s][3:5])) and np.all(np.isinf(lagged.w_upper[s][3:5]))
