"""The physical limit of a scenario: minimum time under the thesis plant's force limits.

Two layers:

* :class:`FreeTimeOCP`, a free-final-time optimal control problem of any model given as
  an ODE with box bounds (:class:`ShootingModel`), solved offline with CasADi/IPOPT. The
  horizon is cut into legs; leg ``i`` has its own duration ``T_i`` and ``M`` shooting
  intervals of length ``T_i / M``, the model is integrated by RK4 under piecewise-constant
  inputs, and each leg ends on a constraint of its own (a waypoint, a goal pose)::

      minimise    sum_i T_i  (+ 1e-6 |u / u_max|^2, a tie-breaker)
      subject to  x_{k+1} = RK4(x_k, u_k, T_i / M)            (every interval of leg i)
                  lower <= end_i(x at the end of leg i) <= upper
                  node rows at every node, interval rows in every interval, state and
                  input boxes, x_0 = start.

* :class:`MinimumTimeProblem`, that problem for the thesis scenarios: the thesis plant's
  force-level model (:class:`~ddwmmr.model.symbolic.ThesisDynamics`, wheel forces and
  joint rates as inputs), one leg per waypoint::

      |p_E(x_end of leg i) - waypoint_i| <= tolerance   (the end effector reaches it)
      S(q) >= S_min at every node and 3 points inside every interval (exact, as a box on
          the centre of mass)
      |F_left|, |F_right| <= force limit, |th_i dot| <= joint speed,
      joint limits, wheel speeds, x_0 = start at rest.

The arm's reach is part of the problem (the end effector, not the base, must reach each
waypoint). The problem is non-convex (heading, elbow branch), so IPOPT returns a local
optimum: the time of a feasible trajectory of the model, i.e. an upper bound on the true
minimum. :mod:`ddwmmr.bounds` runs it from many starts (and brackets it from below);
``solve_minimum_time`` keeps the best of the straight-line starts and any given.
The same :class:`FreeTimeOCP` solves the bounded-wheel-speed differential drive whose
time-optimal paths are known in closed form (:mod:`ddwmmr.bounds.diffdrive`), the check
that the transcription finds true optima.
"""

from __future__ import annotations

import io
import itertools
import json
import math
import os
import zipfile
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np

from ddwmmr import interrupts
from ddwmmr.errors import (
    ParameterError,
    check_int_at_least,
    check_positive,
    finite_values,
    read_input_bytes,
    shown,
)
from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import STABILITY_FLOOR, check_stability_floor

if TYPE_CHECKING:
    import os

#: Points inside each shooting interval where S is checked as well as at the nodes.
INTERIOR_CHECKS = 3
#: Leg durations (s) the solver may choose from.
LEG_TIME_RANGE = (0.05, 120.0)
#: Where ``python -m ddwmmr.bounds`` keeps scenario number N's (from 1) best-known
#: trajectory (``.npz``: ``times``, ``states``, ``inputs``, ``legs``): this name in the
#: ``PLAN_FOLDER`` of its output folder.
PLAN_NAME = "scenario-{:03d}-best.npz"
PLAN_FOLDER = "cache"

Rows = Callable[..., sym.Symbolic]


#: What reading a damaged plan archive raises: EOFError (empty), BadZipFile (truncated,
#: bad checksum), zlib.error (damaged compressed data), RuntimeError (an encrypted
#: member), NotImplementedError (an unknown compression), MemoryError (a header claiming
#: a huge shape), ValueError (pickled data, a member that is not an array), KeyError (a
#: missing array), OSError. Anything else is a bug, not a bad file, and is not caught.
_DAMAGED_ARCHIVE = (
    EOFError,
    zipfile.BadZipFile,
    zlib.error,
    RuntimeError,
    NotImplementedError,
    MemoryError,
    ValueError,
    KeyError,
    OSError,
)


@dataclass(frozen=True)
class ShootingModel:
    """A model for :class:`FreeTimeOCP`: ``xdot = rhs(x, u)`` with its bounds.

    Attributes:
        nx, nu: state and input sizes.
        rhs: ``(x, u) -> xdot`` on CasADi SX.
        u_lower, u_upper: input box (nu,); x_lower, x_upper: state box (nx,), +-inf free.
        node_rows: ``x -> rows`` held at every node within ``node_bounds``, or None.
        interval_rows: ``(x_k, u_k, h) -> rows`` held in every interval within
            ``interval_bounds`` (e.g. a constraint between the nodes), or None.
    """

    nx: int
    nu: int
    rhs: Rows
    u_lower: np.ndarray
    u_upper: np.ndarray
    x_lower: np.ndarray
    x_upper: np.ndarray
    node_rows: Rows | None = None
    node_bounds: tuple[np.ndarray, np.ndarray] | None = None
    interval_rows: Rows | None = None
    interval_bounds: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self) -> None:
        for rows, bounds in (("node_rows", "node_bounds"), ("interval_rows", "interval_bounds")):
            if getattr(self, rows) is not None and getattr(self, bounds) is None:
                raise ParameterError(f"{bounds}: (lower, upper) arrays are needed with {rows}")


@dataclass(frozen=True)
class LegEnd:
    """The constraint ending a leg: ``lower <= rows(x) <= upper`` at its last node."""

    rows: Rows
    lower: np.ndarray
    upper: np.ndarray


@dataclass(frozen=True)
class Guess:
    """A trajectory to start from: node times (s), states (n, nx), inputs (n, nu), and the
    times (s) at which each leg ended (each waypoint was reached)."""

    times: np.ndarray
    states: np.ndarray
    inputs: np.ndarray
    arrivals: np.ndarray

    @classmethod
    def load(cls, path: str | Path, nx: int = sym.NX_FORCE, nu: int = sym.NU_FORCE) -> Guess:
        """A trajectory stored as ``python -m ddwmmr.bounds`` stores its best-known ones
        (``.npz``: ``times`` (M+1,) s increasing from 0, ``states`` (M+1, nx), ``inputs``
        (M, nu) held from each time, ``legs`` (one duration per waypoint, s, > 0, summing
        to the last time)); a one-line :class:`ParameterError` naming the file for anything
        else, a file that cannot be read as such an archive (empty, truncated, damaged, a
        single ``.npy`` array, pickled data, a member that is not a numeric array, a
        folder) included."""
        if os.path.isdir(path):  # False where the name cannot be looked up: read below
            raise ParameterError(
                f"plan {path} must be a .npz file, not a folder (only the scenario tool's "
                "--option plan=DIR takes the output folder of python -m ddwmmr.bounds, "
                f"reading each scenario's {PLAN_FOLDER}/{PLAN_NAME.replace('{:03d}', 'NNN')})"
            )
        arrays = None
        reason = "a single array, not an archive"
        try:
            os.lstat(path)
        except FileNotFoundError:
            raise ParameterError(f"plan {path}: no such file") from None
        except (OSError, ValueError):
            pass  # a name too long, a NUL in it...: read_input_bytes says so, naming plan
        # read as every input file is (a FIFO, /proc/kmsg or a file above the cap refused,
        # never waited on), then parsed from memory
        data = read_input_bytes(path, "plan")
        try:
            loaded = np.load(io.BytesIO(data), allow_pickle=False)
            if isinstance(loaded, np.lib.npyio.NpzFile):
                with loaded:
                    arrays = {key: np.asarray(loaded[key], dtype=float) for key in _PLAN_ARRAYS}
        except _DAMAGED_ARCHIVE as error:
            # a damaged file fails wherever numpy, zipfile or the decompressor notices
            reason = type(error).__name__
            if isinstance(error, KeyError):
                reason = error.args[0]
            elif reason.islower():  # zlib.error
                reason = f"{type(error).__module__}.{reason}"
        if arrays is None:
            raise ParameterError(
                f"plan {path} must be a .npz with {', '.join(_PLAN_ARRAYS)} ({reason})"
                f"{_search_again(Path(path))}"
            )
        times, states, inputs, legs = (arrays[key] for key in _PLAN_ARRAYS)
        m = len(times) - 1
        shapes_ok = (
            times.ndim == 1
            and m >= 1
            and states.shape == (m + 1, nx)
            and inputs.shape == (m, nu)
            and legs.ndim == 1
            and len(legs) >= 1
        )
        finite = shapes_ok and all(np.all(np.isfinite(a)) for a in arrays.values())
        # the legs end where the times do: the arrivals (their sums) are read against the
        # times, a plan shifted or with legs of another length would be followed wrong
        timed = finite and times[0] == 0.0 and np.all(np.diff(times) > 0.0)
        ends = timed and math.isclose(float(np.sum(legs)), float(times[-1]), rel_tol=1e-9)
        if not (ends and np.all(legs > 0.0)):
            raise ParameterError(
                f"plan {path} must hold times (M+1,) increasing from 0, states (M+1, {nx}), "
                f"inputs (M, {nu}) and legs (> 0 s) summing to the last time, all finite"
            )
        return cls(times, states, inputs, np.cumsum(legs))

    def sample(self, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """States and inputs at the times ``at`` (s), linearly interpolated (an input
        between the times it starts at), held beyond the ends."""
        at = np.asarray(at, dtype=float)
        states = np.column_stack([np.interp(at, self.times, c) for c in self.states.T])
        times_u = self.times[: len(self.inputs)]
        inputs = np.column_stack([np.interp(at, times_u, c) for c in self.inputs.T])
        return states, inputs

    def leg_samples(self, leg: int, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`sample` ``offsets`` (s) after the start of leg ``leg`` (0-based: the
        arrival at the waypoint before it)."""
        start = 0.0 if leg == 0 else float(self.arrivals[leg - 1])
        return self.sample(start + np.asarray(offsets, dtype=float))

    @property
    def legs(self) -> np.ndarray:
        """Each leg's duration (s)."""
        return np.diff(np.concatenate([[0.0], self.arrivals]))

    @cached_property
    def arrival_states(self) -> np.ndarray:
        """The state at each arrival (one row per waypoint), sampled once (a controller
        reads its target's every step)."""
        return self.sample(self.arrivals)[0]


#: The arrays of a stored plan, in order.
_PLAN_ARRAYS = ("times", "states", "inputs", "legs")


def plan_path(folder: str | os.PathLike[str], scenario: int) -> Path:
    """Scenario number ``scenario``'s (from 1) best-known trajectory in the output folder
    of ``python -m ddwmmr.bounds`` (in its ``cache``) or in that cache folder itself; a
    one-line :class:`ParameterError` naming ``folder``, the file expected and how to get
    it where neither holds it (:func:`missing_plan`)."""
    folder = Path(folder)
    name = PLAN_NAME.format(scenario)
    inside = folder / PLAN_FOLDER / name
    if inside.exists():
        return inside
    if (folder / name).exists():
        return folder / name
    raise ParameterError(missing_plan(folder, scenario))


def kept_trajectory(record: object) -> bool:
    """Whether a bounds cache's best-known ``record`` (the object of its ``.json``) is of a
    search that kept a trajectory beside it (``replay_ok`` true and the ``start`` it came
    from named): :func:`ddwmmr.bounds.batch.solve` then stores the trajectory as a
    ``.npz`` of the same name."""
    return (
        isinstance(record, dict) and record.get("replay_ok") is True and bool(record.get("start"))
    )


def _kept_trajectory(record: Path) -> bool:
    """:func:`kept_trajectory` of the record in the ``.json`` file ``record``; False for a
    file that cannot be read as one."""
    try:
        found = json.loads(record.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return kept_trajectory(found)


def _plan_number(name: str) -> int | None:
    """The scenario number of a file named as :data:`PLAN_NAME` names a best-known
    trajectory (``scenario-007-best.npz``: 7), else None."""
    head, _, tail = PLAN_NAME.partition("{:03d}")
    middle = name[len(head) : len(name) - len(tail)]
    if not (name.startswith(head) and name.endswith(tail) and middle.isdigit()):
        return None
    return int(middle) if middle.isascii() else None


def _search_again(plan: Path) -> str:
    """For a best-known trajectory ``plan`` of a bounds run's cache that is lost (missing
    or unreadable while its record says the search kept it): how to get it back; ``""``
    for any other file."""
    number = _plan_number(plan.name)
    if plan.parent.name != PLAN_FOLDER or number is None:
        return ""
    if not _kept_trajectory(plan.with_suffix(".json")):
        return ""
    scenario = str(number)
    return (
        f": the trajectory of that bounds run is lost; run python -m ddwmmr.bounds --out "
        f"{plan.parent.parent} --scenarios {scenario} again with the run's --seed and "
        "--payload, without --lower-only: it searches the scenario again"
    )


def missing_plan(folder: Path, scenario: int) -> str:
    """Why the bounds output ``folder`` holds no plan for scenario number ``scenario``
    (from 1), and what to do: it is no bounds output folder (no ``cache``), its search
    found no trajectory (the ``.json`` record beside the missing ``.npz``), or no run
    into it searched this scenario (``--lower-only`` writes the lower bounds only)."""
    cache = folder if folder.name == PLAN_FOLDER else folder / PLAN_FOLDER
    expected = cache / PLAN_NAME.format(scenario)
    head = f"plan {folder}: {expected} is missing"
    if not cache.is_dir():
        return (
            f"{head}: plan=DIR takes the output folder of python -m ddwmmr.bounds (or its "
            f"{PLAN_FOLDER} folder), which keeps each scenario's best-known trajectory there"
        )
    if _kept_trajectory(expected.with_suffix(".json")):
        return f"{head}, though its search kept one{_search_again(expected)}"
    if expected.with_suffix(".json").exists():
        return (
            f"{head}: the bounds run found no trajectory for scenario {scenario} (its "
            f"search is recorded in {expected.with_suffix('.json').name}): there is no plan "
            "to follow, run without plan="
        )
    others = any(cache.glob(PLAN_NAME.replace("{:03d}", "*")))
    what = (
        f"best-known trajectories of other scenarios, not of scenario {scenario}"
        if others
        else "no best-known trajectory (lower bounds only, as a --lower-only run leaves it)"
    )
    return (
        f"{head}: the folder holds {what}; run python -m ddwmmr.bounds --out "
        f"{cache.parent} again without --lower-only, with the same --seed and --payload and "
        f"--scenarios including {scenario} (it resumes from the cache)"
    )


@dataclass(frozen=True)
class PlanProblem:
    """What a stored plan was made for, as ``python -m ddwmmr.bounds`` recorded it:
    ``source``, the file that says so; ``payload`` (kg); ``waypoints`` (m, in order)."""

    source: Path
    payload: float
    waypoints: tuple[tuple[float, float], ...]


def plan_problem(path: str | Path) -> PlanProblem | None:
    """The problem the plan at ``path`` was made for, from the record the bounds tool keeps
    beside it (``scenario-NNN-best.json``, its ``key``'s ``waypoints`` and ``payload``).
    None when that record is not there or not readable: a plan made elsewhere records
    nothing to check. (The bounds run's summary.json names only its seed; turning a seed
    into waypoints is the scenario generator's, a layer above the controllers.)"""
    record = Path(path).with_suffix(".json")
    key = _json_field(record, "key")
    if not isinstance(key, dict):
        return None
    try:
        waypoints = tuple((float(x), float(y)) for x, y in key["waypoints"])
        return PlanProblem(record, float(key["payload"]), waypoints)
    except (KeyError, TypeError, ValueError):
        return None


def _json_field(path: Path, name: str) -> object:
    """Field ``name`` of the JSON object in the file at ``path``; None if the file is
    missing, unreadable, not such an object or has no such field."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data.get(name) if isinstance(data, dict) else None


@dataclass(frozen=True)
class MinimumTime:
    """Result: total time (s), leg durations (s), success flag, node times/states/inputs
    (inputs held over the interval that starts at the node), the start's label and the
    IPOPT status."""

    total: float
    legs: np.ndarray
    success: bool
    times: np.ndarray
    states: np.ndarray
    inputs: np.ndarray
    start: str
    status: str = field(default="")

    def as_guess(self) -> Guess:
        """This solution as a start for another problem (e.g. a finer grid)."""
        return Guess(self.times, self.states, self.inputs, np.cumsum(self.legs))

    def plan_arrays(self) -> dict[str, np.ndarray]:
        """The arrays a stored plan holds (``np.savez`` them; :meth:`Guess.load` reads
        them back)."""
        return {key: getattr(self, key) for key in _PLAN_ARRAYS}


class FreeTimeOCP:
    """A multiple-shooting NLP with one free duration per leg (see the module docstring).

    Args:
        model: the ODE and its bounds.
        start: the initial state (nx,).
        ends: the constraint closing each leg, in order.
        intervals_per_leg: M (>= 2).
        leg_time_range: bounds (s) on each leg's duration.
        ipopt_options: extra IPOPT options (``"max_iter"``, ``"tol"``, ...).
    """

    def __init__(
        self,
        model: ShootingModel,
        start: Sequence[float] | np.ndarray,
        ends: Sequence[LegEnd],
        intervals_per_leg: int = 30,
        leg_time_range: tuple[float, float] = LEG_TIME_RANGE,
        ipopt_options: dict[str, Any] | None = None,
    ) -> None:
        intervals_per_leg = check_int_at_least("intervals_per_leg", intervals_per_leg, 2)
        if not ends:
            raise ParameterError("ends: at least one leg is needed")
        self.model = model
        self.start = np.asarray(start, dtype=float)
        if self.start.shape != (model.nx,):
            raise ParameterError(f"start must hold {model.nx} numbers (got {self.start.shape})")
        self.ends = list(ends)
        self.M = intervals_per_leg
        self.legs = len(self.ends)
        self.n = self.legs * self.M
        self.leg_time_range = leg_time_range
        self._build(ipopt_options or {})

    # -- construction -------------------------------------------------------------------
    def _build(self, extra: dict[str, Any]) -> None:
        m, n = self.model, self.n
        nx, nu = m.nx, m.nu
        X = ca.MX.sym("X", nx, n + 1)
        U = ca.MX.sym("U", nu, n)
        T = ca.MX.sym("T", self.legs)
        xs, us, hs = ca.SX.sym("x", nx), ca.SX.sym("u", nu), ca.SX.sym("h")
        step = ca.Function("step", [xs, us, hs], [sym.rk4_step(m.rhs, xs, us, hs)])
        h_row = ca.reshape(ca.repmat(T.T / self.M, self.M, 1), 1, n)  # leg-major
        rows = [ca.vec(step.map(n)(X[:, :-1], U, h_row) - X[:, 1:])]
        lower, upper = [np.zeros(nx * n)], [np.zeros(nx * n)]
        self.node_slice = self.interval_slice = slice(0, 0)
        if m.node_rows is not None and m.node_bounds is not None:  # both or neither
            node = ca.Function("node", [xs], [m.node_rows(xs)])
            rows.append(ca.vec(node.map(n + 1)(X)))
            lower.append(np.tile(m.node_bounds[0], n + 1))
            upper.append(np.tile(m.node_bounds[1], n + 1))
            self.node_slice = _next_slice(lower)
        if m.interval_rows is not None and m.interval_bounds is not None:  # both or neither
            between = ca.Function("between", [xs, us, hs], [m.interval_rows(xs, us, hs)])
            rows.append(ca.vec(between.map(n)(X[:, :-1], U, h_row)))
            lower.append(np.tile(m.interval_bounds[0], n))
            upper.append(np.tile(m.interval_bounds[1], n))
            self.interval_slice = _next_slice(lower)
        for i, end in enumerate(self.ends):
            rows.append(end.rows(X[:, (i + 1) * self.M]))
            lower.append(np.atleast_1d(np.asarray(end.lower, dtype=float)))
            upper.append(np.atleast_1d(np.asarray(end.upper, dtype=float)))
        self.lbg, self.ubg = np.concatenate(lower), np.concatenate(upper)
        first_end = self.lbg.size - sum(np.atleast_1d(e.lower).size for e in self.ends)
        self.end_slice = slice(first_end, self.lbg.size)
        scale = np.maximum(np.abs(m.u_lower), np.abs(m.u_upper))
        scale[scale == 0.0] = 1.0
        regular = 1e-6 * ca.sumsqr(U / ca.DM(scale))
        nlp = {
            "x": ca.vertcat(ca.vec(X), ca.vec(U), T),
            "f": ca.sum1(T) + regular,
            "g": ca.vertcat(*rows),
        }
        options: dict[str, Any] = {
            "print_time": False,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.max_iter": 3000,
            "ipopt.tol": 1e-7,
            "error_on_fail": False,
            # evaluate on scalar expressions: ~30 % less CPU per iteration than MX here
            "expand": True,
        }
        options.update({f"ipopt.{k}": v for k, v in extra.items()})
        self.solver = ca.nlpsol("min_time", "ipopt", nlp, options)
        lower_x = np.tile(m.x_lower[:, None], (1, n + 1)).astype(float)
        upper_x = np.tile(m.x_upper[:, None], (1, n + 1)).astype(float)
        lower_x[:, 0] = upper_x[:, 0] = self.start
        lo_t, hi_t = self.leg_time_range
        self.lbw = np.concatenate(
            [
                lower_x.ravel(order="F"),
                np.tile(m.u_lower, n),
                np.full(self.legs, lo_t),
            ]
        )
        self.ubw = np.concatenate(
            [
                upper_x.ravel(order="F"),
                np.tile(m.u_upper, n),
                np.full(self.legs, hi_t),
            ]
        )

    # -- starts ---------------------------------------------------------------------------
    def initial(self, guess: Guess) -> np.ndarray:
        """The decision vector of ``guess`` on this grid (states and inputs interpolated at
        the nodes, leg durations from its arrival times), clipped to the bounds."""
        nx, nu = self.model.nx, self.model.nu
        arrivals = np.asarray(guess.arrivals, dtype=float)[: self.legs]
        legs = np.maximum(np.diff(np.concatenate([[0.0], arrivals])), self.leg_time_range[0])
        arrivals = np.cumsum(legs)
        node_times = np.concatenate(
            [t0 + legs[i] * np.arange(self.M) / self.M for i, t0 in enumerate(arrivals - legs)]
            + [[arrivals[-1]]]
        )
        states = guess.sample(node_times)[0][:, :nx]
        states[0] = self.start
        inputs = guess.sample(node_times[:-1])[1][:, :nu]
        w0 = np.concatenate([states.ravel(), inputs.ravel(), legs])
        clipped: np.ndarray = np.clip(w0, self.lbw, self.ubw)
        return clipped

    # -- solve --------------------------------------------------------------------------
    def solve(
        self,
        guess: Guess,
        label: str = "guess",
        lbg: np.ndarray | None = None,
        ubg: np.ndarray | None = None,
    ) -> MinimumTime:
        """Solve from one initial guess (``lbg``/``ubg``: other row bounds, e.g. a looser
        tolerance for a continuation step; default: the problem's own)."""
        return self._solve(self.initial(guess), label, lbg, ubg)

    def _solve(
        self,
        w0: np.ndarray,
        label: str,
        lbg: np.ndarray | None = None,
        ubg: np.ndarray | None = None,
    ) -> MinimumTime:
        solution = self.solver(
            x0=w0,
            lbx=self.lbw,
            ubx=self.ubw,
            lbg=self.lbg if lbg is None else lbg,
            ubg=self.ubg if ubg is None else ubg,
        )
        interrupts.raise_pending()  # IPOPT let a Ctrl-C or SIGTERM through as a warning
        stats = self.solver.stats()
        success = bool(stats.get("success", False))
        w = np.asarray(solution["x"], dtype=float).ravel()
        nx, nu, n = self.model.nx, self.model.nu, self.n
        states = w[: nx * (n + 1)].reshape(n + 1, nx)
        inputs = w[nx * (n + 1) : nx * (n + 1) + nu * n].reshape(n, nu)
        legs = w[-self.legs :]
        node_times = np.concatenate([[0.0], np.cumsum(np.repeat(legs / self.M, self.M))])
        return MinimumTime(
            float(legs.sum()),
            legs,
            success,
            node_times,
            states,
            inputs,
            label,
            str(stats.get("return_status", "")),
        )


class MinimumTimeProblem(FreeTimeOCP):
    """The NLP for one set of waypoints (build once per scenario, solve from several starts).

    Args:
        robot: robot with payload; dynamics: the plant model (default: thesis constants).
        waypoints: end-effector targets (m, world) in order.
        start: start state ``[x, y, phi, th1, th2, v, w]`` (at rest).
        intervals_per_leg: M (>= 2; checked by :class:`FreeTimeOCP`).
        stability_min: floor on S; tolerance: waypoint radius (m).
        ipopt_options: extra IPOPT options.
    """

    def __init__(
        self,
        robot: Robot,
        waypoints: Sequence[tuple[float, float]],
        start: Sequence[float] | np.ndarray,
        dynamics: sym.ThesisDynamics | None = None,
        intervals_per_leg: int = 30,
        stability_min: float = STABILITY_FLOOR,
        tolerance: float = 0.01,
        ipopt_options: dict[str, Any] | None = None,
    ) -> None:
        self.robot = robot
        self.dynamics = dynamics or sym.ThesisDynamics.from_robot(robot)
        self.waypoints = [_waypoint(i, w) for i, w in enumerate(waypoints, start=1)]
        self.tolerance = check_positive("tolerance", tolerance)
        self.stability_min = check_stability_floor(stability_min)
        ends = [self._waypoint_end(w) for w in self.waypoints]
        super().__init__(
            thesis_model(robot, self.dynamics, stability_min),
            start,
            ends,
            intervals_per_leg,
            ipopt_options=ipopt_options,
        )

    def _waypoint_end(self, waypoint: tuple[float, float]) -> LegEnd:
        robot = self.robot

        def rows(x: sym.Symbolic) -> sym.Symbolic:
            return ca.sumsqr(sym.forward_kinematics(robot, x[:5])[:2] - ca.DM(waypoint))

        return LegEnd(rows, np.zeros(1), np.array([self.tolerance**2]))

    def row_bounds(
        self, stability_min: float | None = None, tolerance: float | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(lbg, ubg)`` with another S floor and/or waypoint tolerance (m): the rows of a
        continuation step (the problem's own values where None)."""
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        if stability_min is not None:
            other = thesis_model(self.robot, self.dynamics, stability_min)
            for rows, bounds, count in (
                (self.node_slice, other.node_bounds, self.n + 1),
                (self.interval_slice, other.interval_bounds, self.n),
            ):
                if bounds is not None:  # thesis_model gives both
                    lbg[rows], ubg[rows] = np.tile(bounds[0], count), np.tile(bounds[1], count)
        if tolerance is not None:
            ubg[self.end_slice] = check_positive("tolerance", tolerance) ** 2
        return lbg, ubg

    # -- initial guesses ----------------------------------------------------------------
    def straight_line_guess(
        self, speed: float = 0.9, turn_time: float = 1.5, reverse: str = "never", elbow: float = 1.0
    ) -> Guess:
        """Base along the straight legs between the waypoints at ``speed`` (m/s).

        ``reverse``: ``"never"`` (drive forwards), ``"always"`` (backwards) or ``"turn"``
        (per leg, whichever needs the smaller heading change). ``elbow`` (+-1) is the sign
        of th2 in the guess (the arm keeps the start pose's |th2|).
        """
        points = [self.start[:2], *[np.array(w) for w in self.waypoints]]
        arrivals, headings, signs, t = [], [], [], 0.0
        heading_prev = float(self.start[2])
        for a, b in itertools.pairwise(points):
            t += float(np.linalg.norm(b - a)) / speed + turn_time
            arrivals.append(t)
            forward = math.atan2(b[1] - a[1], b[0] - a[0])
            backward = forward + math.pi
            change_f = abs(math.remainder(forward - heading_prev, 2 * math.pi))
            change_b = abs(math.remainder(backward - heading_prev, 2 * math.pi))
            back = reverse == "always" or (reverse == "turn" and change_b < change_f)
            heading = backward if back else forward
            headings.append(heading)
            signs.append(-1.0 if back else 1.0)
            heading_prev = heading
        times = np.linspace(0.0, t, 400)
        states = np.zeros((len(times), sym.NX_FORCE))
        th1, th2 = self.start[3], math.copysign(abs(self.start[4]), elbow)
        for j, tj in enumerate(times):
            leg = min(int(np.searchsorted(arrivals, tj)), self.legs - 1)
            t0 = 0.0 if leg == 0 else arrivals[leg - 1]
            frac = min(1.0, (tj - t0) / (arrivals[leg] - t0))
            a, b = points[leg], points[leg + 1]
            states[j, :2] = a + frac * (b - a)
            states[j, 2] = headings[leg]
            states[j, 3:5] = (th1 if elbow > 0 else -th1), th2
            states[j, 5] = signs[leg] * speed
        states[:, 2] = np.unwrap(states[:, 2])
        return Guess(times, states, np.zeros((len(times), sym.NU_FORCE)), np.array(arrivals))

    def _initial(self, guess: Guess) -> np.ndarray:
        """Kept for callers of the earlier API: :meth:`initial`."""
        return self.initial(guess)


def _next_slice(blocks: list[np.ndarray]) -> slice:
    """The rows of the last block of ``blocks`` in their concatenation."""
    end = sum(b.size for b in blocks)
    return slice(end - blocks[-1].size, end)


def _waypoint(index: int, value: object) -> tuple[float, float]:
    """Waypoint ``value`` as ``(x, y)`` floats (m, world) if it is 2 finite numbers, else a
    :class:`ParameterError` naming ``waypoints[index]`` (from 1, as the bounds tool's)."""
    point = finite_values(value, 2)
    if point is None:
        raise ParameterError(
            f"waypoints[{index}] must be (x, y): 2 finite numbers in m (got {shown(value)})"
        )
    return float(point[0]), float(point[1])


def thesis_model(robot: Robot, dynamics: sym.ThesisDynamics, stability_min: float) -> ShootingModel:
    """The thesis plant's force-level model with its limits as a :class:`ShootingModel`.

    Node rows: the centre of mass in the box of ``S >= stability_min`` (on a support
    polygon other than the rectangle: its offset towards each edge below the edge's bound,
    :func:`~ddwmmr.model.symbolic.stability_edges`) and the wheel speeds; interval rows:
    the same stability rows at ``INTERIOR_CHECKS`` points inside the interval, where the
    joints have moved linearly (constant rates).
    """
    limit = robot.wheel_speed_limit
    edges = sym.stability_edges(robot, stability_min)  # None: the rectangle's box
    x_max, y_max = sym.stability_bounds(robot, stability_min) or (np.inf, np.inf)  # or edges

    def held(q: sym.Symbolic) -> sym.Symbolic:
        """What the stability rows bound: the centre of mass, or its offset towards each
        edge of the support polygon (m)."""
        com = sym.centre_of_mass(robot, q)
        if edges is None:
            return com
        return ca.vertcat(*(n_x * com[0] + n_y * com[1] for n_x, n_y, _, _ in edges))

    def node_rows(x: sym.Symbolic) -> sym.Symbolic:
        return ca.vertcat(held(x[:5]), sym.wheel_speeds(robot, x[5], x[6]))

    def interval_rows(x: sym.Symbolic, u: sym.Symbolic, h: sym.Symbolic) -> sym.Symbolic:
        points = []
        for frac in np.arange(1, INTERIOR_CHECKS + 1) / (INTERIOR_CHECKS + 1):
            moved = ca.vertcat(x[:3], x[3:5] + frac * h * u[2:4])
            points.append(held(moved))
        return ca.vertcat(*points)

    box = np.array([x_max, y_max])
    box_low = -box
    if edges is not None:
        box = np.array([bound for _, _, bound, _ in edges])
        box_low = np.full(box.size, -np.inf)
    rate = min(dynamics.joint_speed, robot.joint_speed_limit)
    (lo1, hi1), (lo2, hi2) = robot.joint_limits
    inf = np.inf
    return ShootingModel(
        nx=sym.NX_FORCE,
        nu=sym.NU_FORCE,
        rhs=dynamics.rhs,
        u_lower=-np.array([dynamics.force_limit, dynamics.force_limit, rate, rate]),
        u_upper=np.array([dynamics.force_limit, dynamics.force_limit, rate, rate]),
        x_lower=np.array([-inf, -inf, -inf, lo1, lo2, -inf, -inf]),
        x_upper=np.array([inf, inf, inf, hi1, hi2, inf, inf]),
        node_rows=node_rows,
        node_bounds=(
            np.concatenate([box_low, [-limit, -limit]]),
            np.concatenate([box, [limit, limit]]),
        ),
        interval_rows=interval_rows,
        interval_bounds=(np.tile(box_low, INTERIOR_CHECKS), np.tile(box, INTERIOR_CHECKS)),
    )


def solve_minimum_time(
    problem: MinimumTimeProblem, guesses: dict[str, Guess] | None = None
) -> MinimumTime:
    """Best successful solution over the straight-line guess and ``guesses``.

    Raises :class:`RuntimeError` if no start converges.
    """
    starts = {
        f"straight-{reverse}-{'up' if elbow > 0 else 'down'}": problem.straight_line_guess(
            reverse=reverse, elbow=elbow
        )
        for reverse in ("never", "turn")
        for elbow in (1.0, -1.0)
    }
    starts.update(guesses or {})
    best: MinimumTime | None = None
    for label, guess in starts.items():
        result = problem.solve(guess, label)
        if result.success and (best is None or result.total < best.total):
            best = result
    if best is None:
        raise RuntimeError("minimum-time OCP: no start converged")
    return best


def minimum_time(
    robot: Robot,
    waypoints: Sequence[tuple[float, float]],
    start: Sequence[float],
    guesses: dict[str, Guess] | None = None,
    **options: Any,
) -> MinimumTime:
    """Minimum time (s) to take the end effector through ``waypoints`` in order from the
    ``start`` state ``[x, y, phi, th1, th2, v, w]`` under the thesis plant's force limits
    and ``S >= stability_min``: the best local optimum over the straight-line starts and
    ``guesses`` (see the module docstring). ``options`` go to :class:`MinimumTimeProblem`."""
    problem = MinimumTimeProblem(robot, waypoints, start, **options)
    return solve_minimum_time(problem, guesses)


def verify(problem: MinimumTimeProblem, result: MinimumTime) -> dict[str, float]:
    """Independent check of a solution by re-integrating its inputs on a fine grid.

    Returns the largest waypoint miss (m, at the leg ends), the smallest S over the fine
    grid and the largest force and joint rate used.
    """
    d, robot = problem.dynamics, problem.robot
    x, u = ca.SX.sym("x", sym.NX_FORCE), ca.SX.sym("u", sym.NU_FORCE)
    h = ca.SX.sym("h")
    step = ca.Function("step", [x, u, h], [sym.rk4_step(d.rhs, x, u, h)])
    state = np.asarray(result.states[0], dtype=float)
    refine = 10
    lowest_s, misses = math.inf, []
    for k, command in enumerate(result.inputs):
        length = (result.times[k + 1] - result.times[k]) / refine
        for _ in range(refine):
            state = np.asarray(step(state, command, length), dtype=float).ravel()
            lowest_s = min(lowest_s, robot.stability(state[:5])[2])
        if (k + 1) % problem.M == 0:
            leg = (k + 1) // problem.M - 1
            xe, ye, _ = robot.fk(state[:5])
            wx, wy = problem.waypoints[leg]
            misses.append(math.hypot(xe - wx, ye - wy))
    return {
        "max_miss_m": float(max(misses)),
        "min_stability": float(lowest_s),
        "max_force_n": float(np.max(np.abs(result.inputs[:, :2]))),
        "max_joint_rate": float(np.max(np.abs(result.inputs[:, 2:]))),
    }
