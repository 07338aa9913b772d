"""Bad input to the public API is one ParameterError naming the parameter (an audit's cases).

Before, these raised raw TypeError/ValueError/OverflowError/ZeroDivisionError from deep
inside, or were accepted and produced 1e16 commands or an endless reference integration.
"""

import math

import numpy as np
import pytest

from ddwmmr import Robot, make_controller, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.gains import MAX_GAIN
from ddwmmr.plants import make_plant
from ddwmmr.plants.base import Observation
from ddwmmr.qp.limits import JointLimit, Limit
from ddwmmr.qp.tasks import HeadingTask, PostureTask, Task
from ddwmmr.trajectories import Ellipse


def _refused(call, match: str) -> str:
    with pytest.raises(ParameterError, match=match) as error:
        call()
    message = str(error.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize("method", ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs"])
@pytest.mark.parametrize("damping", [0.0, -0.1, math.nan])
def test_damping_must_be_positive(method, damping):
    # Undamped, ats at cos th1 = 0 commanded 1.3e16 rad/s with singular=False.
    _refused(lambda: make_controller(method, Robot(), damping=damping), "damping")


def test_small_damping_still_bounds_the_singular_command():
    controller = make_controller("ats", Robot(), damping=1e-3)
    q = np.array([0.0, 0.0, 0.0, math.pi / 2, 0.6])  # cos th1 = 0: the shoulder singularity
    trajectory = Ellipse()
    controller.reset(trajectory, q)
    u = controller.command(0.0, q, trajectory.pose(0.0), trajectory.velocity(0.0))
    assert np.all(np.isfinite(u)) and controller.last.singular


@pytest.mark.parametrize("step", ["x", None, math.inf, 1e-7, 5.0])
def test_reference_step_is_a_number_in_range(step):
    _refused(lambda: make_controller("clrrmc-cs", Robot(), reference_step=step), "reference_step")


@pytest.mark.parametrize(
    "tau", ["0.5", None, True, ["a"] * 3, [10**400] * 3, 1e-300, [0.5, 0.5], -1.0]
)
def test_tau_forms_refused(tau):
    _refused(lambda: make_controller("clrrmc-ts", Robot(), tau=tau), "tau")


@pytest.mark.parametrize("tau", [np.float32(0.5), np.int64(1), np.array(0.5), np.array([0.5] * 3)])
def test_tau_numpy_forms_accepted(tau):
    controller = make_controller("clrrmc-ts", Robot(), tau=tau)
    gains = (controller.kx, controller.ky, controller.kphi)
    assert gains == pytest.approx((1.0 / float(np.ravel(tau)[0]),) * 3)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"intervals": math.nan}, "intervals must be an integer in"),
        ({"intervals": "x"}, "intervals must be an integer in"),
        ({"intervals": [1, 2]}, "intervals must be an integer in"),
        ({"horizon": 1e300}, "horizon must be in"),
        ({"first_interval": 1e-300}, "first_interval must be in"),
        ({"track_orientation": "yes"}, "track_orientation must be true or false"),
    ],
)
def test_mpc_grid_options(options, match):
    _refused(lambda: make_controller("mpc", Robot(), **options), match)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"limits": [1]}, "limits must be Limit objects"),
        ({"tasks": 3}, "tasks must be a list of Task objects"),
        ({"obstacles": 5}, "obstacles must be circles"),
        ({"track_orientation": math.nan}, "track_orientation must be true or false"),
        ({"warm_start": "x"}, "warm_start must be true or false"),
        ({"tracking_weight": -1.0}, r"tracking_weight must be in \[0, 1e\+06\]"),
        ({"posture_weight": 1e300}, r"posture_weight must be in \[0, 1e\+06\]"),
        ({"manipulability_weight": 1e300}, r"manipulability_weight must be in \[0, 1e\+06\]"),
    ],
)
def test_qp_options(options, match):
    _refused(lambda: make_controller("qp", Robot(), **options), match)


def test_qp_none_means_no_extra_pieces():
    plain = make_controller("qp", Robot())
    none = make_controller("qp", Robot(), obstacles=None, tasks=None, limits=None)
    assert len(none.tasks) == len(plain.tasks) and len(none.limits) == len(plain.limits)


def test_unknown_plant_option_names_the_accepted_ones():
    message = _refused(lambda: make_plant("thesis", Robot(), bogus=1), "plant thesis")
    assert "'bogus'" in message and "force_limit" in message
    _refused(
        lambda: simulate(Robot(), Ellipse(), "ats", plant_options={"bogus": 1}), "unknown option"
    )


@pytest.mark.parametrize("robot", ["x", 3, {"L1": 0.3}])
def test_robot_must_be_a_robot(robot):
    _refused(lambda: make_controller("ats", robot), "robot must be a Robot")
    _refused(lambda: make_plant("kinematic", robot), "robot must be a Robot")
    _refused(lambda: simulate(robot, Ellipse(), "ats"), "robot must be a Robot")


class _NoSamples(Ellipse):
    samples = 0


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: simulate(Robot(), Ellipse(), "ats", q0="abcde"), "q0 must be 5 finite numbers"),
        (lambda: simulate(Robot(), Ellipse(), "ats", initial_offset=5.0), "initial_offset"),
        (lambda: simulate(Robot(), Ellipse(), "ats", plant=3), "plant must be a plant name"),
        (lambda: simulate(Robot(), Ellipse(), "ats", plant=None), "plant must be a plant name"),
        (lambda: simulate(Robot(), Ellipse(), "ats", progress="x"), "progress must be a callable"),
        (lambda: simulate(Robot(), Ellipse(), "ats", plant_options="x"), "plant_options"),
        (lambda: simulate(Robot(), Ellipse(), None), "method must be a method name"),
        (lambda: simulate(Robot(), _NoSamples(), "ats"), "samples"),
    ],
)
def test_simulate_arguments(call, match):
    _refused(call, match)


@pytest.mark.parametrize(
    "offset", [np.array(0.01), {0: 0.01, 1: 0.02}, [[0.01, 0.02]], (0.01, 0.02, 0.0), "ab"]
)
def test_initial_offset_must_be_a_pair(offset):
    # a 0-d array raised a TypeError, a mapping ran from its keys (0, 1) m
    _refused(
        lambda: simulate(Robot(), Ellipse(), "pi", duration=0.1, initial_offset=offset),
        "initial_offset must be two numbers dx, dy in m",
    )


def test_initial_offset_takes_numpy_pairs():
    pair = simulate(Robot(), Ellipse(), "pi", duration=0.1, initial_offset=(-0.02, 0.01))
    array = simulate(Robot(), Ellipse(), "pi", duration=0.1, initial_offset=np.array([-0.02, 0.01]))
    assert pair.summary["initial_offset_m"] == array.summary["initial_offset_m"]


@pytest.mark.parametrize("make", [lambda: 10**5000, lambda: 10**400, lambda: "x" * 500])
def test_messages_stay_one_short_line_for_huge_values(make):
    from ddwmmr.errors import check_positive

    value = make()  # built here: pytest cannot show a 5000-digit int as a test id
    match = "L1 must be a finite number > 0"
    message = _refused(lambda: check_positive("L1", value), match)
    assert len(message) < 100


# -- a newcomer audit's cases: what track refused, the API and the other tools accepted ----


def test_a_start_in_which_the_robot_has_tipped_over_is_named():
    """check_start, which track, compare and the app call before a run; simulate itself
    runs it after a warning (a design study sees min S < 1)."""
    from ddwmmr.resolution.reference import start_configuration
    from ddwmmr.sim.simulate import check_start

    heavy = Robot().with_payload(20.0)
    start = start_configuration(heavy, Ellipse())
    message = _refused(lambda: check_start(heavy, start), r"payload tips the robot over")
    assert "S = 0.551 <= 1" in message and message.startswith("payload:")
    check_start(Robot().with_payload(3.0), start)  # upright: nothing to say
    with pytest.warns(UserWarning, match=r"20 kg payload .*S = 0\.57 <= 1"):  # runs it, says so
        assert simulate(heavy, Ellipse(), "ats", duration=0.1).summary["min_stability"] < 1.0


def test_a_start_inside_an_obstacle_is_named():
    # The default ellipse starts with the base at about (1.6, 0): a 0.5 m circle at (2, 0)
    # overlaps it.
    from ddwmmr.resolution.reference import start_configuration
    from ddwmmr.sim.simulate import check_start

    start = start_configuration(Robot(), Ellipse())
    _refused(
        lambda: check_start(Robot(), start, [(2.0, 0.0, 0.5)]),
        r"obstacles: obstacle 1 .* overlaps the robot's start pose by",
    )
    check_start(Robot(), start, [(5.0, 0.0, 0.5)])


@pytest.mark.parametrize(
    ("trajectory", "match"),
    [
        (None, r"trajectory must have duration \(s\), pose\(t\) and velocity\(t\)"),
        ("ellipse", r"not its name 'ellipse' \(ddwmmr.load_trajectory\('ellipse'\)"),
        (type("NoVelocity", (), {"duration": 1.0, "pose": lambda self, t: None})(), "velocity"),
    ],
)
def test_simulate_names_what_a_trajectory_needs(trajectory, match):
    _refused(lambda: simulate(Robot(), trajectory, "ats"), match)


@pytest.mark.parametrize("method", ["clrrmc-cs", "clrrmc-ts", "ats", "qp", "mpc"])
def test_a_controller_reset_with_no_trajectory_is_refused_or_harmless(method):
    """The configuration-space controller builds its reference at reset: it names what
    a trajectory needs (it raised AttributeError); the others do not read it there."""
    controller = make_controller(method, Robot())
    if method == "clrrmc-cs":
        _refused(lambda: controller.reset(None, np.zeros(5)), match=r"^trajectory must have")
    else:
        controller.reset(None, np.zeros(5))


@pytest.mark.parametrize(
    ("circle", "match"),
    [
        ("x = 1e9\ny = 0.0\nradius = 0.3", r"obstacle x must be in \[-1e\+06, 1e\+06\] m"),
        ("x = 5.0\ny = -2e6\nradius = 0.3", r"obstacle y must be in \[-1e\+06, 1e\+06\] m"),
        ("x = 5.0\ny = 0.0\nradius = 5000.0", r"obstacle radius must be in \[1e-06, 1000\] m"),
        ("x = 5.0\ny = 0.0\nradius = 1e-9", r"obstacle radius must be in \[1e-06, 1000\] m"),
    ],
)
def test_obstacle_files_keep_the_documented_limits(tmp_path, circle, match):
    from ddwmmr.qp.limits.obstacles import load_obstacles

    path = tmp_path / "o.toml"
    path.write_text(f"[[obstacle]]\n{circle}\n")
    _refused(lambda: load_obstacles(path), r"obstacles: .*o.toml: obstacle 1: " + match)
    path.write_text("[[obstacle]]\nx = 1e6\ny = -1e6\nradius = 1000.0\n")
    assert load_obstacles(path)[0].radius == 1000.0  # the limits themselves are allowed


ALL_METHODS = ["pi", "ats", "ap", "clrrmc-cs", "clrrmc-ts", "qp", "mpc"]


class _TurnsNaN(Ellipse):
    """A custom trajectory whose pose turns NaN after 0.5 s (between two samples)."""

    def pose(self, t):
        pose = super().pose(t)
        return pose * math.nan if t > 0.5 else pose


@pytest.mark.parametrize("method", ALL_METHODS)
def test_a_reference_turning_nan_mid_run_is_one_error_for_every_method(method):
    # clrrmc-ts's integrator stages met it first: FloatingPointError from the plant. The
    # trajectory's pose is checked where simulate takes it (the first time after 0.5 s that
    # the method asks: an RK4 stage, or the mpc's preview), so the message names pose(t).
    message = _refused(lambda: simulate(Robot(), _TurnsNaN(), method, duration=1.0), "^traj")
    prefix = (
        "trajectory pose(t) must return 3 finite numbers [xE, yE, phiE] (m, m, rad) "
        "(got array([nan, nan, nan]) at t = "
    )
    assert message.startswith(prefix) and message.endswith(" s)")
    assert 0.5 < float(message[len(prefix) : -len(" s)")]) < 1.0


@pytest.mark.parametrize("method", ALL_METHODS)
def test_a_finite_but_absurd_configuration_never_gives_an_infinite_command(method):
    # clrrmc-ts returned [-inf, inf, 0, -inf]; qp and mpc keep their limits at any finite
    # state (tests/test_qp_limits_extreme.py), the closed-loop closed-form ones refuse it
    q = np.array([1.7e308, 0.0, 0.3, -0.3, 0.6])
    controller = make_controller(method, Robot())
    trajectory = Ellipse()
    controller.reset(trajectory, q)
    call = lambda: controller.command(0.0, q, trajectory.pose(0.0), trajectory.velocity(0.0))  # noqa: E731
    if method not in ("clrrmc-ts", "clrrmc-cs"):  # the open-loop ones do not use x, y
        assert np.all(np.isfinite(call()))
    else:
        _refused(call, "^q, pose_d: too large for the command to be finite")


@pytest.mark.parametrize(
    ("method", "option"),
    [
        ("ap", "K1"),
        ("ap", "K2"),
        ("ap", "K3"),
        ("qp", "stability_gain"),
    ],
)
def test_every_gain_is_capped(method, option):
    # ap with K3 = 1e300 commanded 1.3e300 rad/s
    name = option.replace("_", "[_ ]")
    _refused(lambda: make_controller(method, Robot(), **{option: 1e300}), f"{name} must be <=")
    make_controller(method, Robot(), **{option: MAX_GAIN})  # the cap itself is a gain


@pytest.mark.parametrize(
    "make",
    [
        lambda gain: PostureTask(gain=gain),
        lambda gain: PostureTask(K3=gain),
        lambda gain: JointLimit(Robot(), gain=gain),
        lambda gain: HeadingTask(gain=gain),
    ],
)
def test_qp_piece_gains_are_capped(make):
    _refused(lambda: make(1e300), "must be <= 10000 1/s")


class _NanError(Task):
    """A user task (yaw at 0.5 rad/s) whose error turns NaN."""

    name = "spin"

    def compute(self, ctx, jac, error):
        jac[:] = (0.0, 1.0, 0.0, 0.0)
        error[0] = math.nan


class _NanBound(Limit):
    """A user limit whose upper bound on w turns NaN."""

    name = "nan bound"

    def compute(self, ctx, G, lower, upper, lb, ub):
        ub[1] = math.nan


class _Conflict(Limit):
    """A user limit asking v >= 1 and v <= -1: no solution on any step."""

    def compute(self, ctx, G, lower, upper, lb, ub):
        lb[0], ub[0] = 1.0, -1.0


@pytest.mark.parametrize("mode", ["weighted", "hierarchical"])
def test_a_user_piece_writing_nan_is_one_line_naming_it(mode):
    ellipse = Ellipse()
    message = _refused(
        lambda: simulate(Robot(), ellipse, "qp", duration=0.2, mode=mode, tasks=[_NanError(1.0)]),
        r"^_NanError 'spin': compute\(\) wrote a non-finite value into its error at t = 0 s",
    )
    assert message.endswith("(they must be finite)")
    _refused(
        lambda: simulate(Robot(), ellipse, "qp", duration=0.2, mode=mode, limits=[_NanBound()]),
        r"^limits: a compute\(\) of 'nan bound' wrote a NaN into the input box lb, ub at "
        r"t = 0 s \(bounds must not be NaN; \+-inf leaves a side open\)$",
    )


def test_limits_in_conflict_name_the_qp_fallback_as_the_cause():
    result = simulate(Robot(), Ellipse(), "qp", duration=1.0, limits=[_Conflict()])
    summary = result.summary
    assert summary["qp_fallbacks"] == summary["steps"] == 50
    assert max(abs(v) for v in result.timeseries["v"]) == 0.0  # the fallback holds still
    assert "likely cause: the qp found no solution on 50 of 50 steps" in summary["verdict"]


class _Raises:
    """A controller of the user's own that raises in its third step."""

    name = "my-raiser"

    def reset(self, trajectory, q0):
        self.calls = 0

    def command(self, t, q, pose_d, velocity_d):
        self.calls += 1
        if self.calls > 2:
            raise RuntimeError("boom\n  in my controller")
        return np.zeros(4)


def test_a_controller_that_raises_is_one_line_naming_it_and_the_step():
    from ddwmmr.errors import PluginError

    with pytest.raises(PluginError) as error:
        simulate(Robot(), Ellipse(), _Raises(), duration=0.5, integrator="euler")
    assert str(error.value) == (
        "method: my-raiser.command() raised RuntimeError: 'boom in my controller' at step 2, "
        "t = 0.04 s"
    )
    assert isinstance(error.value.__cause__, RuntimeError)  # the traceback stays reachable


def test_track_prints_a_raising_controller_in_one_line(tmp_path, capsys, registered):
    from ddwmmr.cli.track import main
    from ddwmmr.registry import CONTROLLERS

    class Raiser(_Raises):
        def __init__(self, robot):
            self.robot = robot

    registered(CONTROLLERS, "my-raiser", Raiser, tasks=("tracking",))
    out = tmp_path / "run"
    argv = ["--method", "my-raiser", "--traj", "ellipse", "--duration", "0.5", "--out", str(out)]
    assert main([*argv, "--no-progress"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "error: method: my-raiser.command() raised RuntimeError: 'boom in my controller' at "
        "step 0, t = 0.01 s"  # the third call: an RK4 stage inside step 0
    ]
    assert not out.exists()


@pytest.mark.parametrize(
    ("observed", "got"),
    [
        (lambda q: Observation(q[:4], 0.0, 0.0), "got Observation(q=[1.8"),  # 4 numbers
        (lambda q: Observation(q, math.nan, 0.0), "got Observation(q=[1.8"),
        (lambda q: tuple(q), "got (1.8"),  # not an Observation
    ],
)
def test_a_plant_observing_nonsense_is_one_line_naming_it(observed, got):
    from ddwmmr.plants.kinematic import KinematicPlant

    class Odd(KinematicPlant):
        name = "odd"

        def observe(self):
            real = super().observe()
            return observed(tuple(real.values)) if self.steps_taken else real

        def step(self, t, command, dt, policy=None):
            self.steps_taken = True
            super().step(t, command, dt, policy)

        steps_taken = False

    message = _refused(
        lambda: simulate(Robot(), Ellipse(), "ats", duration=0.2, plant=Odd(Robot())),
        r"^plant: odd\.observe\(\) must return an Observation\(q, v, w\) of 5 \+ 2 finite "
        r"numbers \(got ",
    )
    assert got in message and "at step 1, t = 0.02 s" in message


class _LawRaises:
    """A controller of the user's own whose float-level law raises at the RK4 stages."""

    name = "my-law"

    def reset(self, trajectory, q0):
        pass

    def command(self, t, q, pose_d, velocity_d):
        return np.zeros(4)

    def law(self, t, q, pose_d, velocity_d):
        raise RuntimeError("boom in law")


def test_a_raising_law_is_named_as_the_law():
    from ddwmmr.errors import PluginError

    with pytest.raises(PluginError, match=r"^method: my-law\.law\(\) raised RuntimeError: "):
        simulate(Robot(), Ellipse(), _LawRaises(), duration=0.1)


def test_a_bug_in_a_library_controller_keeps_its_own_traceback(monkeypatch):
    """Only a controller from outside the library is wrapped in a PluginError: an error
    in one of ours propagates as it is, traceback and all."""
    from ddwmmr.qp.controller import QPController

    def broken(self, ctx):
        raise IndexError("list index out of range")

    monkeypatch.setattr(QPController, "_solve", broken)
    with pytest.raises(IndexError) as error:
        simulate(Robot(), Ellipse(), "qp", duration=0.1)
    assert any(frame.name == "broken" for frame in error.traceback)


def test_a_parameter_error_from_a_controller_is_not_its_own_cause():
    with pytest.raises(ParameterError) as error:
        simulate(Robot(), Ellipse(), "qp", duration=0.2, tasks=[_NanError(1.0)])
    assert error.value.__cause__ is not error.value


@pytest.mark.parametrize(
    ("limited", "got"),
    [
        (lambda u: (np.array([np.nan, 0.0, 0.0, 0.0]), False), "(array([nan, 0., 0., 0.]), False)"),
        (lambda u: (np.zeros(3), False), "(array([0., 0., 0.]), False)"),
        (lambda u: np.zeros(4), "array([0., 0., 0., 0.])"),
    ],
)
def test_a_plant_limiting_into_nonsense_is_one_line_naming_it(limited, got):
    from ddwmmr.plants.kinematic import KinematicPlant

    class Odd(KinematicPlant):
        name = "odd"

        def limit(self, q, u):
            return limited(u)

    message = _refused(
        lambda: simulate(Robot(), Ellipse(), "ats", duration=0.2, plant=Odd(Robot())),
        r"^plant: odd\.limit\(q, u\) must return \(u, saturated\) with u 4 finite numbers ",
    )
    assert f"(got {got} at step 0, t = 0 s)" in message
