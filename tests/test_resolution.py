"""Resolution kernels against second formulations of docs/theory.md and the damping bound.

The references here do not use the library's model: the Jacobian is built by complex-step
differentiation (exact to rounding) of the forward kinematics written below from docs/theory.md,
the nonholonomic row
and the auxiliary rows are the documented literals, and the damped solutions are computed
from an SVD of the matrices assembled from that Jacobian.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddwmmr import Ellipse, ParameterError, Rectangle, Robot, make_controller, simulate
from ddwmmr.resolution import kernels

L1, L2 = 0.35, 0.30  # the default robot (docs/theory.md)
#: The documented damping threshold sigma0 and the documented bounds (kernels docstring,
#: docs/theory.md section 4): |u| <= C |Xdot|.
SIGMA0 = 0.05
PI_BOUND = 1.0 / SIGMA0
ATS_BOUND = 2.0 * math.sqrt(1.0 + (L1 + L2) ** 2) / SIGMA0 + 1.0
AUX_ROWS = {"sum": [0, 0, 0, 1, 1], "shoulder": [0, 0, 0, 1, 0]}  # docs/theory.md, "Methods"


def fk(q):
    """End-effector pose from docs/theory.md, written independently of the library (accepts
    complex q for the complex step)."""
    x, y, phi, th1, th2 = q
    return np.array(
        [
            x + L1 * np.cos(phi + th1) + L2 * np.cos(phi + th1 + th2),
            y + L1 * np.sin(phi + th1) + L2 * np.sin(phi + th1 + th2),
            phi + th1 + th2,
        ]
    )


def jacobian(q, h=1e-30):
    """4x5 Jacobian: complex-step derivatives Im f(q + i h e_k) / h of :func:`fk` (no
    subtraction, so exact to rounding) and the nonholonomic row."""
    q = np.asarray(q, dtype=float)
    columns = [np.imag(fk(q + 1j * h * e)) / h for e in np.eye(5)]
    constraint = [-math.sin(q[2]), math.cos(q[2]), 0.0, 0.0, 0.0]
    return np.vstack([np.column_stack(columns), constraint])


def input_matrix(phi):
    """B(phi) of docs/theory.md, "Input form": qdot = B u."""
    B = np.zeros((5, 4))
    B[0, 0], B[1, 0] = math.cos(phi), math.sin(phi)
    B[2:, 1:] = np.eye(3)
    return B


def qdot_of(phi, u):
    return input_matrix(phi) @ np.asarray(u)


def damped_solve(M, r, lam2):
    """Damped least squares by SVD: sum_i s_i / (s_i^2 + lam2) (u_i . r) v_i."""
    U, s, Vt = np.linalg.svd(M, full_matrices=False)
    return Vt.T @ ((s / (s**2 + lam2)) * (U.T @ r))


def lam2_of(sigma):
    """Nakamura/Chiaverini damping with damping = threshold = SIGMA0 (the defaults)."""
    return 0.0 if sigma >= SIGMA0 else SIGMA0**2 * (1.0 - (sigma / SIGMA0) ** 2)


def random_states(rng, n=25, min_cos=0.3):
    """Configurations outside every damping band, with random task rates."""
    out = []
    while len(out) < n:
        q = rng.uniform(-math.pi, math.pi, 5)
        if abs(math.cos(q[3])) > min_cos:
            out.append((q, rng.normal(size=3)))
    return out


def test_pseudoinverse_equals_numpy_pinv(rng):
    for q, xdot in random_states(rng):
        expected = np.linalg.pinv(jacobian(q)) @ np.r_[xdot, 0.0]
        u, singular = kernels.pseudoinverse(L1, L2, *q[2:], *xdot)
        assert not singular
        np.testing.assert_allclose(qdot_of(q[2], u), expected, atol=1e-10)


@pytest.mark.parametrize("aux", ["sum", "shoulder"])
def test_ats_equals_inverse_of_augmented_jacobian(rng, aux):
    for q, xdot in random_states(rng):
        augmented = np.vstack([jacobian(q), AUX_ROWS[aux]])
        expected = np.linalg.solve(augmented, np.r_[xdot, 0.0, 0.0])
        u, singular = kernels.ats(L1, L2, *q[2:], *xdot, aux=aux)
        assert not singular
        np.testing.assert_allclose(qdot_of(q[2], u), expected, atol=1e-10)


def test_artificial_potential_equals_null_space_projection(rng):
    controller = make_controller("ap", Robot(), K1=1.0, K2=0.25, K3=0.66)
    for q, xdot in random_states(rng):
        J = jacobian(q)
        pinv = np.linalg.pinv(J)
        gradient = np.array([0, 0, 2 * 0.66 * q[2], 2 * 1.0 * q[3], 2 * 0.25 * q[4]])
        expected = pinv @ np.r_[xdot, 0] + (np.eye(5) - pinv @ J) @ (-gradient)
        u = controller.command(0.0, q, np.zeros(3), xdot)
        np.testing.assert_allclose(qdot_of(q[2], u), expected, atol=1e-10)


def test_null_space_of_J_is_base_yaw_against_shoulder(rng):
    z = np.array([0, 0, 1, -1, 0]) / math.sqrt(2)
    for q, _ in random_states(rng, 10):
        J = jacobian(q)
        projector = np.eye(5) - np.linalg.pinv(J) @ J
        np.testing.assert_allclose(projector, np.outer(z, z), atol=1e-10)


# -- damping: second formulation, continuity and the documented bound --------------------


def reduced_system(q, xdot, aux):
    """The 2x2 system of the augmented resolution, assembled from the numeric Jacobian.

    aux = shoulder: unknowns (v, w), th1dot = 0, th2dot = phiEdot - w;
    aux = sum: unknowns (v, th1dot), w = phiEdot, th2dot = -th1dot.
    Returns (M, r, map from the unknowns z to u).
    """
    A = jacobian(q)[:3] @ input_matrix(q[2])  # task rows in input form, 3x4
    pe = xdot[2]
    if aux == "shoulder":
        columns = np.array([[1, 0], [0, 1], [0, 0], [0, -1]], dtype=float)
        known = np.array([0, 0, 0, pe])
    else:
        columns = np.array([[1, 0], [0, 0], [0, 1], [0, -1]], dtype=float)
        known = np.array([0, pe, 0, 0])
    M = (A @ columns)[:2]
    r = (np.asarray(xdot) - A @ known)[:2]
    return M, r, lambda z: columns @ z + known


def near_singular_states(rng, n=40):
    """Configurations with |cos th1| < 0.3 (inside or near every band), exact pi/2 included."""
    out = []
    for i in range(n):
        q = rng.uniform(-math.pi, math.pi, 5)
        q[3] = math.pi / 2 + (0.0 if i < 3 else rng.uniform(-0.3, 0.3)) + (math.pi if i % 2 else 0)
        out.append((q, rng.normal(size=3)))
    return out


@pytest.mark.parametrize("aux", ["sum", "shoulder"])
def test_damped_ats_is_damped_least_squares_on_the_reduced_system(rng, aux):
    damped = 0
    for q, xdot in near_singular_states(rng):
        M, r, to_u = reduced_system(q, xdot, aux)
        sigma = np.linalg.svd(M, compute_uv=False)[-1]
        expected = to_u(damped_solve(M, r, lam2_of(sigma)))
        u, singular = kernels.ats(L1, L2, *q[2:], *xdot, aux=aux)
        assert singular == (sigma < SIGMA0)
        damped += singular
        np.testing.assert_allclose(u, expected, atol=1e-10)
    assert 10 < damped < 40  # both sides of the band edge were checked


@pytest.mark.parametrize("threshold", [0.9, 2.0, 1e3])
def test_a_threshold_above_every_singular_value_damps_every_state(rng, threshold):
    """Above sqrt(T / 2) (0.75 for the default arm) sigma_min is below the threshold
    everywhere; the kernel's test without square roots once took such states as undamped.
    Against damped least squares by SVD, at states near and far from the singularity."""
    states = near_singular_states(rng, 10) + random_states(rng, 10)
    for q, xdot in states:
        M, r, to_u = reduced_system(q, xdot, "shoulder")
        sigma = np.linalg.svd(M, compute_uv=False)[-1]
        lam2 = threshold**2 * (1.0 - (sigma / threshold) ** 2)
        expected = to_u(damped_solve(M, r, lam2))
        u, singular = kernels.ats(
            L1, L2, *q[2:], *xdot, aux="shoulder", threshold=threshold, damping=threshold
        )
        assert singular
        np.testing.assert_allclose(u, expected, atol=1e-10)


def test_damped_pseudoinverse_is_damped_least_squares(rng):
    damped = 0
    for q, xdot in near_singular_states(rng):
        A = jacobian(q)[:3] @ input_matrix(q[2])
        gram = A @ A.T
        # The documented singularity measure: 2 sqrt(det(A A^T)) / trace(A A^T).
        measure = 2.0 * math.sqrt(max(np.linalg.det(gram), 0.0)) / np.trace(gram)
        expected = damped_solve(A, xdot, lam2_of(measure))
        u, singular = kernels.pseudoinverse(L1, L2, *q[2:], *xdot)
        assert singular == (measure < SIGMA0)
        damped += singular
        np.testing.assert_allclose(u, expected, atol=1e-10)
    assert 10 < damped < 40


angles = st.floats(-20.0, 20.0, allow_nan=False)
near_pi_2 = st.floats(-0.3, 0.3).map(lambda d: math.pi / 2 + d)
shoulder = st.one_of(angles, near_pi_2, st.sampled_from([math.pi / 2, -math.pi / 2]))
rates = st.lists(st.floats(-5.0, 5.0, allow_nan=False), min_size=3, max_size=3)


@settings(max_examples=400, deadline=None)
@given(phi=angles, th1=shoulder, th2=angles, xdot=rates)
def test_singularity_measure_of_the_pseudoinverse_is_a_lower_bound(phi, th1, th2, xdot):
    A = jacobian([0.0, 0.0, phi, th1, th2])[:3] @ input_matrix(phi)
    smallest = np.linalg.svd(A, compute_uv=False)[-1]
    measure = 2.0 * math.sqrt(2.0) * L1 * abs(math.cos(th1)) / np.trace(A @ A.T)
    assert measure <= smallest * (1 + 1e-7) + 1e-9


@settings(max_examples=600, deadline=None)
@given(phi=angles, th1=shoulder, th2=angles, xdot=rates)
def test_command_norm_is_bounded_by_the_documented_constant_times_the_speed(phi, th1, th2, xdot):
    speed = math.hypot(*xdot)
    u, _ = kernels.pseudoinverse(L1, L2, phi, th1, th2, *xdot)
    assert math.hypot(*u) <= PI_BOUND * speed * (1 + 1e-9) + 1e-12
    for aux in ("sum", "shoulder"):
        u, _ = kernels.ats(L1, L2, phi, th1, th2, *xdot, aux=aux)
        assert math.hypot(*u) <= ATS_BOUND * speed * (1 + 1e-9) + 1e-12


@pytest.mark.parametrize("method", ["pi", "ats", "clrrmc-ts"])
def test_no_cliff_at_the_old_band_edge(method, rng):
    """The audit's case: |cos th1| = 0.0501 (just outside the old band) gave rates of 42-45
    for desired speeds <= 0.5 m/s. Now the documented bound holds there as everywhere."""
    robot = Robot()
    controller = make_controller(method, robot)
    bound = (PI_BOUND if method == "pi" else ATS_BOUND) * 0.5
    peak = 0.0
    for th1 in (math.acos(0.0501), -math.acos(0.0501), math.acos(-0.0501)):
        for _ in range(200):
            q = np.r_[rng.uniform(-2, 2, 3), th1, rng.uniform(-3, 3)]
            direction = rng.normal(size=3)
            xdot = 0.5 * direction / np.linalg.norm(direction)
            u = controller.command(0.0, q, robot.fk(q), xdot)  # no pose error
            peak = max(peak, float(np.linalg.norm(u)))
    assert peak <= bound
    assert peak < 25.0  # against 42-45 before


@pytest.mark.parametrize("method", ["pi", "ats", "ap", "clrrmc-ts"])
def test_commands_stay_bounded_and_continuous_through_the_singularity(method):
    robot = Robot()
    controller = make_controller(method, robot)
    xdot = np.array([0.2, 0.1, 0.05])
    sweep = np.linspace(math.pi / 2 - 0.4, math.pi / 2 + 0.4, 4001)
    commands, singular = [], 0
    for th1 in sweep:
        q = np.array([0.0, 0.0, 0.2, th1, 0.8])
        u = controller.command(0.0, q, robot.fk(q), xdot)
        commands.append(u)
        singular += controller.last.singular
    commands = np.array(commands)
    assert np.all(np.isfinite(commands))
    # The null-space term of ap (|k| <= K1 |th1| + K3 |phi|) is not scaled by the speed.
    extra = math.sqrt(2) * (1.0 * 2.0 + 0.66 * 0.2) if method == "ap" else 0.0
    bound = (PI_BOUND if method in ("pi", "ap") else ATS_BOUND) * np.linalg.norm(xdot) + extra
    assert np.max(np.linalg.norm(commands, axis=1)) <= bound
    # Continuous: neighbouring states (2e-4 rad apart) give nearby commands.
    assert np.max(np.abs(np.diff(commands, axis=0))) < 0.05
    assert 0 < singular < len(sweep)


def test_damping_rises_continuously_from_zero_at_the_threshold():
    assert kernels.damping_squared(0.5, 0.05, 0.05) == 0.0
    assert kernels.damping_squared(0.05, 0.05, 0.05) == 0.0
    assert kernels.damping_squared(0.0, 0.05, 0.05) == pytest.approx(0.05**2, rel=1e-15)
    # Continuous at the band edge: 1e-7 inside it the damping is 1e-8 (2 sigma0 dsigma).
    assert kernels.damping_squared(0.0499999, 0.05, 0.05) == pytest.approx(1e-8, rel=1e-5)
    values = [kernels.damping_squared(s, 0.05, 0.05) for s in np.linspace(0.0, 0.06, 61)]
    assert np.all(np.diff(values) <= 0.0)


def test_smallest_singular_value_of_the_reduced_matrix(rng):
    for q, xdot in near_singular_states(rng, 20) + random_states(rng, 20):
        M, _, _ = reduced_system(q, xdot, "shoulder")
        expected = np.linalg.svd(M, compute_uv=False)[-1]
        assert kernels.smallest_singular_value_m(L1, math.cos(q[3])) == pytest.approx(
            expected, abs=1e-9
        )


def test_documented_gain_constants():
    assert kernels.pi_gain() == pytest.approx(PI_BOUND, rel=1e-15)
    assert kernels.ats_gain(L1, L2) == pytest.approx(ATS_BOUND, rel=1e-15)
    assert (round(PI_BOUND, 6), round(ATS_BOUND, 1)) == (20.0, 48.7)


# -- clrrmc-cs reports the damped steps of its reference ----------------------------------


def test_clrrmc_cs_counts_the_steps_its_reference_was_damped():
    robot = Robot()
    result = simulate(robot, Rectangle(), "clrrmc-cs", aux="sum", duration=20.0)
    reference = result.controller.reference
    ts = result.timeseries
    # Independent count: control steps whose reference configuration lies in the band of
    # the augmented system (smallest singular value of M below sigma0, by SVD).
    in_band = 0
    for t in ts["t"][:-1]:  # the commanded steps (the last sample's command is not applied)
        q_ref, _ = reference(t)
        M, _, _ = reduced_system(np.array(q_ref), np.zeros(3), "sum")
        in_band += np.linalg.svd(M, compute_uv=False)[-1] < SIGMA0
    steps = result.summary["singular_steps"]
    assert in_band > 100
    # A step counts when any rate evaluation of its 0.01 s reference segment was damped:
    # at least every step inside the band, at most a few more at its edges.
    assert in_band <= steps <= in_band + 20
    assert reference.singular_nodes >= steps
    default = simulate(robot, Rectangle(), "clrrmc-cs", duration=20.0).summary
    assert default["singular_steps"] == 0  # the shoulder row never nears cos th1 = 0


def test_unknown_method_and_option_errors():
    robot = Robot()
    with pytest.raises(ParameterError, match="unknown method 'nope'"):
        make_controller("nope", robot)
    with pytest.raises(ParameterError, match="unknown option 'K9'"):
        make_controller("ap", robot, K9=1.0)
    with pytest.raises(ParameterError, match="aux must be one of"):
        make_controller("ats", robot, aux="elbow")
    with pytest.raises(ParameterError, match="tau must be > 0"):
        make_controller("clrrmc-ts", robot, tau=-1.0)
    with pytest.raises(ParameterError, match="tau must be > 0"):
        make_controller("clrrmc-cs", robot, tau=float("nan"))
    with pytest.raises(ParameterError, match=r"^singularity_threshold must be in \[1e-06, 1000"):
        make_controller("clrrmc-cs", robot, singularity_threshold=0.0)


@pytest.mark.parametrize("method", ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs"])
@pytest.mark.parametrize(
    ("name", "value"),
    [("singularity_threshold", 1e200), ("singularity_threshold", 1e-300), ("damping", 1e-300)],
)
def test_threshold_and_damping_stay_where_their_squares_are_numbers(method, name, value):
    """Audit: sigma0 = 1e200 squared to inf, which switched the damping off (ats commanded
    6.5e14 at a near-singular pose with singular=False); 1e-300 squared to 0. Both are
    refused, naming the range the kernels document."""
    ranges = {"singularity_threshold": kernels.THRESHOLD_RANGE, "damping": kernels.DAMPING_RANGE}
    low, high = ranges[name]
    message = f"{name} must be in [{low:g}, {high:g}] (got {value:g})"
    with pytest.raises(ParameterError) as info:
        make_controller(method, Robot(), **{name: value})
    assert str(info.value) == message


def test_the_widest_threshold_and_damping_still_bound_the_singular_command():
    """At both ends of the ranges the ats command at the shoulder singularity is finite
    and marked singular."""
    q = np.array([0.0, 0.0, 0.0, math.pi / 2, 0.6])  # cos th1 = 0
    trajectory = Ellipse()
    for low_or_high in (0, 1):
        threshold = kernels.THRESHOLD_RANGE[low_or_high]
        damping = kernels.DAMPING_RANGE[low_or_high]
        controller = make_controller(
            "ats", Robot(), singularity_threshold=threshold, damping=damping
        )
        controller.reset(trajectory, q)
        u = controller.command(0.0, q, trajectory.pose(0.0), trajectory.velocity(0.0))
        assert np.all(np.isfinite(u)) and controller.last.singular
