"""Whether a run tracked its trajectory: one verdict, computed from a run's summary.

Every tool reports it the same way (``track``'s table, ``compare``'s console summary and
report, the simulator's summary line, :attr:`SimulationResult.summary`): the summary keys

* ``verdict``: ``"tracked"``, or ``"did not track: <what went wrong>; likely cause:
  <why> (see docs/...)"``, either followed by ``"; warning: ..."`` where a physics plant
  unloaded an edge of the support polygon (:func:`support_warning`, below) and where the
  run started below its stability floor without the verdict saying so already
  (:func:`floor_warning`, below);
* ``verdict_reasons``: the machine-readable codes of what went wrong (an empty list when
  it tracked), each one of :data:`REASONS`.

A run did not track when any of these holds (thresholds documented in docs/cli.md,
"Verdict"):

* ``diverged``: the plant's state blew up (``diverged`` in the summary);
* ``tipped_over``: a physics plant recorded the robot tipping over;
* ``tipped_at_start``: the robot had already tipped over in the start pose (static
  S <= 1, ``start_tipped``; the command-line tools refuse such a run, the API warns);
* ``stability_below_1``: on a plant that does not judge tipping over itself (no
  ``tipped`` in the summary: the kinematic and thesis plants), the static stability margin
  fell to S <= 1 during the run (``min_stability``), where a real robot would have tipped
  over; a start already tipped is ``tipped_at_start`` alone;
* ``below_floor_at_start``: an ``mpc`` run (``mpc_fallbacks`` in the summary) started
  below its own stability floor (``start_stability`` < ``stability_min``): its plans
  broke their hard constraint from the first step, however well it tracked after;
* ``collided``: the base's footprint entered an obstacle (``min_obstacle_clearance_m`` < 0;
  ``qp`` and ``mpc`` with obstacles);
* ``singular_most_of_run``: more than :data:`MOST_OF_RUN` of the steps were damped at the
  shoulder singularity (``singular_steps``);
* ``saturated_most_of_run``: more than :data:`MOST_OF_RUN` of the steps had commands
  clipped at a rate limit (``saturated_steps``);
* ``final_error_above_limit`` / ``rms_error_above_limit``: the settled-end RMS or the RMS
  end-effector position error exceeds :func:`error_limit`: :data:`ERROR_LIMIT_M`, or
  :data:`OFFSET_FACTOR` times the run's initial offset if that is larger (an open-loop
  method keeps its initial offset by design, and tracks with it), and never more than
  :data:`EXTENT_FRACTION` of the trajectory's extent (``trajectory_extent_m``), or
  :data:`EXTENT_LIMIT_FLOOR_M` if that is larger (a trajectory that barely moves). The two
  absolute limits are the default robot's: they are multiplied by the robot's length unit
  (``length_unit_m``, :func:`ddwmmr.resolution.kernels.length_unit`; 1 m for the default
  robot, and for a summary that does not record it), so that a robot scaled by s, on a
  trajectory scaled by s, with s times the errors and offset, gets the default run's
  verdict.

The likely cause is read from the summary too (:func:`likely_cause`): the cause a user
should fix first. After what stops or overrules a run (divergence, tipping, a collision, a
start below the floor, solver fallbacks), commands clipped on more than
:data:`SATURATED_CAUSE` of the steps (``saturated_steps``), with as many steps at a rate
limit, name the trajectory as asking more than the robot can give, before anything the arm
did (a singularity, a fold), which follows from it. So does a wheel at its force or
torque limit for more than :data:`FORCE_LIMIT_CAUSE` of the run (the wheels' time at their
limit of ``duration``: ``wheel_saturated_time_s`` on MuJoCo, whose
``actuator_saturated_time_s`` counts the arm's motors too; ``actuator_saturated_time_s``
elsewhere): the base lags commands it cannot produce the force for and the arm stretches
after it; the cause names the limit held and then what the arm did. An
obstacle-avoiding controller (``qp``, ``mpc``: a ``min_obstacle_clearance_m``) whose base
came within :data:`OBSTACLE_NEAR_M` of an obstacle, with no other cause in sight, is named
as having left the trajectory to go round it. A run that would have tipped over
(``stability_below_1``) names that first, as a physics plant's tipping is. Saturation for
most of the run with more steps at a joint's position limit (``joint_limit_steps``) than
at a rate limit names that joint limit instead. A limit counts as held, whatever its kind,
for more than :data:`HELD_CAUSE` of the run and more than :data:`HELD_MIN_STEPS` steps (a
start from rest holds one for a few steps, which are more than HELD_CAUSE of a short run).
A run that held a rate limit (a wheel at its speed limit: ``wheel_limit_steps``; a joint
at its rate limit: ``joint_rate_limit_steps``; an actuator at its limit on a plant with
dynamics: ``actuator_saturated_time_s``; a force-level ``mpc`` at the wheel force it plans
with: ``mpc_wheel_force_bound_time_s``, beyond the wheels' time at the plant's limit), with
no other cause in sight, names that limit, and says whether the plant's clipping
(``saturated_steps``) counted it. A run that failed
on its RMS error alone (its settled-end RMS error within the limit) converged: if the error rose
above its start offset (``max_position_error_m``) while a limit was held, the transient (at the
corners, where the trajectory has them) is named with the limits held; if it never rose
above its start offset, the time it took to remove the offset is named, as on a short run
or a held point (whose limit is :data:`EXTENT_LIMIT_FLOOR_M`). A joint held at a position
limit (``joint_limit_steps``) in a run that did not converge names that joint limit.

A run on a physics plant that saw an edge of its support polygon unloaded without tipping
over (``support_lost``: a wheel off the ground, or the base rocking onto an edge; docs/
physics.md, "Tip-over from the contact forces") is not a failure, as the scenario protocol
does not fail a run on it either: its verdict, ``tracked`` or not, ends with a warning
clause (:func:`support_warning`) saying for how long (``unloaded_time_s``) and, where the
controller predicted its edge loads (``min_predicted_edge_load_n``), whether it predicted
one below its own floor (``min_edge_load_floor_n``). A run that tipped over says so in its
reasons instead.

A run that started below its own stability floor (``start_stability`` < ``stability_min``)
is not a failure either where its controller may (a ``qp``: its recovery from below the
floor is its documented behaviour, docs/qp.md, "Limitations"): where neither a reason
(``below_floor_at_start``, an ``mpc`` run) nor the likely cause names the floor, its
verdict ends with a warning clause (:func:`floor_warning`) giving S at the start and the
floor, after the support warning where both apply.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from numbers import Real
from typing import Any

import numpy as np

from ddwmmr.controllers.option_specs import option_names
from ddwmmr.errors import LENGTH_RANGE_M, ParameterError, one_line, shown, texts_apart
from ddwmmr.qp.limits.obstacles import INFLUENCE_M
from ddwmmr.resolution.kernels import length_unit

__all__ = [
    "ERROR_LIMIT_M",
    "EXTENT_FRACTION",
    "EXTENT_LIMIT_FLOOR_M",
    "FLAG_KEYS",
    "FORCE_LIMIT_CAUSE",
    "HELD_CAUSE",
    "HELD_MIN_STEPS",
    "LENGTH_UNIT_RANGE_M",
    "MOST_OF_RUN",
    "NON_NEGATIVE_KEYS",
    "NUMBER_KEYS",
    "OBSTACLE_NEAR_M",
    "OFFSET_FACTOR",
    "REASONS",
    "STEP_COUNT_KEYS",
    "TRACKED",
    "check_summary",
    "error_limit",
    "explain",
    "floor_warning",
    "lost_support",
    "short_verdict",
    "support_warning",
    "verdict",
]

#: The verdict of a run that tracked.
TRACKED = "tracked"
#: Share of the steps above which singular (damped) or saturated steps mean the run did
#: not track: "most of the run".
MOST_OF_RUN = 0.5
#: Share of the steps above which commands clipped at a rate limit are named as the likely
#: cause before anything the arm did (a singularity, a fold): commands clipped on almost
#: every step mean the trajectory asks more than the robot can give, the first thing to
#: fix; below it, the arm's own cause is the more specific one.
SATURATED_CAUSE = 0.9
#: Share of singular steps above which the singularity is named as the likely cause of a
#: failure, even when they are not most of the run (ap on the rectangle: 990 of 2000).
SINGULAR_CAUSE = 0.25
#: Share of the run (``actuator_saturated_time_s`` of ``duration``) above which an actuator
#: held at its force or torque limit is named as the likely cause before anything the arm
#: did (a singularity, a fold): a base that cannot produce the force its commands need for
#: most of the run lags them, and the arm stretches after it; no method tracks until the
#: motors can drive the robot at the trajectory's pace.
FORCE_LIMIT_CAUSE = 0.5
#: End-effector position error (m) above which a run of the default robot did not track
#: (settled-end RMS or RMS); another robot's is this many of its length units (``length_unit_m``)...
ERROR_LIMIT_M = 0.05
#: ... unless the initial offset times this is larger: the limit an open-loop method,
#: which keeps the initial offset (docs/comparing.md), stays within while it tracks.
OFFSET_FACTOR = 2.0
#: Share of the trajectory's extent (``trajectory_extent_m``) above which an error does
#: not track, whatever the limits above allow: an end effector a fifth of the path's size
#: away no longer follows its shape. The default runs that track stay within 0.152 of it.
EXTENT_FRACTION = 0.2
#: ... unless this (m, of the default robot; another robot's is this many of its length
#: units) is larger: the least limit, so that a trajectory that barely moves (a held point
#: has extent 0) is judged by 10 mm on the default robot, not by zero.
EXTENT_LIMIT_FLOOR_M = 0.01
#: The values a summary's ``length_unit_m`` may take (m): the length units of the robots'
#: first links over ``LENGTH_RANGE_M``.
LENGTH_UNIT_RANGE_M = tuple(length_unit(length) for length in LENGTH_RANGE_M)
#: Share of the run above which a limit held without clipping (``wheel_limit_steps`` of
#: ``steps``, ``actuator_saturated_time_s`` of ``duration``) is named as the likely cause
#: of a failure nothing else explains.
HELD_CAUSE = 0.005
#: ... and for more steps than this, whatever the limit (steps of ``dt`` for a time such as
#: ``actuator_saturated_time_s``): a limit touched for a few steps explains no error of a
#: whole run, yet is more than HELD_CAUSE of a run shorter than 800 steps; the default
#: robot's MuJoCo runs hold a motor at its torque limit for 3 or 4 steps as they start from
#: rest (docs/cli.md, "Verdict").
HELD_MIN_STEPS = 5
#: Relative slack on "the error never rose above its start" (``max_position_error_m`` <=
#: ``initial_offset_m`` x (1 + this)): the two are computed apart and may differ in their
#: last digits.
START_SLACK = 0.01
#: Footprint clearance (m) below which an obstacle is near enough to have bent the run's
#: path: the distance within which the qp's obstacle rows and steering act by default
#: (:data:`ddwmmr.qp.limits.obstacles.INFLUENCE_M`, defined there).
OBSTACLE_NEAR_M = INFLUENCE_M

#: What the verdict calls ``final_position_error_m``, the RMS over the run's settled end:
#: the long label of :data:`ddwmmr.reports.metrics.METRICS` (``track``'s table), written
#: out here because the simulation sits below the reports (a test holds the two equal).
SETTLED_END_ERROR = "settled-end RMS position error"

#: Reason code -> what it says in the verdict.
REASONS = {
    "diverged": "the plant diverged",
    "tipped_over": "the robot tipped over (physics)",
    "tipped_at_start": "the robot tips over in its start pose (S = {start_stability:.3g})",
    "stability_below_1": "the robot would have tipped over (min S = {min_stability:.3g})",
    "below_floor_at_start": (
        "the mpc started below its stability floor (start S = {start_text} < stability_min "
        "{floor_text}), breaking its constraint from the first step"
    ),
    "collided": "the base entered an obstacle (footprint clearance {clearance_mm:.3g} mm)",
    "singular_most_of_run": "singular (damped) {singular_steps} of {steps} steps",
    "saturated_most_of_run": "saturated {saturated_steps} of {steps} steps",
    "final_error_above_limit": SETTLED_END_ERROR + " {final_mm:.4g} mm ({limit})",
    "rms_error_above_limit": "RMS error {rms_mm:.4g} mm ({limit})",
}

SLIDES_ROW = (
    "the auxiliary row th1dot + th2dot = 0 (aux sum, the slides' setting) stops the base "
    "turning where the desired orientation is constant and drags the shoulder into "
    "cos th1 = 0; aux shoulder (the default) avoids it "
    """(see docs/comparing.md, "The slides' settings and ours")"""
)
SINGULAR_DRIFT = (
    "the resolution drives the shoulder into its singularity cos th1 = 0 (pi and ap do on "
    """these trajectories; see docs/comparing.md, "Does the slides' ranking hold?")"""
)
FOLDED_ARM = (
    "the arm folded to a joint limit (min manipulability 0): a resolution that only "
    "integrates Xd_dot ({methods}) loses the orientation steps at corners "
    """(see docs/comparing.md, "Does the slides' ranking hold?")"""
)
#: :data:`FOLDED_ARM` on a trajectory without corners (``corner_position_error_m`` None):
#: what each step misses of the trajectory's turning is lost instead.
FOLDED_ARM_NO_CORNERS = (
    "the arm folded to a joint limit (min manipulability 0): a resolution that only "
    "integrates Xd_dot ({methods}) loses what each step misses of the trajectory's turning "
    "(this one has no corners): a smaller dt (this run's: {dt}) or a slower trajectory "
    """(see docs/comparing.md, "Step size and integrator: Euler drifts, RK4 does not")"""
)
#: The methods whose commands only integrate Xd_dot (open loop, or ``clrrmc-cs``'s
#: configuration reference): :data:`FOLDED_ARM`'s explanation is theirs.
XD_DOT_INTEGRATORS = ("pi", "ats", "ap", "clrrmc-cs")
#: The methods :data:`FOLDED_ARM` names in a run of either (the docs' explanation is of
#: both) or in a summary that names no method.
FOLDING_METHODS = ("ats", "clrrmc-cs")
FOLDED_ARM_OTHER = (
    "the arm folded to a joint limit (min manipulability 0) in this {method} run: the plant "
    "stopped the elbow there and the end effector left the path; a smaller dt or a slower "
    'trajectory (see docs/comparing.md, "Studies")'
)
SATURATION = (
    "the commands asked for more than the wheel and joint rate limits allow: a larger "
    'tau, a slower trajectory or a smaller dt (see docs/comparing.md, "Studies")'
)
SATURATED_THROUGHOUT = (
    "the trajectory asks more than the wheel and joint rate limits allow on almost every "
    "step (what the arm did follows from that): a slower or smaller trajectory (a sampled "
    "one is read in m and rad: positions in mm or angles in degrees ask 1000 or 57.3 times "
    "too much; see "
    'docs/tutorial_custom_trajectory.md, "Before you start: what the robot can follow")'
)
START_TRANSIENT = (
    f"the error converged ({SETTLED_END_ERROR} {{final_mm:.3g}} mm, within the limit) but "
    "never rose above the start offset ({offset_mm:.3g} mm), whose removal took a large "
    "part of this "
    "{duration}run and counts in its RMS: a longer run or a smaller start offset "
    """(track's --duration and --offset; see docs/cli.md, "Verdict")"""
)
#: The methods :data:`NO_CONVERGENCE_CHECKS` names as open-loop.
OPEN_LOOP_METHODS = ("pi", "ats", "ap")
#: :data:`NO_CONVERGENCE` with what to check of the run's own settings in ``{checks}``.
NO_CONVERGENCE_CHECKS = (
    f"the error did not converge: an open-loop method ({', '.join(OPEN_LOOP_METHODS)}) "
    "never removes it; for a closed-loop one check {checks} "
    '(see docs/comparing.md, "Studies")'
)
NO_CONVERGENCE = NO_CONVERGENCE_CHECKS.format(checks="tau, dt and the integrator")
#: What :data:`NO_CONVERGENCE_CHECKS` asks to check in place of ``tau`` for a method without
#: one (its tracking gains' options); ``tau`` for every other method.
GAINS_OF = {"mpc": "position_weight, horizon"}
OBSTACLE_DETOUR = (
    "the base went round an obstacle on or near the path (closest footprint clearance "
    "{clearance_mm:.3g} mm, under the {near_mm:.0f} mm within which the qp steers round "
    "obstacles) and left the trajectory to keep clear of it: a trajectory clear of the "
    'obstacles tracks (see docs/qp.md, "Obstacle on the path")'
)
DIVERGED = (
    'the step is too large for the plant or a command was unbounded (see docs/api.md, "Simulation")'
)
BELOW_FLOOR = (
    "the run starts below its stability floor (start S = {start_stability} < "
    "stability_min {stability_min}): tracking yields until S has risen above it, and "
    "a floor the arm cannot reach holds it back throughout; lower stability_min or start "
    'above it (see docs/qp.md, "Limitations")'
)
COLLIDED = (
    "the controller's obstacle constraint gave way (the mpc's is soft, and a start within "
    "its keep-out, the base's enclosing circle plus its margin, begins violated): start "
    'farther from the obstacles (see docs/mpc.md, "Options")'
)
MPC_FALLBACK = (
    "the mpc's solver failed on {mpc_fallbacks} of {steps} steps and its qp fallback "
    "commanded them: the mpc's options (solver, qp_solver, grid) or limits the start "
    'cannot meet (see docs/mpc.md, "Options")'
)
QP_FALLBACK = (
    "the qp found no solution on {qp_fallbacks} of {steps} steps and held its fallback "
    "command: its limits conflict (a limit of your own, or a stability floor the start "
    'cannot meet; see docs/qp.md, "Failure handling")'
)
CONTROLLER_FALLBACK = (
    "{method} used its safe fallback on {fallback_steps} of {steps} steps (it said so "
    "through StepInfo.fallback): why it could not compute a command there is its own "
    'report (see docs/api.md, "Extending")'
)
HELD_LIMIT = (
    "the robot ran at a limit ({held}), where it cannot follow the trajectory any faster "
    "({clipping}){transient}: a slower trajectory, a smaller dt or a higher limit "
    '(see docs/cli.md, "Verdict")'
)
#: :data:`HELD_LIMIT`'s words on a run held at its force limit (:data:`FORCE_LIMIT_CAUSE`)
#: whose arm would otherwise have been named (:func:`_arm_cause`): what it did, in
#: ``{arm}``, may follow from the force limit or be the method's own.
ARM_AFTER_FORCE_LIMIT = (
    "; the arm {arm}, which may follow from it (the base lagged and the arm stretched after "
    "it), so fix this first"
)
#: :data:`ARM_AFTER_FORCE_LIMIT` for a run that converged after a transient
#: (:data:`HELD_TRANSIENT` before it): the arm's part is told after the transient, with no
#: "fix this first" after "converged".
ARM_AFTER_FORCE_LIMIT_TRANSIENT = (
    "; the arm {arm} on the way, which may follow from the force limit too (the base "
    "lagged and the arm stretched after it)"
)
#: :data:`HELD_LIMIT`'s words on ``saturated_steps``: none
#: clipped (the controller's own bounds or the plant's dynamics held the limit) ...
NOT_CLIPPED = "the commands' clipping, saturated_steps, does not count it"
#: ... or the plant clipped the commands on some steps (at a rate limit, or a joint stopped
#: at a position limit).
CLIPPED = "the plant clipped the commands on {saturated_steps} of {steps} steps, saturated_steps"
#: :data:`HELD_LIMIT`'s words on a run that converged after the transient at the limit.
HELD_TRANSIENT = (
    f"; the error converged after it ({SETTLED_END_ERROR} {{final_mm:.3g}} mm, within the "
    "limit), but the transient, up to {peak_mm:.3g} mm {where}, counts in the RMS"
)
JOINT_LIMIT = (
    "the arm held at a joint limit ({joint}) on {joint_steps} of {steps} steps, where the "
    "plant stops the joint and the end effector cannot reach the poses the trajectory asks "
    "for ({clipping}): a trajectory the arm reaches within its joint_limits, or wider "
    'joint_limits (see docs/cli.md, "Verdict")'
)
#: How :data:`HELD_LIMIT` names a force-level ``mpc`` held at the wheel force it plans with
#: (``mpc_wheel_force_bound_time_s``; its own bound, below the plant's motors).
PLANNED_FORCE_HELD = (
    "a wheel at the force the mpc plans with (mpc_wheel_force_limit_n {force:.6g} N, its own "
    "bound below the motors; --option wheel_force_limit=N raises it, never above the "
    "motors' wheel_torque_limit / wheel_radius) for {held_s:.3g} of {duration:.3g} s"
)
#: How :data:`HELD_LIMIT` names ``actuator_saturated_time_s``, by the summary's ``plant``.
ACTUATOR_LIMITS = {"thesis": "a wheel at its force limit", "mujoco": "a motor at its torque limit"}
TIPPED = (
    "the payload or the accelerations put the centre of pressure outside the support "
    "polygon (the wheels and casters): a lighter payload, another start pose or a "
    "stability floor (stability_min; see "
    'docs/physics.md, "Tip-over from the contact forces")'
)
#: The cause of a physics plant's tip-over by the tilt alone: no edge of the support
#: polygon ever went unloaded (``unloaded_time_s`` 0) and the centre of pressure stayed
#: inside it (``min_physics_stability`` > 1), so only the tip rule's angle can have fired.
TIPPED_TILT = (
    "the base tilted past the tip rule's angle (max_base_tilt_rad {tilt:.3g}) with every "
    "edge of the support polygon loaded (unloaded_time_s 0, min_physics_stability "
    "{stability:.3g} > 1): it sank into soft contacts, not the payload: stiffer tyres or "
    "contacts (tyre_stiffness, contact_time_constant; see "
    'docs/physics.md, "Settings")'
)

#: The warning clause of a run on a physics plant that unloaded an edge of its support
#: polygon without tipping over (:func:`support_warning`).
SUPPORT_LOST = (
    "warning: an edge of the support polygon was unloaded for {unloaded_s:.3g} of "
    "{duration_s:.3g} s (support_lost: a wheel off the ground or the base rocking onto an "
    "edge; it did not tip over){predicted}: a higher floor (qp's and mpc's stability_min "
    "and min_edge_load) or a slower trajectory keeps the load on it "
    '(see docs/physics.md, "Tip-over from the contact forces")'
)
#: :data:`SUPPORT_LOST`'s words on a controller that predicted an edge load below its floor.
PREDICTED_BELOW_FLOOR = (
    "; the controller predicted an edge load of {least} N, below its {floor} N floor "
    "(min_predicted_edge_load_n, min_edge_load_floor_n)"
)
#: Force (N) by which a predicted edge load must fall below its floor for
#: :data:`PREDICTED_BELOW_FLOOR`: a solver meets the floor to within its tolerance, and a
#: load a few 1e-14 N under it held it.
PREDICTED_SLACK_N = 1e-3
#: The warning clause of a run that started below its own stability floor and tracked
#: anyway, or failed for a cause that does not name the floor (:func:`floor_warning`):
#: the protocol does not fail such a run (a ``qp``'s recovery from below its floor is its
#: documented behaviour), but the floor it was given did not hold from the start.
STARTED_BELOW_FLOOR = (
    "warning: the run started below its stability floor (start S = {start} < "
    "stability_min {floor}; start_stability, stability_min), so the floor did not hold "
    "from the start: start above it or lower stability_min "
    '(see docs/qp.md, "Limitations")'
)

WOULD_TIP = (
    "the arm's reach and the payload put the centre of mass outside the support polygon "
    "(the wheels and casters; static S <= 1), where a real robot tips over; this plant "
    "does not simulate tipping and ran on: a lighter payload, a trajectory nearer the "
    "base or a stability floor (qp's or "
    'mpc\'s stability_min; see docs/cli.md, "Verdict")'
)


def check_summary(summary: Any) -> Mapping[str, Any]:
    """``summary`` if it is a mapping (a run's summary: :attr:`SimulationResult.summary`,
    or a dict read from a ``summary.json``) whose keys read as numbers
    (:data:`NUMBER_KEYS`) hold numbers, ``steps`` and the counts of steps
    (:data:`STEP_COUNT_KEYS`) whole numbers from 0 (to ``steps``), the errors, lengths and
    times (:data:`NON_NEGATIVE_KEYS`) numbers >= 0 or NaN or inf, and the flags
    (:data:`FLAG_KEYS`) booleans; each may be missing or None. Anything else is a one-line
    :class:`ParameterError` naming ``summary`` or the key and what it allows. Every
    function here taking a summary checks it first."""
    if not isinstance(summary, Mapping):
        raise ParameterError(
            "summary must be a mapping of a run's summary keys (a dict such as "
            f"SimulationResult.summary) (got {shown(summary, 60)})"
        )
    for key in NUMBER_KEYS:
        _number(summary, key)
    for key in FLAG_KEYS:
        _flag(summary, key)
    steps = _count(summary, "steps", None)
    for key in STEP_COUNT_KEYS:
        _count(summary, key, steps)
    for key, unit in NON_NEGATIVE_KEYS.items():
        _non_negative(summary, key, unit)
    _robot_unit(summary)
    return summary


#: The summary keys the verdict reads as numbers: each must be a number, missing or None,
#: or the string a ``summary.json`` writes for a non-finite one (``"nan"``, ``"inf"``,
#: ``"-inf"``).
NUMBER_KEYS = (
    "steps",
    "singular_steps",
    "saturated_steps",
    "wheel_limit_steps",
    "joint_rate_limit_steps",
    "joint_limit_steps",
    "min_stability",
    "actuator_saturated_time_s",
    "wheel_saturated_time_s",
    "mpc_wheel_force_bound_time_s",
    "mpc_wheel_force_limit_n",
    "duration",
    "trajectory_extent_m",
    "initial_offset_m",
    "max_position_error_m",
    "final_position_error_m",
    "rms_position_error_m",
    "min_manipulability",
    "start_stability",
    "stability_min",
    "qp_fallbacks",
    "mpc_fallbacks",
    "fallback_steps",
    "min_obstacle_clearance_m",
    "unloaded_time_s",
    "min_predicted_edge_load_n",
    "min_edge_load_floor_n",
    "dt",
    "corner_position_error_m",
    "min_physics_stability",
    "max_base_tilt_rad",
    "length_unit_m",
)
#: The summary keys that count steps of the run: each a whole number from 0 to ``steps``
#: (itself a whole number >= 0).
STEP_COUNT_KEYS = (
    "singular_steps",
    "saturated_steps",
    "wheel_limit_steps",
    "joint_rate_limit_steps",
    "joint_limit_steps",
    "qp_fallbacks",
    "mpc_fallbacks",
    "fallback_steps",
)
#: The errors, lengths and times the verdict reads, with their units: each >= 0, or NaN
#: or inf (the errors of a run that blew up).
NON_NEGATIVE_KEYS = {
    "duration": "s",
    "actuator_saturated_time_s": "s",
    "wheel_saturated_time_s": "s",
    "mpc_wheel_force_bound_time_s": "s",
    "unloaded_time_s": "s",
    "trajectory_extent_m": "m",
    "initial_offset_m": "m",
    "max_position_error_m": "m",
    "final_position_error_m": "m",
    "rms_position_error_m": "m",
}
#: The plant's yes-or-no keys the verdict reads: each True or False (Python's or numpy's,
#: as a ``summary.json`` holds them too), missing or None. ``diverged`` is not one: it
#: holds the plant's message.
FLAG_KEYS = ("tipped", "start_tipped", "support_lost")
#: How a ``summary.json`` spells the non-finite floats (:func:`ddwmmr.sim.result.json_safe`):
#: a summary read back from one holds these strings where the run held the numbers.
_NON_FINITE = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}


def _number(summary: Mapping[str, Any], key: str) -> float | None:
    """``summary[key]`` as a float, or None if it is missing or None. A number (Python's
    or numpy's, not a boolean) or the spelling a ``summary.json`` gives a non-finite one
    (``"nan"``, ``"inf"``, ``"-inf"``); anything else (text, a boolean, a list) is a
    one-line :class:`ParameterError` naming the key."""
    value = summary.get(key)
    if value is None:
        return None
    if isinstance(value, str) and value in _NON_FINITE:
        return _NON_FINITE[value]
    if isinstance(value, Real) and not isinstance(value, bool | np.bool_):
        try:
            return float(value)
        except OverflowError:  # an integer beyond a float
            pass
    raise ParameterError(
        f"summary: {key} must be a number, 'nan', 'inf', '-inf' or None (got {shown(value)})"
    )


def _flag(summary: Mapping[str, Any], key: str) -> None:
    """A one-line :class:`ParameterError` naming ``key`` unless ``summary[key]`` is a
    boolean (Python's or numpy's), the integer 0 or 1, None or missing: text such as
    ``"no"`` would read as true."""
    value = summary.get(key)
    if value is None or isinstance(value, bool | np.bool_):
        return
    if not (isinstance(value, int | np.integer) and value in (0, 1)):
        raise ParameterError(
            f"summary: {key} must be True, False (or 1, 0) or None (got {shown(value)})"
        )


def _count(summary: Mapping[str, Any], key: str, steps: float | None) -> float | None:
    """``summary[key]`` (already a number, :func:`_number`) if it is a whole number from 0
    to ``steps`` (from 0 up, where ``steps`` is None), or None if missing; anything else
    is a one-line :class:`ParameterError` naming ``key`` and that range."""
    value = _number(summary, key)
    if value is None:
        return None
    most = math.inf if steps is None else steps
    upper = "" if steps is None else f" to steps = {steps:.0f}"
    if not (math.isfinite(value) and value.is_integer() and 0 <= value <= most):
        raise ParameterError(
            f"summary: {key} must be a whole number of steps from 0{upper} "
            f"(got {shown(summary.get(key))})"
        )
    return value


def _non_negative(summary: Mapping[str, Any], key: str, unit: str) -> None:
    """A one-line :class:`ParameterError` naming ``key`` where ``summary[key]`` is below 0
    (NaN and inf pass: a run that blew up has them)."""
    value = _number(summary, key)
    if value is not None and value < 0.0:
        raise ParameterError(
            f"summary: {key} must be >= 0 {unit}, 'nan', 'inf' or None "
            f"(got {shown(summary.get(key))})"
        )


def _robot_unit(summary: Mapping[str, Any]) -> float:
    """The robot's length unit (m) the summary records (``length_unit_m``), 1.0 where it
    records none (a summary written before the key was: judged in metres, as then). A
    value outside :data:`LENGTH_UNIT_RANGE_M` (or NaN, inf) is a one-line
    :class:`ParameterError` naming the key."""
    unit = _number(summary, "length_unit_m")
    if unit is None:
        return 1.0
    low, high = LENGTH_UNIT_RANGE_M
    if not low <= unit <= high:
        raise ParameterError(
            f"summary: length_unit_m must be the robot's length unit in m, from {low:.4g} "
            f"to {high:.4g} (kernels.length_unit(L1)), or None "
            f"(got {shown(summary.get('length_unit_m'))})"
        )
    return unit


def error_limit(summary: Mapping[str, Any]) -> float:
    """The position-error limit (m) of the run ``summary`` describes:
    max(:data:`ERROR_LIMIT_M` x unit, :data:`OFFSET_FACTOR` x ``initial_offset_m``), and
    at most :func:`extent_limit` where the summary records the trajectory's extent; unit is
    the robot's length unit ``length_unit_m`` (1 where the summary records none)."""
    absolute, relative = _limits(summary)
    return absolute if relative is None else min(absolute, relative)


def _limits(summary: Mapping[str, Any]) -> tuple[float, float | None]:
    """The two parts of :func:`error_limit` (m): the absolute one, max(ERROR_LIMIT_M x
    unit, OFFSET_FACTOR x offset), and :func:`extent_limit` (None without an extent)."""
    check_summary(summary)
    offset = _number(summary, "initial_offset_m") or 0.0
    absolute = max(ERROR_LIMIT_M * _robot_unit(summary), OFFSET_FACTOR * offset)
    return absolute, extent_limit(summary)


def extent_limit(summary: Mapping[str, Any]) -> float | None:
    """The error limit (m) the trajectory's size sets: max(:data:`EXTENT_FRACTION` x
    ``trajectory_extent_m``, :data:`EXTENT_LIMIT_FLOOR_M` x unit), unit the robot's length
    unit ``length_unit_m`` (1 where the summary records none); None if the summary records
    no (or a NaN) extent, as a summary written before the key was."""
    check_summary(summary)
    extent = _number(summary, "trajectory_extent_m")
    if extent is None or math.isnan(extent):
        return None
    return max(EXTENT_FRACTION * extent, EXTENT_LIMIT_FLOOR_M * _robot_unit(summary))


def _limit_text(summary: Mapping[str, Any]) -> str:
    """``limit 84.85 mm``; where the trajectory's extent sets it, also that extent
    (``for a trajectory 2.828 mm across``); where a robot of another size than the default
    one's (``length_unit_m`` not 1) is held to :data:`ERROR_LIMIT_M` or
    :data:`EXTENT_LIMIT_FLOOR_M` of its length unit, also that unit."""
    absolute, relative = _limits(summary)
    limit = absolute if relative is None else min(absolute, relative)
    what = []
    if relative is not None and relative < absolute:
        extent = _number(summary, "trajectory_extent_m") or 0.0
        what.append(f"a trajectory {1000.0 * extent:.4g} mm across")
    unit = _robot_unit(summary)
    if unit != 1.0 and limit in (ERROR_LIMIT_M * unit, EXTENT_LIMIT_FLOOR_M * unit):
        what.append(f"this robot's size (length_unit_m {unit:.4g})")
    text = f"limit {1000.0 * limit:.4g} mm"
    return f"{text} for {' and '.join(what)}" if what else text


def _started_below_floor(summary: Mapping[str, Any]) -> bool:
    """The run started below its own stability floor (``start_stability`` <
    ``stability_min``; False where either is missing)."""
    start, floor = _number(summary, "start_stability"), _number(summary, "stability_min")
    return start is not None and floor is not None and start < floor


def reasons(summary: Mapping[str, Any]) -> list[str]:
    """The codes (keys of :data:`REASONS`) of what went wrong in the run, in that order."""
    check_summary(summary)
    found = []
    if summary.get("diverged"):
        found.append("diverged")
    if summary.get("tipped"):
        found.append("tipped_over")
    if summary.get("start_tipped"):
        found.append("tipped_at_start")
    elif _would_have_tipped(summary):
        found.append("stability_below_1")
    if _number(summary, "mpc_fallbacks") is not None and _started_below_floor(summary):
        found.append("below_floor_at_start")
    clearance = _number(summary, "min_obstacle_clearance_m")  # None: no obstacles
    if clearance is not None and clearance < 0.0:
        found.append("collided")
    steps = _number(summary, "steps") or 0
    if steps and (_number(summary, "singular_steps") or 0) > MOST_OF_RUN * steps:
        found.append("singular_most_of_run")
    if steps and (_number(summary, "saturated_steps") or 0) > MOST_OF_RUN * steps:
        found.append("saturated_most_of_run")
    limit = error_limit(summary)
    if _above(_number(summary, "final_position_error_m"), limit):
        found.append("final_error_above_limit")
    if _above(_number(summary, "rms_position_error_m"), limit):
        found.append("rms_error_above_limit")
    return found


def _would_have_tipped(summary: Mapping[str, Any]) -> bool:
    """The static stability margin fell to S <= 1 (``min_stability``) on a plant that does
    not judge tipping over itself (no ``tipped`` key: a physics plant's own flag rules)."""
    if "tipped" in summary:
        return False
    least = _number(summary, "min_stability")
    return least is not None and least <= 1.0


def _above(value: float | None, limit: float) -> bool:
    """``value`` exceeds ``limit``; NaN (a run that blew up) counts as above."""
    if value is None:
        return False
    return not value <= limit


def likely_cause(summary: Mapping[str, Any], found: list[str]) -> str:
    """The most likely cause of the failures ``found`` (reason codes), from the summary."""
    check_summary(summary)
    if "diverged" in found:
        return DIVERGED
    if "tipped_over" in found or "tipped_at_start" in found:
        return _tipped(summary)
    if "stability_below_1" in found:
        return WOULD_TIP
    if "collided" in found:
        return COLLIDED
    if _started_below_floor(summary):
        start_text, floor_text = _floor_texts(summary)
        return BELOW_FLOOR.format(start_stability=start_text, stability_min=floor_text)
    steps = _number(summary, "steps") or 0
    fallbacks = _number(summary, "qp_fallbacks") or 0
    if steps and fallbacks > MOST_OF_RUN * steps:
        return QP_FALLBACK.format(qp_fallbacks=int(fallbacks), steps=int(steps))
    fallbacks = _number(summary, "mpc_fallbacks") or 0
    if steps and fallbacks > MOST_OF_RUN * steps:
        return MPC_FALLBACK.format(mpc_fallbacks=int(fallbacks), steps=int(steps))
    fallbacks = _number(summary, "fallback_steps") or 0
    # a controller of one's own: for the qp and the mpc fallback_steps are the counts above
    if steps and fallbacks > MOST_OF_RUN * steps:
        method = summary.get("method")
        return CONTROLLER_FALLBACK.format(
            method=f"the controller {method}" if isinstance(method, str) else "the controller",
            fallback_steps=int(fallbacks),
            steps=int(steps),
        )
    if steps and _clipped_throughout(summary, steps):
        return SATURATED_THROUGHOUT
    return _arm_or_path_cause(summary, found)


def _tipped(summary: Mapping[str, Any]) -> str:
    """:data:`TIPPED_TILT` for a tip-over with every edge loaded throughout and the centre
    of pressure inside the polygon (``unloaded_time_s`` 0, ``min_physics_stability`` > 1),
    else :data:`TIPPED`."""
    unloaded = _number(summary, "unloaded_time_s")
    stability = _number(summary, "min_physics_stability")
    tilt = _number(summary, "max_base_tilt_rad")
    if unloaded == 0.0 and stability is not None and stability > 1.0 and tilt is not None:
        return TIPPED_TILT.format(tilt=tilt, stability=stability)
    return TIPPED


def _arm_or_path_cause(summary: Mapping[str, Any], found: list[str]) -> str:
    """The rest of :func:`likely_cause`, after the causes that stop or overrule a run: an
    actuator at its force limit for most of the run, what the arm did, saturation, an
    obstacle, a limit held, the start offset, else no convergence."""
    arm = _arm_cause(summary)
    if _force_limited(summary):
        converged = _converged_after_a_transient(summary, found)
        template = ARM_AFTER_FORCE_LIMIT_TRANSIENT if converged else ARM_AFTER_FORCE_LIMIT
        words = template.format(arm=arm[1]) if arm else ""
        cause = _held_cause(summary, found, words)
        if cause is not None:
            return cause
    if arm:
        return arm[0]
    if "saturated_most_of_run" in found:
        return _joint(summary) if _mostly_at_joint_limits(summary) else SATURATION
    clearance = _number(summary, "min_obstacle_clearance_m")  # None: no obstacles
    if clearance is not None and clearance < OBSTACLE_NEAR_M:
        return OBSTACLE_DETOUR.format(
            clearance_mm=1000.0 * clearance, near_mm=1000.0 * OBSTACLE_NEAR_M
        )
    return _held_or_converging_cause(summary, found)


def _arm_cause(summary: Mapping[str, Any]) -> tuple[str, str] | None:
    """What the arm did, where it explains a failure: ``(cause, words)``, the cause
    (:data:`SLIDES_ROW` or :data:`SINGULAR_DRIFT` for singular steps above
    :data:`SINGULAR_CAUSE` of the run, else :func:`_folded_arm` for an arm folded to
    ``min_manipulability`` 0) and a few words on it for :data:`ARM_AFTER_FORCE_LIMIT`;
    None where neither holds."""
    steps = _number(summary, "steps") or 0
    singular = _number(summary, "singular_steps") or 0
    if steps and singular > SINGULAR_CAUSE * steps:
        cause = SLIDES_ROW if summary.get("aux") == "sum" else SINGULAR_DRIFT
        return cause, f"was singular (damped) on {int(singular)} of {int(steps)} steps"
    min_manipulability = _number(summary, "min_manipulability")
    if min_manipulability is not None and min_manipulability < 1e-6:
        return _folded_arm(summary), "folded to a joint limit (min manipulability 0)"
    return None


def _force_limited(summary: Mapping[str, Any]) -> bool:
    """A wheel was at its force or torque limit for more than :data:`FORCE_LIMIT_CAUSE` of
    the run (``duration``, s): ``wheel_saturated_time_s`` where the plant records it (the
    MuJoCo plant, whose ``actuator_saturated_time_s`` counts the arm's motors too), else
    ``actuator_saturated_time_s`` on any plant but MuJoCo (the thesis plant's counts its
    wheels only); a MuJoCo summary without the wheels' time never is."""
    duration = _number(summary, "duration") or 0.0
    at_limit = max(_wheel_limit_time(summary), _planned_force_time(summary))
    return duration > 0.0 and at_limit > FORCE_LIMIT_CAUSE * duration


def _wheel_limit_time(summary: Mapping[str, Any]) -> float:
    """Time (s) with a wheel at the plant's force or torque limit: ``wheel_saturated_time_s``
    where the plant records it, else ``actuator_saturated_time_s`` on any plant but MuJoCo
    (whose counts the arm's motors too); 0 where neither applies."""
    at_limit = _number(summary, "wheel_saturated_time_s")
    if at_limit is None and summary.get("plant") != "mujoco":
        at_limit = _number(summary, "actuator_saturated_time_s")
    return at_limit or 0.0


def _planned_force_time(summary: Mapping[str, Any]) -> float:
    """Time (s) a force-level ``mpc`` held a wheel at the force it plans with
    (``mpc_wheel_force_bound_time_s``) where that is its own bound: held longer than the
    wheels were at the plant's limit (:func:`_wheel_limit_time`) by a hold that counts
    (:func:`_counts_as_held`); 0 otherwise (the thesis plant's limit is the mpc's bound
    by default, and is named as the plant's)."""
    planned = _number(summary, "mpc_wheel_force_bound_time_s") or 0.0
    if _counts_as_held(summary, planned - _wheel_limit_time(summary), time=True):
        return planned
    return 0.0


def _counts_as_held(summary: Mapping[str, Any], amount: float, time: bool = False) -> bool:
    """A limit held for ``amount`` (steps; seconds where ``time``) counts, whatever its
    kind: more than :data:`HELD_CAUSE` of the run (``steps``; ``duration`` where ``time``)
    and more than :data:`HELD_MIN_STEPS` steps (of ``dt`` where ``time``, where the summary
    records it): a start from rest holds a motor or a wheel at its limit for a few steps,
    which on a short run are more than HELD_CAUSE of it."""
    whole = _number(summary, "duration" if time else "steps") or 0.0
    if not (whole > 0.0 and amount > HELD_CAUSE * whole):
        return False
    if not time:
        return amount > HELD_MIN_STEPS
    dt = _number(summary, "dt")
    return dt is None or not dt > 0.0 or amount / dt > HELD_MIN_STEPS * (1.0 + 1e-9)


def _held_or_converging_cause(summary: Mapping[str, Any], found: list[str]) -> str:
    """The rest of :func:`_arm_or_path_cause`: a transient at a limit of a run that
    converged, a rate limit held, the start offset, a joint limit held, else no
    convergence."""
    held = _held_cause(summary, found)
    if held is not None:
        return held
    if _only_the_start_offset(summary, found):
        return START_TRANSIENT.format(
            final_mm=1000.0 * (_number(summary, "final_position_error_m") or 0.0),
            offset_mm=1000.0 * (_number(summary, "initial_offset_m") or 0.0),
            duration=_duration_text(summary),
        )
    if _joint_limit_phrase(summary):
        return _joint(summary)
    return NO_CONVERGENCE_CHECKS.format(checks=_convergence_checks(summary))


def _convergence_checks(summary: Mapping[str, Any]) -> str:
    """What :data:`NO_CONVERGENCE_CHECKS` asks to check, of what the run had: ``tau``, or
    the gains of a method without it (:data:`GAINS_OF`), ``dt``, and ``the integrator``
    unless the summary records the plant's as None (a plant without one: thesis, MuJoCo)."""
    checks = [_gains_of(str(summary.get("method"))), "dt"]
    if not ("integrator" in summary and summary["integrator"] is None):
        checks.append("the integrator")
    return ", ".join(checks[:-1]) + " and " + checks[-1]


def _gains_of(method: str) -> str:
    """What sets how fast ``method`` removes an error: ``tau``, :data:`GAINS_OF`'s entry,
    or for a plug-in method without ``tau`` its own options (a method the registry does
    not know is taken to have ``tau``)."""
    if method in GAINS_OF:
        return GAINS_OF[method]
    try:
        names = option_names(method)
    except ParameterError:
        return "tau"
    if "tau" in names or method in OPEN_LOOP_METHODS or not names:
        return "tau"
    return f"its options ({', '.join(names)})"


def _held_cause(summary: Mapping[str, Any], found: list[str], after: str = "") -> str | None:
    """:data:`HELD_LIMIT` for a run that held a limit (:func:`held_limits`): with the
    transient (and the joint limit held, :func:`_joint_limit_phrase`) where the run
    converged after it, then ``after``; None where no limit was held (nor a joint limit
    held on a run that converged after a transient)."""
    held = held_limits(summary)
    joint = _joint_limit_phrase(summary)
    transient = held + ([joint] if joint else [])
    if transient and _converged_after_a_transient(summary, found):
        return _held_limit(summary, transient, _transient_text(summary) + after)
    if held:
        return _held_limit(summary, held, after)
    return None


def _clipped_throughout(summary: Mapping[str, Any], steps: float) -> bool:
    """The plant clipped the commands on more than :data:`SATURATED_CAUSE` of the ``steps``
    (``saturated_steps``), and as many steps were at a rate limit
    (:func:`_rate_limit_steps`), not a joint held at a position limit. A limit held inside
    a controller's own bounds (``wheel_limit_steps`` of a qp or mpc) clips nothing and
    does not count."""
    clipped = _number(summary, "saturated_steps") or 0
    threshold = SATURATED_CAUSE * steps
    return clipped > threshold and _rate_limit_steps(summary) > threshold


def _mostly_at_joint_limits(summary: Mapping[str, Any]) -> bool:
    """More steps had a joint at a position limit (``joint_limit_steps``) than at a rate
    limit (:func:`_rate_limit_steps`): the joint limit explains most of the clipping."""
    return (_number(summary, "joint_limit_steps") or 0) > _rate_limit_steps(summary)


def _rate_limit_steps(summary: Mapping[str, Any]) -> float:
    """The least number of steps the plant clipped at a rate limit: ``saturated_steps``
    less the steps with a joint at a position limit (``joint_limit_steps``, which may
    explain the rest), or the steps with a wheel or a joint at its rate limit
    (``wheel_limit_steps``, ``joint_rate_limit_steps``) if more, except in a run whose
    controller holds those limits inside its own bounds (:func:`_bounds_own_rates`),
    where a limit held clips nothing and the position limit is what the plant clipped."""
    clipped = _number(summary, "saturated_steps") or 0
    beyond_joint_limits = clipped - (_number(summary, "joint_limit_steps") or 0)
    if _bounds_own_rates(summary):
        return beyond_joint_limits
    return max(
        beyond_joint_limits,
        _number(summary, "wheel_limit_steps") or 0,
        _number(summary, "joint_rate_limit_steps") or 0,
    )


def _bounds_own_rates(summary: Mapping[str, Any]) -> bool:
    """A ``qp`` or ``mpc`` run (``qp_fallbacks`` or ``mpc_fallbacks`` in the summary):
    its controller keeps the wheel speeds and joint rates a hair inside their limits, so
    the plant clips no command at a rate limit."""
    return any(_number(summary, key) is not None for key in ("qp_fallbacks", "mpc_fallbacks"))


def _clipping(summary: Mapping[str, Any]) -> str:
    """What ``saturated_steps`` says of the limits held: :data:`NOT_CLIPPED` where the
    plant clipped no command, else :data:`CLIPPED` with its count."""
    clipped = _number(summary, "saturated_steps") or 0
    if not clipped > 0:
        return NOT_CLIPPED
    steps = _number(summary, "steps") or 0
    return CLIPPED.format(saturated_steps=int(clipped), steps=int(steps))


def _joint_limit_phrase(summary: Mapping[str, Any]) -> str | None:
    """``"the arm at a joint limit (th2 = 0.3 rad) on 207 of 750 steps"`` where a joint
    was held at a position limit (:func:`_counts_as_held`), else None."""
    steps = _number(summary, "steps") or 0
    at_limit = _number(summary, "joint_limit_steps") or 0
    if not _counts_as_held(summary, at_limit):
        return None
    where = _joint_name(summary)
    return f"the arm at a joint limit ({where}) on {int(at_limit)} of {int(steps)} steps"


def _joint_name(summary: Mapping[str, Any]) -> str:
    """The summary's ``joint_limit_held`` on one line, ``"a joint"`` where it has none."""
    held = summary.get("joint_limit_held")
    return "a joint" if held is None else one_line(str(held), 40)


def _joint(summary: Mapping[str, Any]) -> str:
    """:data:`JOINT_LIMIT` for the summary's joint limit held."""
    return JOINT_LIMIT.format(
        joint=_joint_name(summary),
        joint_steps=int(_number(summary, "joint_limit_steps") or 0),
        steps=int(_number(summary, "steps") or 0),
        clipping=_clipping(summary),
    )


def _converged_after_a_transient(summary: Mapping[str, Any], found: list[str]) -> bool:
    """Only the RMS error failed, and the error rose above its start offset on the way
    (``max_position_error_m`` beyond :data:`START_SLACK` of ``initial_offset_m``): the
    run converged, and its RMS counts a transient on the way."""
    if found != ["rms_error_above_limit"]:
        return False
    largest = _number(summary, "max_position_error_m")
    offset = _number(summary, "initial_offset_m") or 0.0
    return largest is not None and largest > offset * (1.0 + START_SLACK)


def _held_limit(summary: Mapping[str, Any], held: list[str], transient: str) -> str:
    """:data:`HELD_LIMIT` naming the limits ``held``, with the words on
    ``saturated_steps`` true of this run and ``transient`` (``""`` or
    :func:`_transient_text`) after them."""
    return HELD_LIMIT.format(
        held=" and ".join(held), clipping=_clipping(summary), transient=transient
    )


def _transient_text(summary: Mapping[str, Any]) -> str:
    """:data:`HELD_TRANSIENT` for the summary: the final error, and the largest one with
    where it was: at a corner where the summary's corner error is it, else during the
    run."""
    corner = _number(summary, "corner_position_error_m")
    peak = _number(summary, "max_position_error_m") or 0.0
    where = "during the run"
    if corner is not None and corner >= peak * (1.0 - START_SLACK):
        where = "at a corner"
    return HELD_TRANSIENT.format(
        final_mm=1000.0 * (_number(summary, "final_position_error_m") or 0.0),
        peak_mm=1000.0 * peak,
        where=where,
    )


def _duration_text(summary: Mapping[str, Any]) -> str:
    """``"2 s "``: the run's ``duration``, or ``""`` where the summary records none."""
    duration = _number(summary, "duration")
    return "" if duration is None or not duration > 0.0 else f"{duration:.3g} s "


def _only_the_start_offset(summary: Mapping[str, Any], found: list[str]) -> bool:
    """Only the RMS error failed, and the error was never larger than at the start
    (``max_position_error_m`` within :data:`START_SLACK` of ``initial_offset_m``): the
    error converged, and the RMS counts the time it took to remove the start offset."""
    if found != ["rms_error_above_limit"]:
        return False
    largest = _number(summary, "max_position_error_m")
    offset = _number(summary, "initial_offset_m")
    final = _number(summary, "final_position_error_m")
    if largest is None or offset is None or final is None or not offset > 0.0:
        return False
    return largest <= offset * (1.0 + START_SLACK)


def _folded_arm(summary: Mapping[str, Any]) -> str:
    """:data:`FOLDED_ARM` naming the run's ``method`` if it only integrates Xd_dot (both
    such methods of the docs' explanation if the summary names none), or
    :data:`FOLDED_ARM_NO_CORNERS` where the summary says the trajectory has no corners
    (``corner_position_error_m`` present and None) and gives the step ``dt``; else
    :data:`FOLDED_ARM_OTHER` naming it."""
    method = summary.get("method")
    if method is None or method in FOLDING_METHODS:
        methods = ", ".join(FOLDING_METHODS)
    elif method in XD_DOT_INTEGRATORS:
        methods = method
    else:
        return FOLDED_ARM_OTHER.format(method=one_line(str(method), 40))
    dt = _number(summary, "dt")
    no_corners = "corner_position_error_m" in summary and summary["corner_position_error_m"] is None
    if no_corners and dt is not None:
        return FOLDED_ARM_NO_CORNERS.format(methods=methods, dt=f"{dt:g} s")
    return FOLDED_ARM.format(methods=methods)


def held_limits(summary: Mapping[str, Any]) -> list[str]:
    """The rate and actuator limits the run held (:func:`_counts_as_held`), in words
    (``"a wheel at its speed limit on 342 of 400 steps"``, ``"a joint at its rate limit on
    250 of 750 steps"``, ``"a wheel at its force limit for 7.38 of 40 s"``), from
    ``wheel_limit_steps`` of ``steps``, ``actuator_saturated_time_s`` of ``duration`` and
    ``joint_rate_limit_steps`` of ``steps``, in that order; empty where none is recorded. A
    joint at a position limit (``joint_limit_steps``) is not among them: it is a pose the arm
    cannot reach, not a speed it cannot exceed."""
    check_summary(summary)
    held = []
    steps = _number(summary, "steps") or 0
    at_wheel_limit = _number(summary, "wheel_limit_steps") or 0
    if _counts_as_held(summary, at_wheel_limit):
        held.append(f"a wheel at its speed limit on {int(at_wheel_limit)} of {int(steps)} steps")
    duration = _number(summary, "duration") or 0.0
    at_actuator_limit = _number(summary, "actuator_saturated_time_s") or 0.0
    if _counts_as_held(summary, at_actuator_limit, time=True):
        what = ACTUATOR_LIMITS.get(str(summary.get("plant")), "an actuator at its limit")
        held.append(f"{what} for {at_actuator_limit:.3g} of {duration:.3g} s")
    planned = _planned_force_time(summary)
    if planned:
        force = _number(summary, "mpc_wheel_force_limit_n") or 0.0
        held.append(PLANNED_FORCE_HELD.format(force=force, held_s=planned, duration=duration))
    at_rate_limit = _number(summary, "joint_rate_limit_steps") or 0
    if _counts_as_held(summary, at_rate_limit):
        held.append(f"a joint at its rate limit on {int(at_rate_limit)} of {int(steps)} steps")
    return held


def _floor_texts(summary: Mapping[str, Any]) -> tuple[str, str]:
    """``start_stability`` and ``stability_min`` spelt apart (:func:`texts_apart`: a start
    just below the floor is not spelt as the floor itself); ``nan`` where missing."""
    start = _number(summary, "start_stability")
    floor = _number(summary, "stability_min")
    if start is None or floor is None:
        return "nan", "nan"
    start_text, (floor_text,) = texts_apart(start, floor)
    return start_text, floor_text


def explain(summary: Mapping[str, Any]) -> tuple[list[str], str, str]:
    """``(codes, what, cause)`` of a run's ``summary``: the reason codes, what went wrong
    in words and its likely cause (both ``""`` when the run tracked). ``summary`` must
    be a mapping whose :data:`NUMBER_KEYS` hold numbers (:func:`check_summary`)."""
    found = reasons(summary)
    if not found:
        return found, "", ""
    start_stability = _number(summary, "start_stability")
    least_stability = _number(summary, "min_stability")
    start_text, floor_text = _floor_texts(summary)
    values = {
        "steps": summary.get("steps"),
        "singular_steps": summary.get("singular_steps"),
        "saturated_steps": summary.get("saturated_steps"),
        "final_mm": 1000.0 * (_number(summary, "final_position_error_m") or 0.0),
        "rms_mm": 1000.0 * (_number(summary, "rms_position_error_m") or 0.0),
        "limit": _limit_text(summary),
        "start_text": start_text,
        "floor_text": floor_text,
        "start_stability": math.nan if start_stability is None else start_stability,
        "min_stability": math.nan if least_stability is None else least_stability,
        "clearance_mm": 1000.0 * (_number(summary, "min_obstacle_clearance_m") or 0.0),
    }
    what = ", ".join(REASONS[code].format(**values) for code in found)
    return found, what, likely_cause(summary, found)


def lost_support(summary: Mapping[str, Any]) -> bool:
    """The run's physics plant unloaded an edge of the support polygon (``support_lost``
    true) and the robot did not tip over (``tipped`` false: a tip-over is a reason of its
    own): the run whose verdict ends with :func:`support_warning`. False on every plant
    that does not report ``support_lost``. ``summary`` as in :func:`verdict`."""
    check_summary(summary)
    return bool(summary.get("support_lost")) and not summary.get("tipped")


def support_warning(summary: Mapping[str, Any]) -> str:
    """:data:`SUPPORT_LOST` for a run whose physics plant unloaded an edge of the support
    polygon (``support_lost`` true) and did not tip over (``tipped`` false: a tip-over is
    a reason of its own), with :data:`PREDICTED_BELOW_FLOOR` where the controller
    predicted an edge load (N) below its floor; ``""`` otherwise, and on every plant that
    does not report ``support_lost``. ``summary`` as in :func:`verdict`."""
    if not lost_support(summary):
        return ""
    least = _number(summary, "min_predicted_edge_load_n")
    floor = _number(summary, "min_edge_load_floor_n")
    predicted = ""
    if least is not None and floor is not None and least < floor - PREDICTED_SLACK_N:
        least_text, floor_text = f"{least:.3g}", f"{floor:.3g}"
        if least_text == floor_text:  # spelt alike: texts_apart spells both in full
            least_text, (floor_text,) = texts_apart(least, floor)
        predicted = PREDICTED_BELOW_FLOOR.format(least=least_text, floor=floor_text)
    return SUPPORT_LOST.format(
        unloaded_s=_number(summary, "unloaded_time_s") or 0.0,
        duration_s=_number(summary, "duration") or 0.0,
        predicted=predicted,
    )


def floor_warning(
    summary: Mapping[str, Any], found: list[str] | None = None, cause: str | None = None
) -> str:
    """:data:`STARTED_BELOW_FLOOR` for a run that started below its own stability floor
    (``start_stability`` < ``stability_min``, both in the summary: a ``qp`` or ``mpc``
    run) where its verdict does not say so already: not where it is a reason
    (``below_floor_at_start``, an ``mpc`` run) nor where it is the likely cause
    (:data:`BELOW_FLOOR`); ``""`` otherwise. ``found`` and ``cause`` are the run's
    reasons and likely cause (:func:`explain`'s, computed when None); ``summary`` as in
    :func:`verdict`."""
    check_summary(summary)
    if not _started_below_floor(summary):
        return ""
    if found is None or cause is None:
        found, _, cause = explain(summary)
    start_text, floor_text = _floor_texts(summary)
    named = BELOW_FLOOR.format(start_stability=start_text, stability_min=floor_text)
    if "below_floor_at_start" in found or cause == named:
        return ""
    return STARTED_BELOW_FLOOR.format(start=start_text, floor=floor_text)


def verdict(summary: Mapping[str, Any]) -> dict[str, Any]:
    """The verdict keys of a run's ``summary`` (the keys :func:`ddwmmr.simulate` writes):
    ``{"verdict": str, "verdict_reasons": list[str]}`` (see the module docstring).
    ``summary`` must be a mapping; anything else (None, a list, a number) is a one-line
    :class:`~ddwmmr.errors.ParameterError` naming ``summary`` (:func:`reasons` checks it
    first). Each key it reads as a number (:data:`NUMBER_KEYS`) must be a number, missing
    or None, or the ``"nan"``/``"inf"``/``"-inf"`` a ``summary.json`` writes for a
    non-finite one; anything else (text, a boolean, a list) is a one-line
    :class:`~ddwmmr.errors.ParameterError` naming the key, whether or not this summary's
    verdict would read it."""
    found, what, cause = explain(summary)
    warnings = (support_warning(summary), floor_warning(summary, found, cause))
    tail = "".join(f"; {warning}" for warning in warnings if warning)
    if not found:
        return {"verdict": TRACKED + tail, "verdict_reasons": []}
    return {
        "verdict": f"did not track: {what}; likely cause: {cause}{tail}",
        "verdict_reasons": found,
    }


def short_verdict(summary: Mapping[str, Any]) -> str:
    """A few words for a crowded line: ``tracked`` or ``DID NOT TRACK (codes)``, from the
    summary's verdict keys (computed if missing); ``summary`` as in :func:`verdict`, its
    ``verdict_reasons`` (if there) a list of reason codes (strings)."""
    check_summary(summary)
    found = summary.get("verdict_reasons")
    if found is None:
        found = verdict(summary)["verdict_reasons"]
    elif not isinstance(found, list | tuple) or not all(isinstance(c, str) for c in found):
        raise ParameterError(
            "summary: verdict_reasons must be a list of reason codes (strings such as "
            f"'rms_error_above_limit') or None (got {shown(found)})"
        )
    return TRACKED if not found else f"DID NOT TRACK ({', '.join(found)})"
