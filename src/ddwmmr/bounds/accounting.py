"""Where a trajectory's time goes, against the lower bound's force budget.

The lower bound (:mod:`ddwmmr.bounds.lower`) prices a task by the wheels' shared force
budget alone. Along one trajectory of the thesis plant the same argument is an identity:
every second of it is either a second of budget spent or a second of budget left unused,
and the spent budget splits exactly into the bound's own terms plus what the bound lets go
free. With ``F = F_l + F_r``, ``T = b (F_r - F_l)``, ``m vdot + c1 v = F`` and ``I(th2) wdot
+ c2 w = T`` (docs/mpc.md, "How tight")::

    t_f = c1 P / (2 F_w) + (c2 - k) Phi / (2 F_w b)        the bound's price of the path
        + (k Phi - int I' |w|) / (2 F_w b)                 the turn price's allowance for
                                                           the arm swinging the inertia
        + m |v_f| / (2 F_w) + I |w_f| / (2 F_w b)          motion left at the end
        + 2 int (sign(v) F)^- / (2 F_w)
        + 2 int (sign(w) T)^- / (2 F_w b)                  wheels pushing against the motion
        + int (1 - max(|F_l|, |F_r|) / F_w)                force left unused

(``P`` the base centre's path, ``Phi`` its total rotation, ``k`` the fastest the inertia
changes, capped at ``c2`` as in the price; on the plant's steps, which hold the inertia over
each step, ``int I' |w|`` is ``sum_k (I_k - I_{k-1}) |w_k|`` and the end's ``I`` the last
step's). :func:`account` replays a trajectory on :class:`~ddwmmr.plants.thesis.ThesisPlant`
as :func:`~ddwmmr.bounds.replay.replay` does and sums each term over the plant's exact
steps, so the terms add up to the time to rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ddwmmr.bounds.lower import Prices
from ddwmmr.bounds.replay import REPLAY_DT, held_commands
from ddwmmr.model import Robot
from ddwmmr.plants.thesis import ThesisPlant, first_order_step

if TYPE_CHECKING:
    from ddwmmr.mpc.min_time import MinimumTime


@dataclass(frozen=True)
class Accounting:
    """A trajectory's time (s) split into the force budget's terms (module docstring).

    Attributes:
        time_s: the trajectory's time.
        path_s, turn_s: its base path and rotation at the lower bound's prices (the
            bound is the least of their sum over every path that can do the task).
        allowance_s: what the turn price leaves for the arm swinging the yaw inertia,
            less what the arm did.
        momentum_s: speed and yaw rate left at the end.
        braking_s: the wheels pushing against the motion (twice the force spent so).
        idle_s: force left unused (no wheel at its limit).
        path_m: base centre's path length (m); rotation_rad: its total rotation (rad).
    """

    time_s: float
    path_s: float
    turn_s: float
    allowance_s: float
    momentum_s: float
    braking_s: float
    idle_s: float
    path_m: float
    rotation_rad: float

    @property
    def terms_s(self) -> float:
        """The sum of the six terms (s): the time, to rounding."""
        return (
            self.path_s
            + self.turn_s
            + self.allowance_s
            + self.momentum_s
            + self.braking_s
            + self.idle_s
        )


def magnitude_and_opposed(
    x0: float, u: float, gain: float, tau: float, dt: float
) -> tuple[float, float]:
    """For ``tau xdot + x = gain u`` with ``u`` held over ``dt`` (s) from ``x0``: ``(integral
    of |x|, time x is of the opposite sign to u)``. ``x`` moves monotonically towards
    ``gain u``, so it changes sign at most once."""
    target = gain * u
    _, integral = first_order_step(x0, u, gain, tau, dt)
    if x0 * target >= 0.0:
        return abs(integral), 0.0
    crossing = tau * math.log((x0 - target) / -target)
    if crossing >= dt:
        return abs(integral), dt
    _, before = first_order_step(x0, u, gain, tau, crossing)
    return abs(before) + abs(integral - before), crossing


def account(robot: Robot, result: MinimumTime, until: float, dt: float = REPLAY_DT) -> Accounting:
    """The force-budget accounting (module docstring) of ``result`` (``times``, ``states``,
    ``inputs`` as :class:`~ddwmmr.mpc.min_time.MinimumTime` has them: wheel forces in N,
    joint rates in rad/s) replayed on the thesis plant in steps of at most ``dt`` (s)
    from its first state at rest, over its first ``until`` seconds (its time: for a
    solution, the replay's :attr:`~ddwmmr.bounds.replay.Replay.time_s`; all of it if
    shorter)."""
    prices = Prices.from_robot(robot)
    plant = ThesisPlant(robot)
    plant.reset(np.asarray(result.states[0][:5], dtype=float), dt)
    budget, lever = 2.0 * plant.force_limit, plant.wheel_lever
    t = path = rotation = brake_v = brake_w = pumped = idle = 0.0
    last_inertia = None
    for command, step in held_commands(plant, np.asarray(result.times), result.inputs, dt):
        if t >= until - 1e-9:
            break
        state = plant.state
        inertia = plant.inertia(state.th1, state.th2)
        if last_inertia is not None:  # summation by parts of I d|w| over the steps
            pumped += (inertia - last_inertia) * abs(state.w)
        last_inertia = inertia
        f1, f2 = plant.clip_force(command.left), plant.clip_force(command.right)
        force, torque = f1 + f2, (f2 - f1) * lever
        distance, opposed_v = magnitude_and_opposed(
            state.v, force, 1.0 / plant.c1, plant.mass / plant.c1, step
        )
        turned, opposed_w = magnitude_and_opposed(
            state.w, torque, 1.0 / plant.c2, inertia / plant.c2, step
        )
        path, rotation = path + distance, rotation + turned
        brake_v += abs(force) * opposed_v
        brake_w += abs(torque) * opposed_w
        idle += step * (1.0 - max(abs(f1), abs(f2)) / plant.force_limit)
        plant.step(t, command, step)
        t += step
    end = plant.state
    full_turn = plant.c2 / (budget * lever)
    terms = {
        "time_s": t,
        "path_s": prices.drive * path,
        "turn_s": prices.turn * rotation,
        "allowance_s": (full_turn - prices.turn) * rotation - pumped / (budget * lever),
        "momentum_s": plant.mass * abs(end.v) / budget
        + (last_inertia or 0.0) * abs(end.w) / (budget * lever),
        "braking_s": 2.0 * brake_v / budget + 2.0 * brake_w / (budget * lever),
        "idle_s": idle,
        "path_m": path,
        "rotation_rad": rotation,
    }
    return Accounting(**{name: float(value) for name, value in terms.items()})
