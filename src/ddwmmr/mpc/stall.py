"""When the ``mpc``'s waypoint plan is stuck and the next step should start cold.

One real-time iteration per step follows the optimum it is near; from a poor warm start
that can be a stationary point far from the best plan. Three rules drop the plan (each
fires at most once per :data:`STALL_TIME`):

* the end effector has not moved :data:`STALL_PROGRESS` robot length units (net; 1 mm on
  the default robot) for :data:`STALL_TIME` short of the target;
* every plan for :data:`STALL_TIME` needed the constraints' slack (largest slack above
  :data:`STALL_SLACK`, in the rows' units, m for the stability box; the joint box's slack
  left out, ``ShootingOCP.max_slack``): a plan that cannot meet its hard constraints is
  stuck (on the physics plant: spinning on the spot with the arm stretched at the dynamic
  floor);
* every plan for :data:`STALL_TIME` promised to arrive in the same time (its free horizon
  within :data:`FROZEN_HORIZON` of the first's, strictly between its bounds): a plan that
  is followed arrives a second sooner every second, so one whose arrival recedes with the
  clock is frozen, even while the end effector moves (:meth:`StallWatch.horizon_frozen`).

A fourth timer serves the plans through a target to the next one (``lookahead``):
:meth:`StallWatch.arrival_overdue` when every plan for :data:`STALL_TIME` said "there at
the shortest horizon" without the target being reached.

Why each rule: docs/mpc.md, "Formulation".
"""

from __future__ import annotations

import math

#: How long (s) a plan may make no progress, need slack or stay frozen before it is dropped.
STALL_TIME = 0.5
#: Net end-effector motion (the robot's length units, ``L1 / 0.35 m``: m on the default
#: robot) that counts as progress: a robot s times the default's size moves s times as far
#: in the same time, so a fixed distance would be noise on a large robot and most of a
#: small one's motion.
STALL_PROGRESS = 1e-3
#: Largest slack (rows' units) of a plan that meets its constraints.
STALL_SLACK = 1e-3
#: Change of the promised arrival horizon (s) below which the plans count as frozen.
FROZEN_HORIZON = 0.05


class StallWatch:
    """The rules' memory over a run (reset with the controller), for a robot of length unit
    ``length_unit`` (m, ``ddwmmr.resolution.kernels.length_unit``; 1.0 for the default
    robot): the progress rule's distance is :data:`STALL_PROGRESS` of it."""

    def __init__(self, length_unit: float = 1.0) -> None:
        self._progress = STALL_PROGRESS * length_unit  # m
        self._anchor: tuple[float, float] | None = None
        self._anchor_time = 0.0
        self._infeasible_since: float | None = None  # first of the plans that needed slack
        self._arriving_since: float | None = None  # first of the plans at the shortest horizon
        self._promise: tuple[float, float] | None = None  # (t, horizon): first of the run

    def fresh_plan(self) -> None:
        """A cold start: its plans get their own :data:`STALL_TIME` to need slack."""
        self._infeasible_since = None

    def stuck(self, t: float, end_effector: tuple[float, float], new_target: bool) -> bool:
        """True when the progress or the slack rule fires at time t (s) with the end effector at
        ``end_effector`` (m, world); ``new_target``: the target just changed."""
        return self._stalled(t, end_effector, new_target) or self._infeasible_too_long(t)

    def plan_slack(self, t: float, slack: float) -> None:
        """The plan made at t (s) needed ``slack`` (its largest, ``ShootingOCP.max_slack``)."""
        if slack <= STALL_SLACK:
            self._infeasible_since = None
        elif self._infeasible_since is None:
            self._infeasible_since = t

    def plan_arrival(self, t: float, shortest: bool, new_target: bool) -> None:
        """The plan made at t (s) reaches its target at the shortest horizon (``shortest``);
        ``new_target``: the target just changed."""
        if not shortest:
            self._arriving_since = None
        elif new_target or self._arriving_since is None:
            self._arriving_since = t

    def plan_horizon(self, t: float, horizon: float, free: bool, cold: bool) -> None:
        """The plan made at t (s) promises to arrive in ``horizon`` s; ``free``: the horizon
        lies strictly between its bounds (a plan at its longest only gets as close as it
        can; one at its shortest is about to arrive, or is the arrival timer's through a
        target); ``cold``: the plan started cold (a new target, a restart)."""
        promise = self._promise
        if not free:
            self._promise = None
        elif cold or promise is None or abs(horizon - promise[1]) > FROZEN_HORIZON:
            self._promise = (t, horizon)

    def horizon_frozen(self, t: float) -> bool:
        """True (once per :data:`STALL_TIME`) when every plan for longer than STALL_TIME (s)
        up to t promised the same arrival horizon (:meth:`plan_horizon`)."""
        promise = self._promise
        if promise is None or t - promise[0] <= STALL_TIME:
            return False
        self._promise = None  # the next plan starts a new run
        return True

    def arrival_overdue(self, t: float) -> bool:
        """True when every plan for longer than :data:`STALL_TIME` (s) up to t said "there at
        the shortest horizon" (:meth:`plan_arrival`) and the target is still ahead."""
        since = self._arriving_since
        return since is not None and t - since > STALL_TIME

    def _stalled(self, t: float, end_effector: tuple[float, float], new: bool) -> bool:
        """True (once per STALL_TIME) when the end effector has stopped short of the target."""
        xe, ye = end_effector
        anchor = self._anchor
        if new or anchor is None or math.hypot(xe - anchor[0], ye - anchor[1]) > self._progress:
            self._anchor, self._anchor_time = (xe, ye), t
            return False
        if t - self._anchor_time > STALL_TIME:
            self._anchor_time = t
            return True
        return False

    def _infeasible_too_long(self, t: float) -> bool:
        """True (once per STALL_TIME) when every plan since STALL_TIME needed slack."""
        since = self._infeasible_since
        if since is None or t - since <= STALL_TIME:
            return False
        self._infeasible_since = t
        return True
