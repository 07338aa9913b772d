"""A user's QP piece and its ``unit`` (docs/qp.md, "What a piece declares and reads"), and
the limits as hard constraints in hierarchical mode (docs/qp.md, "Priorities and modes").

``unit`` is the length (m) in which a piece's rows take ``v``: a finite length > 0, or None
for rows without ``v``. Anything else is refused in one line when the problem is built, and
a piece declaring None that writes a ``v`` entry or bounds ``v`` is refused at the step it
does (the problem would read that ``v`` in the robot's unit, not in m/s).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, load_trajectory, make_controller, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.qp.limits import Limit
from ddwmmr.qp.tasks import Task
from ddwmmr.resolution.kernels import length_unit
from scaled_robots import scaled_robot

#: A start inside the default robot's workspace: (x, y, phi, th1, th2) in m, m, rad, rad, rad.
Q0 = np.array([0.0, 0.0, 0.0, 0.3, 1.2])
#: The hierarchical solves' limit tolerance (qp.solve.STRICT_PRIMAL_TOL), m/s.
HARD = 1e-9


class BaseSpeedTask(Task):
    """``v = target`` (m/s unless ``unit`` says otherwise)."""

    name = "base speed"

    def __init__(self, weight: float, target: float, when: float = -1.0) -> None:
        super().__init__(weight)
        self.target, self.when = target, when

    def compute(self, ctx, jac, error):
        jac[:] = (1.0 if ctx.t > self.when else 0.0, 0.0, 0.0, 0.0)
        error[0] = self.target


class Th2Posture(Task):
    """``th2dot = -(th2 - 1.2)`` (rad/s): no ``v`` anywhere."""

    name = "th2 posture"

    def compute(self, ctx, jac, error):
        jac[:] = (0.0, 0.0, 0.0, 1.0)
        error[0] = -(ctx.th2 - 1.2)


class BoxCap(Limit):
    """``|v| <= cap`` (m/s) in the box."""

    name = "box cap"

    def __init__(self, cap: float) -> None:
        self.cap = cap

    def compute(self, ctx, G, lower, upper, lb, ub):
        lb[0], ub[0] = max(lb[0], -self.cap), min(ub[0], self.cap)


class RowCap(Limit):
    """``|v| <= cap`` (m/s) as a general row, written from time ``when`` on (s); before,
    the row bounds the yaw rate alone."""

    rows = 1
    name = "row cap"

    def __init__(self, cap: float, when: float = -1.0) -> None:
        self.cap, self.when = cap, when

    def compute(self, ctx, G, lower, upper, lb, ub):
        G[0] = (1.0, 0.0, 0.0, 0.0) if ctx.t > self.when else (0.0, 1.0, 0.0, 0.0)
        lower[0], upper[0] = -self.cap, self.cap


def _command(robot: Robot, **options) -> np.ndarray:
    """One qp command at ``Q0`` towards a point 1 m ahead."""
    controller = make_controller("qp", robot, **options)
    controller.reset(None, Q0)
    return controller.command(0.0, Q0, np.array([1.0, 0.0, 0.0]), np.zeros(3))


def _scaled_run(factor: float, duration: float = 2.0, **options):
    """``qp`` on the robot scaled by ``factor``, on the default ellipse and start offset
    scaled alike."""
    robot = scaled_robot(factor)
    ellipse = Ellipse(a=factor * Ellipse().a, b=factor * Ellipse().b)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scaled lengths look like unit mistakes
        return simulate(
            robot,
            ellipse,
            "qp",
            duration=duration,
            initial_offset=(-0.03 * factor, -0.03 * factor),
            **options,
        )


BAD_UNITS = [0, 0.0, -1.0, math.inf, -math.inf, math.nan, "m", True, [1.0]]


@pytest.mark.parametrize("unit", BAD_UNITS, ids=repr)
@pytest.mark.parametrize("kind", ["tasks", "limits"])
def test_a_bad_unit_is_refused_in_one_line_naming_the_piece(kind, unit):
    """0 and "m" used to raise a bare ZeroDivisionError / TypeError, -1 and inf ran with
    the cap dropped or the target reversed, nan blamed compute(), True passed as 1.0."""
    piece = BaseSpeedTask(100.0, -0.2) if kind == "tasks" else BoxCap(0.05)
    piece.unit = unit
    with pytest.raises(ParameterError) as caught:
        make_controller("qp", Robot(), **{kind: [piece]})
    message = str(caught.value)
    assert "\n" not in message
    assert repr(piece.name) in message and "unit must be a finite length > 0" in message
    assert "or None" in message


@pytest.mark.parametrize("unit", [0.35, 2, np.float64(1.5)], ids=repr)
def test_a_positive_unit_converts_the_pieces_v(unit):
    """A box cap of 0.05 units/s caps ``v`` at 0.05 * unit m/s; the default robot's
    unconstrained command here is ~0.16 m/s."""
    cap = BoxCap(0.05)
    cap.unit = unit
    v = _command(Robot(), limits=[cap])[0]
    assert v == pytest.approx(0.05 * float(unit), rel=1e-12)


def test_a_unit_none_limit_writing_a_v_row_is_refused():
    """Unit None read the row ``|v| <= 0.1`` in the robot's unit: 0.8 m/s on the 8x robot."""
    cap = RowCap(0.1)
    cap.unit = None
    with pytest.raises(ParameterError, match=r"^RowCap 'row cap': unit = None .* wrote \[1\.0\] "):
        _scaled_run(8.0, limits=[cap])


def test_a_unit_none_limit_bounding_v_is_refused():
    cap = BoxCap(0.1)
    cap.unit = None
    with pytest.raises(ParameterError, match=r"BoxCap 'box cap': unit = None .* bounded v"):
        _scaled_run(8.0, limits=[cap])


@pytest.mark.parametrize("mode", ["weighted", "hierarchical"])
def test_a_unit_none_task_writing_v_later_is_refused_at_that_step(mode):
    """Checked every step, not only the first: the v entry appears after 0.5 s."""
    task = BaseSpeedTask(10.0, 0.1, when=0.5)
    task.unit = None
    with pytest.raises(ParameterError, match=r"BaseSpeedTask 'base speed': .* at t = 0\.5\d* s"):
        _scaled_run(8.0, mode=mode, tasks=[task])


def test_a_unit_none_task_without_v_runs_as_with_unit_one():
    """A v-free piece gives the same run whether it declares None or 1.0 (8x robot)."""
    free = Th2Posture(0.5)
    free.unit = None
    metres = Th2Posture(0.5)
    none_run = _scaled_run(8.0, tasks=[free])
    metre_run = _scaled_run(8.0, tasks=[metres])
    for key in ("v", "w", "th1", "th2", "position_error_m"):
        np.testing.assert_array_equal(none_run.timeseries[key], metre_run.timeseries[key])


def test_the_robots_unit_makes_a_linear_task_scale_free():
    """A task declaring the robot's unit, target in units/s, runs the default robot's
    steps scaled by s on the 8x robot (docs/qp.md: a linear task in SI is weighed per
    (unit/s)^2 there)."""
    factor = 8.0

    class UnitSpeed(BaseSpeedTask):
        unit = length_unit(scaled_robot(factor).L1)

    reference = _scaled_run(1.0, tasks=[BaseSpeedTask(10.0, 0.1)])
    scaled = _scaled_run(factor, tasks=[UnitSpeed(10.0, 0.1)])
    np.testing.assert_allclose(
        scaled.timeseries["v"] / factor, reference.timeseries["v"], rtol=0.0, atol=1e-12
    )
    si = _scaled_run(factor, tasks=[BaseSpeedTask(10.0, 0.1 * factor)])
    assert np.max(np.abs(si.timeseries["v"] / factor - reference.timeseries["v"])) > 1e-3


@pytest.mark.parametrize(
    "limit",
    [{"max_base_speed": 0.15}, {"limits": [BoxCap(0.15)]}, {"limits": [RowCap(0.15)]}],
    ids=["max_base_speed", "user box", "user row"],
)
def test_hierarchical_mode_holds_a_speed_cap(limit):
    """DAQP's default feasibility tolerance (1e-6) let level 2 overrun the cap by 2e-7 m/s
    on the default robot; both levels now solve to 1e-9 (quadprog and weighted mode hold
    it to rounding)."""
    result = simulate(
        Robot(), load_trajectory("ellipse"), "qp", mode="hierarchical", duration=4.0, **limit
    )
    speed = np.abs(result.timeseries["v"])
    assert speed.max() - 0.15 <= HARD
    assert speed.max() > 0.15 - 1e-6  # the cap is active
    assert result.summary["qp_fallbacks"] == 0
