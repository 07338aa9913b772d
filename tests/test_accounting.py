"""The force-budget accounting of a trajectory (ddwmmr.bounds.accounting): its terms add up
to the time on a replayed minimum-time solution, and each term matches its closed form on
straight drives and turns from rest."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.bounds.accounting import account, magnitude_and_opposed
from ddwmmr.bounds.lower import Prices, budget_bound
from ddwmmr.bounds.replay import replay
from ddwmmr.bounds.search import start_state
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc.min_time import MinimumTimeProblem

HEAVY = Robot().with_payload(3.0)
MODEL = sym.ThesisDynamics.from_robot(HEAVY)
TAU = MODEL.mass / MODEL.c1  # the speed's time constant (s)
BUDGET = 2.0 * MODEL.force_limit  # both wheels' force (N)


def held(*pieces):
    """A trajectory from rest at the start pose holding ``(duration s, F_l N, F_r N[,
    shoulder rad/s, elbow rad/s])`` in turn (the arm still where no rates are given)."""
    times = np.concatenate([[0.0], np.cumsum([p[0] for p in pieces])])
    inputs = np.array([[*p[1:], 0.0, 0.0][:4] for p in pieces])
    states = np.tile(start_state(HEAVY), (len(times), 1))
    return SimpleNamespace(times=times, states=states, inputs=inputs)


def covered(t: float) -> float:
    """Distance (m) from rest in ``t`` s under both wheels' full force."""
    return MODEL.top_speed * (t - TAU * (1.0 - math.exp(-t / TAU)))


def test_a_straight_drive_from_rest_is_its_path_and_its_end_speed():
    """Full force for 2 s: no braking, no force unused; the path at the bound's price plus
    the speed left at the end is the time (closed form of the first-order speed)."""
    result = account(HEAVY, held((2.0, 10.0, 10.0)), until=2.0)
    speed = MODEL.top_speed * (1.0 - math.exp(-2.0 / TAU))
    assert result.time_s == pytest.approx(2.0, abs=1e-9)
    assert result.path_m == pytest.approx(covered(2.0), rel=1e-9)
    assert result.momentum_s == pytest.approx(MODEL.mass * speed / BUDGET, rel=1e-9)
    assert result.path_s == pytest.approx(MODEL.c1 * covered(2.0) / BUDGET, rel=1e-9)
    assert result.braking_s == result.idle_s == result.turn_s == 0.0
    assert result.terms_s == pytest.approx(2.0, abs=1e-9)


def test_reversing_the_force_counts_the_braking_until_the_speed_turns():
    """1 s forwards then 1 s of full reverse force: the wheels push against the motion
    from 1 s until the speed crosses zero, ``tau ln((v1 + v_top) / v_top)`` later, and
    that time counts twice."""
    v1 = MODEL.top_speed * (1.0 - math.exp(-1.0 / TAU))
    crossing = TAU * math.log((v1 + MODEL.top_speed) / MODEL.top_speed)
    result = account(HEAVY, held((1.0, 10.0, 10.0), (1.0, -10.0, -10.0)), until=2.0)
    assert 0.0 < crossing < 1.0
    assert result.braking_s == pytest.approx(2.0 * crossing, rel=1e-6)
    assert result.terms_s == pytest.approx(2.0, abs=1e-9)


def test_half_force_leaves_half_the_budget_unused():
    result = account(HEAVY, held((1.5, 5.0, 5.0)), until=1.5)
    assert result.idle_s == pytest.approx(0.75, rel=1e-9)
    assert result.terms_s == pytest.approx(1.5, abs=1e-9)


def test_a_turn_in_place_is_its_rotation_at_the_full_turn_price():
    """Opposite full forces, the arm still: no path; the rotation at the bound's price
    plus the allowance (nothing pumped) is the steady-turn price ``c2 / (2 F_w b)``."""
    result = account(HEAVY, held((1.0, -10.0, 10.0)), until=1.0)
    inertia = MODEL.inertia(start_state(HEAVY)[4])
    tau_w = inertia / MODEL.c2
    rate = 2.0 * MODEL.force_limit * MODEL.half_width / MODEL.c2
    rotation = rate * (1.0 - tau_w * (1.0 - math.exp(-1.0 / tau_w)))
    assert result.path_m == 0.0
    assert result.rotation_rad == pytest.approx(rotation, rel=1e-9)
    full_price = MODEL.c2 / (BUDGET * MODEL.half_width)
    assert result.turn_s + result.allowance_s == pytest.approx(full_price * rotation, rel=1e-9)
    assert result.turn_s == pytest.approx(Prices.from_robot(HEAVY).turn * rotation, rel=1e-9)
    assert result.terms_s == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("dt", [0.001, 0.05])
def test_the_terms_add_up_while_the_arm_swings_the_inertia(dt):
    """Turning, driving and braking while the elbow swings at its full rate both ways: the
    inertia changes every step, and the terms still add up to the time to rounding (on
    coarse steps too, where a slip in the summation by parts or in the end's inertia would
    show), with the allowance non-negative (the joints within their rate limit)."""
    trajectory = held(
        (0.7, -10.0, 10.0, 0.0, 2.0),
        (0.5, 10.0, -3.0, 1.0, -2.0),
        (0.9, -10.0, 10.0, 0.0, 2.0),
        (0.4, 10.0, 10.0, 0.0, -2.0),
    )
    result = account(HEAVY, trajectory, until=2.5, dt=dt)
    assert result.time_s == pytest.approx(2.5, abs=1e-9)
    assert result.rotation_rad > 1.0 and result.path_m > 0.1
    assert result.terms_s == pytest.approx(result.time_s, abs=1e-9)
    assert result.allowance_s >= 0.0


def test_the_terms_add_up_to_a_replayed_solution_s_time():
    """A minimum-time solution through two waypoints, replayed on the thesis plant: the
    six terms sum to the replay's time to rounding, it spends the whole budget (no wheel
    below its limit for long), and its path and rotation at the bound's prices are at least
    the lower bound (the bound is their least over every path that does the task)."""
    waypoints = [(2.0, 1.0), (0.5, 2.0)]
    problem = MinimumTimeProblem(
        HEAVY,
        waypoints,
        start_state(HEAVY),
        intervals_per_leg=20,
        stability_min=1.2505,
        tolerance=0.009,
    )
    solution = problem.solve(problem.straight_line_guess())
    check = replay(HEAVY, solution, waypoints)
    assert solution.success and check.ok
    result = account(HEAVY, solution, until=check.time_s)
    assert result.time_s == pytest.approx(check.time_s, abs=1e-9)
    assert result.terms_s == pytest.approx(result.time_s, abs=1e-9)
    assert result.allowance_s >= 0.0
    assert result.idle_s < 0.02 * result.time_s
    bound = budget_bound(HEAVY, waypoints, arcs=144).value
    assert bound <= result.path_s + result.turn_s <= result.time_s


@pytest.mark.parametrize(
    ("x0", "u", "expected_opposed"),
    [(0.5, 2.0, 0.0), (0.0, -1.0, 0.0), (-0.2, 2.0, 0.8 * math.log(1.2)), (-3.0, 0.1, 0.3)],
)
def test_magnitude_and_opposed_against_fine_sampling(x0, u, expected_opposed):
    """``tau xdot + x = gain u`` sampled finely: the integral of |x| and the time x opposes
    u (the crossing time in closed form where it crosses within the step)."""
    gain, tau, dt = 0.5, 0.8, 0.3
    magnitude, opposed = magnitude_and_opposed(x0, u, gain, tau, dt)
    s = np.linspace(0.0, dt, 200_001)
    x = gain * u + (x0 - gain * u) * np.exp(-s / tau)
    trapezoid = float(np.sum(0.5 * (np.abs(x[1:]) + np.abs(x[:-1])) * np.diff(s)))
    assert magnitude == pytest.approx(trapezoid, rel=1e-6)
    fine = float(np.sum(np.sign(x[:-1]) * np.sign(u) < 0) * (s[1] - s[0]))
    assert opposed == pytest.approx(fine, abs=2e-6)
    assert opposed == pytest.approx(expected_opposed, abs=1e-12)
