"""One home each for four things that were defined twice: the study tables' number
formatter (:func:`ddwmmr.scenarios.studies.table_number`), the check of the minimum-time
problem's ``intervals_per_leg`` (:func:`ddwmmr.errors.check_int_at_least`, in
:class:`~ddwmmr.mpc.min_time.FreeTimeOCP`), the base motion ``qdot = B(phi) u``
(:func:`ddwmmr.model.kinematics.base_motion`, which the kinematic plant's integrators and
the reference trajectory call) and the rectangle's stability terms with their gradients
(:func:`ddwmmr.model.stability.stability_terms_from_trig`, which the qp's stability limit
uses)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import load_trajectory
from ddwmmr.bounds.diffdrive import diffdrive_model
from ddwmmr.bounds.search import start_state
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot, kinematics
from ddwmmr.model import stability as model_stability
from ddwmmr.model.stability import STABILITY_CAP
from ddwmmr.mpc.min_time import FreeTimeOCP, LegEnd, MinimumTimeProblem
from ddwmmr.plants import kinematic
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.qp.limits import stability as qp_stability
from ddwmmr.resolution import reference
from ddwmmr.resolution.reference import ReferenceTrajectory
from ddwmmr.scenarios import arbiter_study, studies

ROBOT = Robot()


# -- the study tables' numbers ------------------------------------------------------------
@pytest.mark.parametrize(
    ("value", "text"),
    [
        (None, "–"),
        (math.nan, "–"),
        (7, "7"),
        (12345, "12345"),
        (0.123456, "0.123"),
        (52.34, "52.3"),
        (1234.5, "1.23e+03"),
        (0.0, "0"),
    ],
)
def test_table_number_formats_a_cell(value, text):
    assert studies.table_number(value) == text


def test_the_arbiter_study_tables_use_the_studies_formatter(monkeypatch):
    """The noise table's numbers come from studies.table_number (a second formatter in
    arbiter_study would ignore the patch)."""
    monkeypatch.setattr(arbiter_study, "table_number", lambda value: f"<{value}>")
    row = dict(label="a", noise=0.1, level=2.0, seed=3, failed=0)
    row.update(mean_time_s=52.345, min_stability=1.5, fix_entries=2)
    table = arbiter_study.noise_table([row])
    assert "| <52.345> | <1.5> | <2> |" in table
    assert arbiter_study.table_number is not studies.table_number  # the patch took
    monkeypatch.undo()
    assert arbiter_study.table_number is studies.table_number
    assert "| 52.3 | 1.5 | 2 |" in arbiter_study.noise_table([row])
    assert not hasattr(arbiter_study, "_g") and not hasattr(studies, "_g")


# -- intervals_per_leg ----------------------------------------------------------------------
BAD_INTERVALS = ["30", None, math.nan, math.inf, 0, 1, -3, 2.5, True, [3]]


def _free_time(intervals) -> FreeTimeOCP:
    end = LegEnd(lambda x: x[:0], np.zeros(0), np.zeros(0))
    return FreeTimeOCP(diffdrive_model(1.0, 1.0, 1.0), [0.0, 0.0, 0.0], [end], intervals)


def _minimum_time(intervals) -> MinimumTimeProblem:
    return MinimumTimeProblem(ROBOT, [(1.0, 1.0)], start_state(ROBOT), intervals_per_leg=intervals)


@pytest.mark.parametrize("build", [_free_time, _minimum_time])
@pytest.mark.parametrize("bad", BAD_INTERVALS, ids=repr)
def test_bad_intervals_per_leg_is_a_one_line_parameter_error(build, bad):
    with pytest.raises(ParameterError) as info:
        build(bad)
    message = str(info.value)
    assert message.startswith("intervals_per_leg must be an integer >= 2 (got ")
    assert "\n" not in message


@pytest.mark.parametrize("build", [_free_time, _minimum_time])
def test_a_whole_float_or_numpy_intervals_per_leg_is_taken_as_an_int(build):
    for value in (4.0, np.int64(4)):
        problem = build(value)
        assert problem.M == 4 and type(problem.M) is int
        assert problem.n == 4


# -- the base motion qdot = B(phi) u ---------------------------------------------------------
STATES = [
    ([0.1, 0.2, 0.3, 0.4, -0.5], (0.3, 0.2, 0.1, -0.1)),
    ([-1.0, 2.0, -2.9, 1.2, 0.7], (-0.4, -0.15, 0.05, 0.2)),
    ([3.0, -0.5, 1.6, -0.3, 1.9], (0.25, 0.0, -0.2, 0.0)),
]


def test_base_motion_is_b_of_phi_times_u():
    for state, u in STATES:
        phi = state[2]
        rates = kinematics.base_motion(phi, *u)
        np.testing.assert_allclose(rates, kinematics.input_matrix(phi) @ np.array(u), atol=0)
        assert rates[:2] == (u[0] * math.cos(phi), u[0] * math.sin(phi))
        assert np.array_equal(kinematics.qdot_from_u(phi, u), np.array(rates))
        assert np.array_equal(KinematicPlant.derivative(np.array(state), np.array(u)), rates)


def _count_calls(monkeypatch, module) -> list[int]:
    calls = [0]
    home = kinematics.base_motion

    def counted(*args):
        calls[0] += 1
        return home(*args)

    monkeypatch.setattr(module, "base_motion", counted)
    return calls


def _rk4_by_hand(state, u, dt):
    """One RK4 step of the held u, the stage rates written out."""
    phi = state[2]
    v, w, r1, r2 = u

    def rate(p):
        return np.array([v * math.cos(p), v * math.sin(p), w, r1, r2])

    k1 = rate(phi)
    k2 = rate(phi + 0.5 * dt * k1[2])
    k3 = rate(phi + 0.5 * dt * k2[2])
    k4 = rate(phi + dt * k3[2])
    return np.array(state) + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_the_kinematic_plant_integrates_with_the_home(monkeypatch, integrator):
    plant = KinematicPlant(ROBOT, integrator)
    calls = _count_calls(monkeypatch, kinematic)
    dt = 0.01
    for state, u in STATES:
        q_next, u0, saturated = plant.integrate(0.0, np.array(state), dt, None, np.array(u))
        assert not saturated and np.array_equal(u0, u)
        if integrator == "euler":
            expected = np.array(state) + dt * np.array(kinematics.base_motion(state[2], *u))
            assert np.array_equal(q_next, expected)  # bit for bit: the same operations
        else:
            np.testing.assert_allclose(q_next, _rk4_by_hand(state, u, dt), rtol=0, atol=1e-15)
    assert calls[0] == len(STATES) * (1 if integrator == "euler" else 4)


def test_the_reference_trajectory_rates_come_from_the_home(monkeypatch):
    trajectory = load_trajectory("ellipse")
    ref = ReferenceTrajectory(ROBOT, trajectory, np.array([0.0, 0.0, 0.0, 0.6, -1.2]))
    calls = _count_calls(monkeypatch, reference)
    q = [0.1, 0.2, 0.3, 0.6, -1.2]
    rate, _ = ref._rate(q, trajectory.velocity(1.0).tolist())
    assert calls[0] == 1
    v = rate[0] / math.cos(q[2])
    assert rate[:2] == [v * math.cos(q[2]), v * math.sin(q[2])]
    assert isinstance(rate, list) and len(rate) == 5


# -- the stability terms and their gradients ---------------------------------------------------
def _closed_form(k, th1, th2):
    """The rectangle's terms written out: S_i = h / |c_i|, dS_i = -S_i dc_i / c_i."""
    x = k.A * math.cos(th1) + k.B * math.cos(th1 + th2)
    y = k.A * math.sin(th1) + k.B * math.sin(th1 + th2)
    dx = (-k.A * math.sin(th1) - k.B * math.sin(th1 + th2), -k.B * math.sin(th1 + th2))
    dy = (x, k.B * math.cos(th1 + th2))
    terms = []
    for offset, half, (d1, d2) in ((x, k.half_length, dx), (y, k.half_width, dy)):
        if abs(offset) * STABILITY_CAP <= half:
            terms.append((STABILITY_CAP, 0.0, 0.0))
        else:
            s = half / abs(offset)
            terms.append((s, -s / offset * d1, -s / offset * d2))
    return tuple(terms)


def test_the_qp_stability_rows_are_the_model_terms():
    assert qp_stability.stability_terms_from_trig is model_stability.stability_terms_from_trig
    rng = np.random.default_rng(0)
    capped = 0
    for payload in (0.0, 1.25, 3.0):
        k = ROBOT.with_payload(payload).com_coefficients
        for th1, th2 in rng.uniform(-4.0, 4.0, (2000, 2)):
            th1, th2 = float(th1), float(th2)
            terms = qp_stability.stability_terms_gradient(k, th1, th2)
            assert terms == _closed_form(k, th1, th2)
            s_lon, s_lat, _ = model_stability.stability_terms(k, th1, th2)
            assert (terms[0][0], terms[1][0]) == (s_lon, s_lat)
            lat_first = terms[1][0] <= terms[0][0]
            assert model_stability.stability_gradient(k, th1, th2) == terms[1 if lat_first else 0]
            capped += STABILITY_CAP in (s_lon, s_lat)
    assert 0 < capped < 6000  # both branches of the cap were met
