"""Why a run scored as it did, and the measurements the studies share.

:func:`diagnose` turns a run's time series into :class:`Finding` sentences (shoulder
singularity, orientation lost at corners, joint limits, commands the plant clipped, speed
limits a method held itself, kept offset, convergence); :func:`convergence_time`,
:func:`observed_order` and :func:`corner_times` serve the studies.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ddwmmr.controllers.base import commanded_steps
from ddwmmr.model import Robot
from ddwmmr.reports.compare.constants import CONVERGED_FRACTION, SINGULAR_COS, SINGULAR_LOSS_M
from ddwmmr.reports.compare.document import fmt, mm
from ddwmmr.reports.compare.plan import CompareConfig, Plan, RunOutput, RunSpec
from ddwmmr.sim.simulate import joint_limits_held

# -- the reasons a run scores as it does --------------------------------------------------


def singularity_onset(ts: Mapping[str, np.ndarray]) -> int | None:
    """Index of the first sample with |cos th1| < :data:`SINGULAR_COS`, or None."""
    hits = np.nonzero(np.abs(np.cos(ts["th1"])) < SINGULAR_COS)[0]
    return int(hits[0]) if len(hits) else None


def singularity_outcome(ts: Mapping[str, np.ndarray]) -> tuple[str, int | None]:
    """What the shoulder singularity did to a run: ``("away", None)`` if |cos th1| never
    fell below :data:`SINGULAR_COS`, else ``("lost", onset)`` when the error afterwards
    exceeds twice the largest error before it and :data:`SINGULAR_LOSS_M`, or
    ``("passes", onset)``."""
    onset = singularity_onset(ts)
    if onset is None:
        return "away", None
    before = float(np.max(ts["position_error_m"][: onset + 1]))
    after = float(np.max(ts["position_error_m"][onset:]))
    return ("lost" if after > max(2.0 * before, SINGULAR_LOSS_M) else "passes"), onset


def saturation_span(
    ts: Mapping[str, np.ndarray], exclude: np.ndarray | None = None
) -> tuple[int, float, float]:
    """Number of saturated commanded steps (not in ``exclude``, a boolean per sample) and
    the first and last such time (s). The steps are the run's commanded ones
    (:func:`~ddwmmr.controllers.base.commanded_steps`: the last sample's command is never
    applied), as the summary's ``saturated_steps`` counts them."""
    saturated = _saturated(ts, exclude)
    hits = np.nonzero(saturated)[0]
    if not len(hits):
        return 0, math.nan, math.nan
    return len(hits), float(ts["t"][hits[0]]), float(ts["t"][hits[-1]])


def _saturated(ts: Mapping[str, np.ndarray], exclude: np.ndarray | None) -> np.ndarray:
    """Boolean per commanded step: the plant clipped its command, the step not in
    ``exclude`` (a boolean per sample)."""
    saturated = commanded_steps(ts["saturated"]) > 0
    if exclude is not None:
        saturated &= ~commanded_steps(exclude)
    return saturated


def orientation_jumps(ts: Mapping[str, np.ndarray]) -> int:
    """Number of steps of the desired orientation (> 1 rad between samples: corners)."""
    return int(np.sum(np.abs(np.diff(ts["phiE_d"])) > 1.0))


def at_joint_limit(ts: Mapping[str, np.ndarray], robot: Robot) -> np.ndarray:
    """Boolean per sample: th1 or th2 sits at one of the robot's joint limits (as the
    summary's ``joint_limit_steps`` judges it: :func:`ddwmmr.sim.simulate.joint_limits_held`)."""
    return joint_limits_held(ts, robot)[0]


def _joint_limit_reason(
    ts: Mapping[str, np.ndarray], summary: Mapping[str, Any], limited: np.ndarray
) -> str:
    """The first joint limit reached and the commanded steps at a joint limit (the
    summary's ``joint_limit_steps`` where it has it)."""
    first = int(np.argmax(limited))
    joint = "th2" if abs(ts["th2"][first]) >= abs(ts["th1"][first]) else "th1"
    steps = summary.get("joint_limit_steps")
    if steps is None:
        steps = int(np.sum(commanded_steps(limited)))
    text = (
        f"{'the elbow' if joint == 'th2' else 'the shoulder'} {joint} ran into its joint limit "
        f"({ts[joint][first]:+.2f} rad) at t = {ts['t'][first]:.1f} s and stayed there for "
        f"{steps} steps; the plant stops a joint at its limit, so the commanded "
        "motion is not produced"
    )
    if joint == "th2":
        text += " (an elbow at +-pi folds the arm back: manipulability 0)"
    return text


def saturated_after_jumps(ts: Mapping[str, np.ndarray], exclude: np.ndarray) -> bool:
    """True if every saturated step (not in ``exclude``) lies within 10 % of the run after a
    step of the desired orientation."""
    t = ts["t"]
    jumps = t[1:][np.abs(np.diff(ts["phiE_d"])) > 1.0]
    saturated = commanded_steps(t)[_saturated(ts, exclude)]
    if not len(jumps) or not len(saturated):
        return False
    lag = saturated[:, None] - jumps[None, :]
    return bool(np.all(np.any((lag >= 0) & (lag <= 0.1 * t[-1]), axis=1)))


def keeps_offset(summary: Mapping[str, Any]) -> bool:
    """Final and largest position error within 10 % of the initial offset (open loop)."""
    initial = float(summary["initial_offset_m"])
    return initial > 0 and (
        abs(summary["final_position_error_m"] - initial) <= 0.1 * initial
        and summary["max_position_error_m"] <= 1.1 * initial
    )


@dataclass(frozen=True)
class Finding:
    """One data-backed sentence about a run; ``adverse`` if it explains a poor score."""

    text: str
    adverse: bool = True


def diagnose(
    config: CompareConfig, plan: Plan, outputs: Mapping[RunSpec, RunOutput], spec: RunSpec
) -> list[Finding]:
    """Why the run ``spec`` scored as it did: singularity, lost corner orientation,
    saturation, kept offset (adverse) or convergence (not adverse)."""
    ts, summary = outputs[spec].timeseries, outputs[spec].summary
    findings = []
    outcome, onset = singularity_outcome(ts)
    # ignore: "lost" and "passes" come with an onset (singularity_outcome), never None
    if outcome == "lost":
        findings.append(Finding(_singularity_reason(spec, ts, onset, plan, outputs)))  # type: ignore[arg-type]
    elif outcome == "passes":
        findings.append(Finding(_passage_text(ts, summary, onset), False))  # type: ignore[arg-type]
        onset = None
    jumps = orientation_jumps(ts)
    if jumps and summary["rms_orientation_error_rad"] > 0.5 and onset is None:
        findings.append(Finding(_corner_reason(spec, summary, jumps)))
    limited = at_joint_limit(ts, config.robot)
    # a limit reached at the last sample only starts no step: nothing held, nothing to say
    if np.any(commanded_steps(limited)):
        findings.append(Finding(_joint_limit_reason(ts, summary, limited)))
    count, first, last = saturation_span(ts, exclude=limited)
    if count:
        where = (
            f"all within {fmt(0.1 * ts['t'][-1])} s after a corner's orientation step"
            if saturated_after_jumps(ts, limited)
            else f"t = {first:.1f} to {last:.1f} s"
        )
        more = " more" if np.any(commanded_steps(limited)) else ""
        findings.append(
            Finding(
                f"the plant clipped the command at the wheel or joint speed limits in "
                f"{count}{more} steps ({where}), so the robot could not follow it"
            )
        )
    held = held_limits_text(summary)
    if held:
        findings.append(Finding(held, False))
    if keeps_offset(summary):
        findings.append(
            Finding(
                "it is open loop: it keeps the initial end-effector offset "
                f"({mm(summary['initial_offset_m'])} mm) for the whole run"
            )
        )
    settle = convergence_time(ts["t"], ts["position_error_m"])
    if summary["initial_offset_m"] > 0 and not math.isnan(settle):
        findings.append(
            Finding(f"it removes the initial offset (below 5 % after {fmt(settle)} s)", False)
        )
    if not any(f.adverse for f in findings):
        findings.append(Finding(NOTHING_ADVERSE))
    return findings


#: The closing finding of a run without an adverse one: what was looked for and not found
#: (a passage of cos(th1) = 0 that kept the path, or a limit a method held itself, is not
#: among them).
NOTHING_ADVERSE = (
    "no path lost at the shoulder singularity, no command clipped by the plant and no "
    "orientation lost at a corner"
)


def _passage_text(ts: Mapping[str, np.ndarray], summary: Mapping[str, Any], onset: int) -> str:
    """A passage of |cos th1| < :data:`SINGULAR_COS` that kept the path: when, the largest
    error after it (mm), and whether the method damped an inverse there."""
    after = float(np.max(ts["position_error_m"][onset:]))
    damped = summary.get("singular_steps") or 0
    how = f"damped on {damped} steps" if damped else "no step damped"
    return (
        f"it passes the shoulder singularity cos(th1) = 0 at t = {ts['t'][onset]:.1f} s "
        f"without losing the path (largest error after it {mm(after)} mm; {how})"
    )


def held_limits_text(summary: Mapping[str, Any]) -> str:
    """A finding on the steps with a wheel at its speed limit (``wheel_limit_steps``) or a
    joint rate at its limit (``joint_rate_limit_steps``), when either count exceeds the
    steps the plant clipped (``saturated_steps``): a limit held inside the method's own
    bounds (``qp``, ``mpc``), which ``saturated_steps`` does not see. Empty otherwise."""
    clipped = summary.get("saturated_steps") or 0
    counts = [
        (summary.get(key) or 0, what)
        for key, what in (
            ("wheel_limit_steps", "a wheel at its speed limit"),
            ("joint_rate_limit_steps", "a joint at its rate limit"),
        )
    ]
    if all(count <= clipped for count, _ in counts):
        return ""
    parts = " and ".join(f"{what} on {count} steps" for count, what in counts if count)
    clip = f"the plant clipped {clipped} steps in all" if clipped else "the plant clipped none"
    return f"it held {parts} ({clip})"


def _singularity_reason(
    spec: RunSpec,
    ts: Mapping[str, np.ndarray],
    onset: int,
    plan: Plan,
    outputs: Mapping[RunSpec, RunOutput],
) -> str:
    t = float(ts["t"][onset])
    d_th1 = float(ts["th1"][onset] - ts["th1"][0])
    d_phi = float(ts["phi"][onset] - ts["phi"][0])
    text = (
        f"it drove the shoulder into the singularity cos(th1) = 0 at t = {t:.1f} s "
        f"(th1 moved by {d_th1:+.2f} rad while the base heading moved by {d_phi:+.2f} rad); "
        "near it the damped inverse cannot produce the commanded motion and the end effector "
        f"leaves the path (largest error {mm(np.max(ts['position_error_m'][onset:]))} mm)"
    )
    if spec.method == "pi" and abs(d_th1 - d_phi) <= 0.25 * abs(d_phi):
        text += (
            ". Why: the base-yaw and shoulder columns of J are identical, so the "
            "minimum-norm solution splits the yaw rate equally between them and th1 follows "
            "the base heading, which must turn 2 pi per loop"
        )
    variant = next(
        (v for v in plan.variants if v.method == spec.method and v.trajectory == spec.trajectory),
        None,
    )
    if spec.method == "ap" and not spec.options and variant is not None:
        run = outputs[variant]
        if singularity_onset(run.timeseries) is None:
            text += (
                ". Why: the K3 phi^2 term of the potential (K3 = 0.66, the slides' value) "
                "pushes the base heading toward 0 while the tangent heading must turn 2 pi "
                "per loop; in the null space of J, turning the base by +k turns the shoulder "
                "by -k, so the shoulder absorbs the heading the base is denied and th1 is "
                "dragged to pi/2. With K3 = 0 the same run never gets near the singularity "
                f"(RMS {mm(run.summary['rms_position_error_m'])} mm)"
            )
    return text


def _corner_reason(spec: RunSpec, summary: Mapping[str, Any], jumps: int) -> str:
    text = (
        f"it does not follow the pi/2 steps of the desired orientation at the {jumps} "
        "corners: the steps are not in Xd_dot, which is all it integrates, so phiE lags by "
        f"k pi/2 after corner k (RMS orientation error "
        f"{summary['rms_orientation_error_rad']:.2f} rad)"
    )
    if spec.method == "clrrmc-cs":
        text += (
            ". Its feedback acts on q_d - q, and the reference q_d is the augmented-Jacobian "
            "resolution integrated from Xd_dot alone, so it tracks the reference's own "
            "orientation loss faithfully"
        )
    return text


# -- studies ------------------------------------------------------------------------------


def convergence_time(
    t: np.ndarray, error: np.ndarray, fraction: float = CONVERGED_FRACTION
) -> float:
    """First time (s) after which ``error`` stays below ``fraction`` of its initial value.

    0 for a run that starts on the path; NaN if it never settles within the run.
    """
    if error[0] <= 0.0:
        return 0.0
    above = np.nonzero(error > fraction * error[0])[0]
    last = int(above[-1])
    return float(t[last + 1]) if last + 1 < len(t) else math.nan


def observed_order(values: Mapping[float, float]) -> float:
    """Median slope of log(error) vs log(dt): the integrator's observed order of accuracy.

    Pairs with an error below 1e-12 m (round-off) are skipped; NaN if none is left.
    """
    steps = sorted(values)
    slopes = [
        math.log(values[b] / values[a]) / math.log(b / a)
        for a, b in itertools.pairwise(steps)
        if values[a] > 1e-12 and values[b] > 1e-12
    ]
    return float(np.median(slopes)) if slopes else math.nan


def corner_times(trajectory: Any, duration: float) -> list[float]:
    """Times (s) of the trajectory's corners within the run, its end ``duration`` (s)
    excluded (no window follows a corner there): the trajectory's own ``corner_times`` (a
    :class:`~ddwmmr.trajectories.Rectangle`'s alpha = k pi/2); none for a trajectory
    without corners."""
    corners = getattr(trajectory, "corner_times", None)
    return [] if corners is None else [t for t in corners(duration) if t < duration]
