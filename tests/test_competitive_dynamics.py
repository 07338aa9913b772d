"""Competitive dynamics (paper eq. 3): exact update, fixed points, switching, bounds, noise.

Independent checks: the closed-form step against scipy's adaptive integrator, fixed points
and their stability against the linearisation of eq. (3), the integrator against a fine
reference solution of the coupled system.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from ddwmmr.arbiters.competitive import W_LIMIT, CompetitiveDynamics, bernoulli_step
from ddwmmr.errors import ParameterError


def rhs(w, a, r, t_const):
    """Right-hand side of eq. (3) without noise: T_b w_b' = a w - |a| w^3 - sum r w'^2 w."""
    w = np.asarray(w, dtype=float)
    n = len(w)
    out = np.empty(n)
    for i in range(n):
        pressure = sum(r[j][i] * w[j] ** 2 for j in range(n) if j != i)
        out[i] = (a[i] * w[i] - abs(a[i]) * w[i] ** 3 - pressure * w[i]) / t_const[i]
    return out


def reference(w0, a, r, t_const, duration):
    """Tight-tolerance solution of the coupled noise-free system at ``duration`` (s)."""
    sol = solve_ivp(
        lambda t, w: rhs(w, a, r, t_const),
        (0.0, duration),
        w0,
        method="LSODA",
        rtol=1e-10,
        atol=1e-12,
    )
    return sol.y[:, -1]


def run(dyn, a, r, h, steps):
    for _ in range(steps):
        dyn.step(a, r, h)
    return np.array(dyn.w)


@pytest.mark.parametrize(
    ("w0", "alpha", "beta", "tau"),
    [
        (0.3, 1.0, 1.0, 0.7),  # growth toward 1
        (-0.3, 2.0, 2.0, 3.0),  # sign kept
        (0.9, -1.5, 0.5, 0.4),  # decay
        (1.4, 0.5, 0.5, 2.0),  # above the fixed point: down to it
        (0.5, 0.0, 1.0, 1.3),  # alpha = 0: algebraic decay
        (0.2, 0.3, 1.2, 5.0),  # fixed point sqrt(alpha / beta) = 0.5
        (0.6, -3.0, 0.0, 0.8),  # beta = 0: pure exponential decay
    ],
)
def test_bernoulli_step_matches_adaptive_integrator(w0, alpha, beta, tau):
    sol = solve_ivp(lambda t, w: alpha * w - beta * w**3, (0.0, tau), [w0], rtol=1e-11, atol=1e-13)
    assert bernoulli_step(w0, alpha, beta, tau) == pytest.approx(sol.y[0, -1], rel=1e-8)


def test_bernoulli_step_large_steps_land_on_the_fixed_point_without_overflow():
    assert bernoulli_step(0.01, 3.0, 12.0, 1e6) == pytest.approx(0.5, rel=1e-12)
    assert bernoulli_step(0.7, -5.0, 5.0, 1e6) == pytest.approx(0.0, abs=1e-300)
    assert bernoulli_step(0.0, 1.0, 1.0, 10.0) == 0.0  # the unstable fixed point


def test_single_behaviour_fixed_points_plus_minus_one_and_zero():
    """a > 0: w -> +-1 (sign of the start); a < 0: w -> 0 (here: the floor)."""
    for w0, expected in ((0.05, 1.0), (-0.05, -1.0), (1.3, 1.0)):
        dyn = CompetitiveDynamics([0.1], floor=0.0)
        dyn.reset([w0])
        assert run(dyn, [0.8], [[0.0]], 0.01, 1000)[0] == pytest.approx(expected, abs=1e-9)
    dyn = CompetitiveDynamics([0.1], floor=1e-3)
    dyn.reset([0.9])
    assert run(dyn, [-0.8], [[0.0]], 0.01, 1000)[0] == pytest.approx(1e-3)


def test_winner_at_one_loser_at_zero_when_interaction_exceeds_advantage():
    """Two behaviours, mutual interactions above both advantages: winner-take-all."""
    a, r = [0.6, 0.5], [[0.0, 1.0], [1.0, 0.0]]
    dyn = CompetitiveDynamics([0.1, 0.1], floor=0.0)
    dyn.reset([0.6, 0.4])
    w = run(dyn, a, r, 0.01, 3000)
    assert w == pytest.approx([1.0, 0.0], abs=1e-9)
    # both winner configurations are fixed points, each linearly stable: the loser's
    # growth rate at w_winner = 1 is (a_loser - r) / T < 0 and the winner's is -2 a / T
    for winner, loser in ((0, 1), (1, 0)):
        w_star = [0.0, 0.0]
        w_star[winner] = 1.0
        eps = 1e-6
        jac = np.empty((2, 2))
        for k in range(2):
            dw = np.zeros(2)
            dw[k] = eps
            t_const = [0.1, 0.1]
            jac[:, k] = (rhs(np.add(w_star, dw), a, r, t_const) - rhs(w_star, a, r, t_const)) / eps
        assert np.all(np.linalg.eigvals(jac).real < 0)
        assert jac[loser, loser] == pytest.approx((a[loser] - 1.0) / 0.1, rel=1e-4)
        assert jac[winner, winner] == pytest.approx(-2.0 * a[winner] / 0.1, rel=1e-4)


def test_weak_competition_gives_the_coexistence_fixed_point():
    """r below a: both stay on at w^2 = (1 - rho) / (1 - rho sigma) (Large et al.)."""
    a1, a2, r12, r21 = 1.0, 0.8, 0.4, 0.5  # r12: 1 on 2, r21: 2 on 1
    rho, sigma = r21 / a1, r12 / a2
    dyn = CompetitiveDynamics([0.1, 0.2], floor=0.0)
    dyn.reset([0.2, 0.9])
    w = run(dyn, [a1, a2], [[0.0, r12], [r21, 0.0]], 0.01, 5000)
    assert w[0] ** 2 == pytest.approx((1 - rho) / (1 - rho * sigma), rel=1e-6)
    assert w[1] ** 2 == pytest.approx((1 - sigma) / (1 - rho * sigma), rel=1e-6)


def test_winner_switches_when_the_advantages_cross():
    """With r_{b',b} = a_{b'} the winner configuration of b' is stable exactly while
    a_{b'} > a_b, so ramping a1 down through a2 and back hands over at each crossing.

    The first hand-over lags the crossing by the time the loser needs to grow out of the
    floor f at the rate (a_loser - a_winner) / T = k t' / T (ramp rate k, t' since the crossing):
    ln(w / f) = k t'^2 / (2 T), i.e. t' = sqrt(2 T ln(w / f) / k) for w ~ 0.7.
    """
    t_const, floor, h, k, a2 = 0.05, 1e-3, 0.01, 0.4, 0.6
    dyn = CompetitiveDynamics([t_const, t_const], floor=floor)
    dyn.reset([1.0, 0.0])
    # a1 = 1 - k t down to 0.2 (t = 2 s), then back up: crossings at t = 1 s and t = 3 s
    times = np.arange(0.0, 4.0, h)
    a1 = np.where(times < 2.0, 1.0 - k * times, 0.2 + k * (times - 2.0))
    leader = []
    for a in a1:
        w = dyn.step([a, a2], [[0.0, a], [a2, 0.0]], h)
        leader.append(0 if abs(w[0]) > abs(w[1]) else 1)
    changes = [times[i] for i in range(1, len(leader)) if leader[i] != leader[i - 1]]
    lag = math.sqrt(2.0 * t_const * math.log(0.7 / floor) / k)  # 1.28 s
    assert len(changes) == 2  # two hand-overs, no chatter
    assert changes[0] - 1.0 == pytest.approx(lag, rel=0.2)
    # back: behaviour 1 was suppressed for only ~1 s, not yet down to the floor: sooner
    assert 3.0 < changes[1] < 3.0 + lag


@settings(max_examples=300, deadline=None)
@given(
    a=st.lists(st.floats(-1e6, 1e6), min_size=3, max_size=3),
    r=st.lists(st.floats(0.0, 1e6), min_size=9, max_size=9),
    w0=st.lists(st.floats(-W_LIMIT, W_LIMIT), min_size=3, max_size=3),
    t_const=st.floats(1e-4, 10.0),
    h=st.floats(0.0, 10.0),
    noise=st.floats(0.0, 10.0),
)
def test_weights_stay_bounded_for_any_input(a, r, w0, t_const, h, noise):
    interactions = [r[0:3], r[3:6], r[6:9]]
    quiet = CompetitiveDynamics([t_const] * 3, floor=0.0)
    quiet.reset(w0)
    w = quiet.step(a, interactions, h)
    assert all(math.isfinite(x) for x in w)
    assert max(abs(x) for x in w) <= max(1.0, max(abs(x) for x in w0)) + 1e-12
    noisy = CompetitiveDynamics([t_const] * 3, noise=noise, seed=1)
    noisy.reset(w0)
    for _ in range(5):
        w = noisy.step(a, interactions, h)
    assert all(math.isfinite(x) and abs(x) <= W_LIMIT for x in w)


ARBITER_LIKE = {
    # stability, manipulability, obstacle, objective: the arbiter's time constants and
    # interactions at a moment when stability is wanted (a_S = 4 > h_S = 4 * 0.9)
    "t": [0.05, 0.1, 0.05, 0.02],
    "a": [4.0, -0.5, -1.0, 1.0],
    "r": [
        [0.0, 12.0, 2.0, 2.0],
        [3.6, 0.0, 12.0, 12.0],
        [3.6, 0.75, 0.0, 12.0],
        [3.6, 0.75, 0.0, 0.0],
    ],
    "w0": [0.05, 0.01, 0.01, 1.0],
}


@pytest.mark.parametrize(("h", "tolerance"), [(0.001, 0.006), (0.01, 0.03)])
def test_integration_converges_to_the_reference_at_the_controller_step(h, tolerance):
    case = ARBITER_LIKE
    duration = 0.3  # the hand-over from the objective to stability
    dyn = CompetitiveDynamics(case["t"], floor=0.0)
    dyn.reset(case["w0"])
    ours = run(dyn, case["a"], case["r"], h, round(duration / h))
    ref = reference(case["w0"], case["a"], case["r"], case["t"], duration)
    assert np.max(np.abs(ours - ref)) < tolerance
    dyn.reset(case["w0"])
    final = run(dyn, case["a"], case["r"], h, round(2.0 / h))
    settled = reference(case["w0"], case["a"], case["r"], case["t"], 2.0)
    assert final == pytest.approx(settled, abs=1e-6)


def test_splitting_error_is_first_order_in_the_step():
    """Gauss-Seidel splitting: the error at the hand-over shrinks like h (measured 0.018,
    0.0038, 0.0004 at 0.01, 0.001, 0.0001 s)."""
    case = ARBITER_LIKE
    ref = reference(case["w0"], case["a"], case["r"], case["t"], 0.3)
    errors = []
    for h in (0.001, 0.0001):
        dyn = CompetitiveDynamics(case["t"], floor=0.0)
        dyn.reset(case["w0"])
        errors.append(np.max(np.abs(run(dyn, case["a"], case["r"], h, round(0.3 / h)) - ref)))
    assert 5.0 < errors[0] / errors[1] < 15.0


@pytest.mark.parametrize("h", [0.02, 0.05, 0.1, 0.5])
def test_large_steps_stay_stable_and_reach_the_same_fixed_point(h):
    """Steps up to 25 T: no overshoot or oscillation, same winner as the exact solution."""
    case = ARBITER_LIKE
    dyn = CompetitiveDynamics(case["t"], floor=0.0)
    dyn.reset(case["w0"])
    history = np.array([dyn.step(case["a"], case["r"], h) for _ in range(round(3.0 / h))])
    assert history[-1] == pytest.approx([1.0, 0.0, 0.0, 0.0], abs=1e-6)
    assert np.all(np.diff(np.abs(history[:, 0])) >= -1e-12)  # the winner rises monotonically
    assert np.all(np.abs(history) <= 1.0 + 1e-12)


def test_explicit_euler_is_unstable_at_the_controller_step():
    """Why the exact update: near w = 1 Euler's factor is 1 - 2 a h / T (here -3), so
    Euler never settles (it wanders chaotically, flipping sign) while the exact update
    sits on w = 1."""
    a, t_const, h = 4.0, 0.02, 0.01
    w, euler = 0.99, []
    for _ in range(40):
        w = w + h / t_const * (a * w - a * w**3)
        euler.append(w)
    assert max(abs(abs(x) - 1.0) for x in euler[-10:]) > 0.3
    assert min(euler) < -1.0 < 1.0 < max(euler)
    dyn = CompetitiveDynamics([t_const], floor=0.0)
    dyn.reset([0.99])
    assert run(dyn, [a], [[0.0]], h, 20)[0] == pytest.approx(1.0, abs=1e-9)


def test_noise_is_deterministic_per_seed_and_restarts_on_reset():
    def sequence(seed):
        dyn = CompetitiveDynamics([0.05, 0.05], noise=0.05, seed=seed)
        dyn.reset([0.5, 0.5])
        return [tuple(dyn.step([1.0, 1.0], [[0.0, 0.5], [0.5, 0.0]], 0.01)) for _ in range(50)]

    assert sequence(3) == sequence(3)
    assert sequence(3) != sequence(4)
    dyn = CompetitiveDynamics([0.05], noise=0.05, seed=3)
    dyn.reset([0.5])
    first = [dyn.step([1.0], [[0.0]], 0.01)[0] for _ in range(10)]
    dyn.reset([0.5])
    assert [dyn.step([1.0], [[0.0]], 0.01)[0] for _ in range(10)] == first


def test_noise_kicks_a_weight_off_the_unstable_fixed_point_and_floor_keeps_it_ready():
    quiet = CompetitiveDynamics([0.05], floor=0.0)
    quiet.reset([0.0])
    assert run(quiet, [1.0], [[0.0]], 0.01, 200)[0] == 0.0
    noisy = CompetitiveDynamics([0.05], noise=0.01, seed=0, floor=0.0)
    noisy.reset([0.0])
    assert abs(run(noisy, [1.0], [[0.0]], 0.01, 200)[0]) == pytest.approx(1.0, abs=0.05)
    floored = CompetitiveDynamics([0.05], floor=1e-3)
    floored.reset([0.0])
    assert run(floored, [1.0], [[0.0]], 0.01, 200)[0] == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: CompetitiveDynamics([]), "at least one behaviour"),
        (lambda: CompetitiveDynamics([0.1, 0.0]), r"time_constants\[2\] must be > 0"),
        (lambda: CompetitiveDynamics([0.1], noise=-1.0), "noise must be >= 0"),
        (lambda: CompetitiveDynamics([0.1], floor=1.0), "floor must be < 1"),
        (lambda: CompetitiveDynamics([0.1]).reset([2.0]), r"w0\[1\] must be in"),
        (lambda: CompetitiveDynamics([0.1]).step([math.nan], [[0.0]], 0.01), "finite"),
        (lambda: CompetitiveDynamics([0.1, 0.1]).step([1, 1], [[0, -1], [0, 0]], 0.01), ">= 0"),
        (lambda: CompetitiveDynamics([0.1]).step([1.0], [[0.0]], -0.01), "h must be >= 0"),
        (lambda: CompetitiveDynamics([0.1]).step([1.0, 2.0], [[0.0]], 0.01), "need 1 and 1x1"),
    ],
)
def test_bad_input_raises_parameter_error(make, message):
    with pytest.raises(ParameterError, match=message):
        make()


def test_subnormal_advantage_changes_nothing():
    """Found by hypothesis: a = 2.2e-313 (subnormal) with w0 = 1.0625 came out as
    1.0625000000032 (products of subnormals keep ~35 bits); a rate below 1e-18 is no change."""
    from ddwmmr.arbiters.competitive import bernoulli_step

    assert bernoulli_step(1.0625, 2.2250738585e-313, 2.2250738585e-313, 1.0) == 1.0625
    assert bernoulli_step(-0.5, -1e-300, 1e-300, 10.0) == -0.5
    # just above the threshold the exact solution still moves towards sqrt(alpha/beta) = 1
    assert bernoulli_step(1.0625, 1e-6, 1e-6, 1.0) < 1.0625
