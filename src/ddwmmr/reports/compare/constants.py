"""Settings of the method comparison: the slides' ranking and names, the studies and
their sweeps, the tie tolerance, the diagnosis thresholds and the timing keys.
"""

from __future__ import annotations

#: The slides' ranking, best first: CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS >= RR-PI.
SLIDES_ORDER = ("clrrmc-ts", "clrrmc-cs", "ap", "ats", "pi")
#: The slides' names of our methods.
SLIDES_NAMES = {
    "clrrmc-ts": "CLRRMC-TS",
    "clrrmc-cs": "CLRRMC-CS",
    "ap": "RR-AP",
    "ats": "RR-ATS",
    "pi": "RR-PI",
}
#: Studies selectable with ``--study`` (``all`` selects every one).
STUDIES = ("tau", "dt", "integrator", "init", "corners")
#: Trajectories every comparison includes; the studies use them.
DEFAULT_TRAJECTORIES = ("ellipse", "rectangle")
STUDY_TRAJECTORY = "ellipse"
CORNER_TRAJECTORY = "rectangle"
#: Relative and absolute (m) tolerance under which two scores count as a tie.
TIE_RELATIVE = 0.05
TIE_ABSOLUTE_M = 1e-4
#: Time constants (s) of the tau sweep.
TAUS = (0.1, 0.3, 1.0, 3.0)
#: Steps (s) of the step-size sweep.
STEP_SIZES = (0.01, 0.02, 0.04, 0.08, 0.16)
#: Initial offsets of the offset sweep, as multiples of the robot's default offset
#: (:func:`ddwmmr.resolution.reference.default_offset`).
OFFSET_SCALES = (0.0, 0.5, 1.0, 2.0, 4.0)
#: Converged = the position error stays below this fraction of its initial value.
CONVERGED_FRACTION = 0.05
#: |cos th1| below this counts as reaching the shoulder singularity cos(th1) = 0.
SINGULAR_COS = 0.05
#: A run counts as lost at the singularity if its error afterwards exceeds twice the largest
#: error before it and this many metres (a QP on u passes cos(th1) = 0 unharmed).
SINGULAR_LOSS_M = 0.05
#: Extra runs that explain the ranking: (method, options) checked when the method runs.
#: (The slides' aux = sum for ats and the closed-loop methods is the slides preset, which
#: the report runs in full.)
VARIANTS = (("ap", (("K3", 0.0),)),)
#: Summary keys that are wall-clock timings (vary run to run; excluded from equality tests).
TIMING_KEYS = ("median_step_us",)
#: Marker file that identifies an output folder of this tool (so it may be replaced).
MARKER = "metrics.csv"


def slides_name(method: str) -> str:
    """The slides' name of ``method`` (``RR-PI``...), or the method name itself."""
    return SLIDES_NAMES.get(method, method)


def is_timing(key: str) -> bool:
    """True for summary keys that are wall-clock timings (not reproducible)."""
    return key in TIMING_KEYS or key.endswith("_us")
