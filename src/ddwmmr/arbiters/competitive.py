"""Competitive-dynamics arbiter (Ellekilde & Christensen 2009; docs/thesis.md, "The dynamics").

Instead of a state machine, every behaviour b has a weight ``w_b`` that evolves by the
paper's eq. (3) (after Large, Christensen & Bajcsy 1999)::

    T_b w_b' = a_b w_b - |a_b| w_b^3 - sum_{b' != b} r_{b',b} w_{b'}^2 w_b + noise

``a_b`` is the *competitive advantage* (how much b is wanted now), ``r_{b',b} >= 0`` the
*competitive interaction* (how strongly an active b' suppresses b) and ``T_b`` the time
constant. Fixed points: ``w_b = 0`` is stable when ``a_b < sum r_{b',b} w_{b'}^2`` (b is
suppressed, or not wanted) and ``w_b = +-1`` is stable when ``a_b > 0`` and nothing
suppresses b. The commands are blended by the weights (see :class:`Blend`).

:class:`CompetitiveDynamics` integrates the equation for any advantages and interactions;
:class:`CompetitiveDynamicsArbiter` gives them meaning for the thesis's behaviours.

Integration. Held over one step of length h, the other behaviours' weights make each
equation a Bernoulli equation ``T w' = alpha w - beta w^3`` (``alpha = a_b - sum r w'^2``,
``beta = |a_b|``) whose solution is closed-form: with ``u = w^2``, ``x = 2 alpha h / T``,
``u(h) = alpha u0 / (beta u0 + (alpha - beta u0) e^{-x})`` (the limit ``u0 / (1 + 2 beta
u0 h / T)`` at ``alpha = 0``). Behaviours are updated one after another in priority order,
each seeing the weights already updated (Gauss-Seidel splitting). The update is exact for a
single behaviour and for fixed points of the coupled system, never overshoots a fixed point,
keeps ``|w| <= max(|w0|, 1)`` for any step and any advantage, and is first-order accurate in
the coupling. Explicit Euler is not usable at the controller's 0.01 s: its step factor is
``1 - 2 a h / T`` near ``w = 1`` (-3 for stability, a up to 10, T = 0.05 s) and ``1 - (r - a)
h / T`` for a suppressed weight (-4.5 for the objective under manipulability, r = 12,
T = 0.02 s); it is unstable beyond -1.

Noise. The additive noise is white with intensity ``noise`` (``T dw = (...) dt + noise
dW``), drawn from a ``random.Random(seed)`` that :meth:`reset` re-seeds, so every run is
deterministic per seed. A suppressed weight also never falls below ``floor`` in magnitude:
this is the role the noise plays in the paper (a weight exactly at 0 can never grow again),
so the arbiter works noise-free too. As a guard, ``|w| <= W_LIMIT``.
"""

from __future__ import annotations

import math
import random
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from ddwmmr.arbiters.state_machine import (
    MANIPULABILITY,
    MOVE_ARM,
    MOVE_BASE,
    OBSTACLE,
    STABILITY,
    THESIS_MANIPULABILITY,
    THESIS_STABILITY,
    Hysteresis,
    Selection,
)
from ddwmmr.behaviours.base import Behaviour, Percept, Proposal
from ddwmmr.errors import ParameterError, check_nonnegative, check_positive
from ddwmmr.registry import register_arbiter

#: Behaviours of the arbiter, in priority order (also the order of the weight updates).
BEHAVIOURS = ("stability", "manipulability", "obstacle", "objective")
#: Guard on |w| (the dynamics keep |w| <= 1; only noise can push a weight above 1).
W_LIMIT = 1.5
#: Weights whose square is below this are left out of the blend (not even evaluated).
SHARE_CUTOFF = 1e-3
#: A behaviour becomes dominant (the reported state) when its w^2 is the largest and at
#: least this; while no weight is that large, the previous dominant behaviour stays.
DOMINANT_MIN = 0.25


class CompetitiveDynamics:
    """Weights of n behaviours under the competitive dynamics (paper eq. 3).

    Args:
        time_constants: ``T_b`` (s), one per behaviour.
        noise: noise intensity (``T dw = ... dt + noise dW``); 0 for none.
        seed: noise seed; :meth:`reset` restarts the same sequence.
        floor: smallest |w| kept (a suppressed behaviour stays ready to grow).
    """

    def __init__(
        self,
        time_constants: Sequence[float],
        noise: float = 0.0,
        seed: int = 0,
        floor: float = 1e-3,
    ) -> None:
        if not time_constants:
            raise ParameterError("time_constants: need at least one behaviour")
        self.time_constants = tuple(
            check_positive(f"time_constants[{i}]", t) for i, t in enumerate(time_constants, start=1)
        )
        self.noise = check_nonnegative("noise", noise)
        self.floor = check_nonnegative("floor", floor)
        if self.floor >= 1.0:
            raise ParameterError(f"floor must be < 1 (got {floor:g})")
        self.seed = int(seed)
        self._random = random.Random(self.seed)
        self.w = [self.floor] * len(self.time_constants)

    @property
    def n(self) -> int:
        """Number of behaviours."""
        return len(self.time_constants)

    def reset(self, w0: Sequence[float]) -> None:
        """Restart from weights ``w0`` (each |w| <= W_LIMIT) and restart the noise."""
        if len(w0) != self.n:
            raise ParameterError(f"w0: need {self.n} weights (got {len(w0)})")
        for i, value in enumerate(w0, start=1):
            if not (math.isfinite(value) and abs(value) <= W_LIMIT):
                raise ParameterError(
                    f"w0[{i}] must be in [-{W_LIMIT:g}, {W_LIMIT:g}] (got {value})"
                )
        self.w = [self._floored(float(v)) for v in w0]
        self._random = random.Random(self.seed)

    def step(
        self,
        advantages: Sequence[float],
        interactions: Sequence[Sequence[float]],
        h: float,
        check: bool = True,
    ) -> list[float]:
        """Advance the weights by h seconds; returns them (a new list).

        Args:
            advantages: ``a_b``, one per behaviour (any finite value).
            interactions: ``r[j][i] >= 0``: how strongly behaviour j suppresses i (the
                diagonal is ignored).
            h: step (s, >= 0).
            check: validate the inputs (callers that build them can skip it).
        """
        if check:
            if not h >= 0.0:
                raise ParameterError(f"h must be >= 0 (got {h})")
            _check_inputs(advantages, interactions, self.n)
        w = self.w
        n = self.n
        sigma = self.noise * math.sqrt(h) if h > 0.0 else 0.0
        gauss = self._random.gauss
        for i in range(n):
            pressure = 0.0
            for j in range(n):
                if j != i:
                    pressure += interactions[j][i] * w[j] * w[j]
            a = advantages[i]
            t = self.time_constants[i]
            value = bernoulli_step(w[i], a - pressure, abs(a), h / t)
            if sigma > 0.0:
                value += sigma / t * gauss(0.0, 1.0)
            if value > W_LIMIT:
                value = W_LIMIT
            elif value < -W_LIMIT:
                value = -W_LIMIT
            w[i] = value if abs(value) >= self.floor else self._floored(value)
        return list(w)

    def _floored(self, value: float) -> float:
        if abs(value) >= self.floor:
            return value
        return math.copysign(self.floor, value) if value != 0.0 else self.floor


#: Dimensionless rate (alpha tau, beta w^2 tau) below which a weight step changes nothing.
NEGLIGIBLE_RATE = 1e-18


def bernoulli_step(w0: float, alpha: float, beta: float, tau: float) -> float:
    """Exact solution of ``w' = alpha w - beta w^3`` after ``tau`` (time in units of T).

    ``beta >= 0``; the sign of w is kept and |w| moves monotonically toward
    ``sqrt(alpha / beta)`` (alpha > 0) or 0 (alpha <= 0), never past it.
    """
    u0 = w0 * w0
    if u0 == 0.0 or tau == 0.0:
        return w0
    if abs(alpha) * tau < NEGLIGIBLE_RATE and beta * u0 * tau < NEGLIGIBLE_RATE:
        # |w| would change by a factor 1 + O(1e-18), below double precision; the formulas
        # below would instead lose precision to subnormal products (alpha ~ 1e-313).
        return w0
    x = 2.0 * alpha * tau
    if x > 0.0:  # growth: this form cannot overflow
        u = alpha * u0 / (beta * u0 + (alpha - beta * u0) * math.exp(-x))
    else:  # decay or alpha = 0: u0 E / (1 + beta u0 (E - 1) / alpha)
        growth = math.exp(x)
        g = math.expm1(x) / alpha if alpha != 0.0 else 2.0 * tau  # (E - 1) / alpha >= 0
        u = u0 * growth / (1.0 + beta * u0 * g)
    return math.copysign(math.sqrt(u), w0)


def _check_inputs(
    advantages: Sequence[float], interactions: Sequence[Sequence[float]], n: int
) -> None:
    if len(advantages) != n or len(interactions) != n or any(len(r) != n for r in interactions):
        raise ParameterError(f"advantages and interactions: need {n} and {n}x{n} values")
    total = math.fsum(advantages) + math.fsum(math.fsum(r) for r in interactions)
    if not math.isfinite(total):
        raise ParameterError("advantages and interactions must be finite")
    if min(min(r) for r in interactions) < 0.0:
        raise ParameterError("interactions must be >= 0 (competitive: they only suppress)")


@dataclass(frozen=True)
class CompetitiveParameters:
    """Tuning of :class:`CompetitiveDynamicsArbiter` (advantages dimensionless, T in s).

    Attributes:
        objective: the objective's advantage while there is a waypoint (``-objective``
            when there is none).
        limit: advantages of the fix behaviours saturate at +-``limit``
            (``a = limit tanh(k d / limit)`` for a distance d past a threshold).
        suppression: ``r`` of a higher-priority behaviour on a lower one where the higher
            one must win outright; > ``limit`` (and > ``objective``).
        margin: width (units of S) of the band below the stability enter threshold in which
            stability and the task are blended; the task has stopped ``margin`` below it.
        task_suppression: (low, high) multiples of ``objective``: stability's suppression
            of the task (objective, obstacle avoidance): ``low`` (< 1: they coexist, the task
            goes on at a reduced share) at ``S_enter``, 1 (the task stops) at
            ``S_enter - margin``, ``high`` at ``S_enter - 2 margin`` and below; linear between.
        stability_gain, manipulability_gain: k per unit of S and of eta.
        obstacle_gain: k per metre inside the obstacle behaviour's buffer.
        off: ``-off`` is the advantage of a behaviour that does not apply (manipulability
            while the objective drives, obstacle avoidance while it reaches or when no
            obstacle is in the way).
        time_constants: ``T_b`` (s) by behaviour name.
        noise: noise intensity of eq. (3).
        floor: smallest |w| kept.
    """

    objective: float = 1.0
    limit: float = 10.0
    suppression: float = 12.0
    margin: float = 0.1
    task_suppression: tuple[float, float] = (0.5, 1.5)
    stability_gain: float = 20.0
    manipulability_gain: float = 5.0
    obstacle_gain: float = 20.0
    off: float = 1.0
    time_constants: Mapping[str, float] = field(
        default_factory=lambda: {
            "stability": 0.05,
            "manipulability": 0.1,
            "obstacle": 0.05,
            "objective": 0.02,
        }
    )
    noise: float = 0.002
    floor: float = 0.01

    def __post_init__(self) -> None:
        for name in (
            "objective",
            "limit",
            "margin",
            "stability_gain",
            "manipulability_gain",
            "obstacle_gain",
            "off",
        ):
            check_positive(name, getattr(self, name))
        if not self.suppression > max(self.limit, self.objective):
            raise ParameterError(
                f"suppression must be > limit and > objective (got {self.suppression:g})"
            )
        low, high = self.task_suppression
        if not 0.0 <= low < 1.0 < high:
            raise ParameterError(
                f"task_suppression must satisfy 0 <= low < 1 < high (got {low:g}, {high:g})"
            )
        missing = set(BEHAVIOURS) - set(self.time_constants)
        if missing:
            raise ParameterError(f"time_constants: missing {', '.join(sorted(missing))}")


@dataclass(frozen=True)
class Blend:
    """The competitive arbiter's decision: weights to blend the behaviours' proposals by.

    Attributes:
        state: state of the dominant behaviour (largest |w|), for the metrics: the
            objective reports ``move_base`` / ``move_arm`` by its label.
        behaviour: name of the dominant behaviour.
        shares: blending share of each behaviour to use, ``w_b^2 / max(1, sum w^2)`` over
            the behaviours that have a proposal now and ``w_b^2 >= SHARE_CUTOFF``; they sum
            to at most 1 (the paper's eq. 1 scales commands by the weights; the controller
            gives the rest to braking and holding the arm).
        proposals: the proposals the arbiter evaluated to compute advantages, on the
            percept it was given (the controller evaluates the others).
    """

    state: str
    behaviour: str
    shares: Mapping[str, float]
    proposals: Mapping[str, Proposal]


@register_arbiter("competitive")
class CompetitiveDynamicsArbiter:
    """Competitive dynamics over objective, manipulability, stability, obstacle avoidance.

    Advantages from the percept (``A = limit``, ``k`` the gains of
    :class:`CompetitiveParameters`; ``sat(d) = A tanh(k d / A)``, nearly linear here):

    * stability ``a_S = sat(S_exit - S)``;
    * manipulability ``a_M = sat(eta_exit - eta)`` while the objective reaches with the arm
      (``label == "arm"``, as the state machine only allows it then), else ``-off``;
    * obstacle avoidance ``a_B = sat(buffer - distance)`` for the obstacle in range and
      in the way (the behaviour proposes something) while the objective drives, else ``-off``;
    * objective ``a_O = objective`` while there is a waypoint.

    Interactions (``r[b'][b]``, b' suppresses b), priority stability > manipulability >
    objective, obstacle avoidance replacing the objective's base movement: ``suppression``
    from stability onto manipulability, from manipulability onto the objective and obstacle
    avoidance, from obstacle avoidance onto the objective; every other behaviour suppresses
    stability with ``h_S = sat(S_exit - S_enter)``, the objective and obstacle avoidance
    suppress manipulability with ``h_M = sat(eta_exit - eta_enter)``; stability suppresses
    the task with ``r_T(S)`` (:meth:`task_suppression`).

    What the stability thresholds become (fixed points of the two-behaviour competition
    with the task, ``rho = h_S / a_S``, ``sigma = r_T / a_O``):

    * S > S_enter: ``rho > 1``, stability is suppressed (w_S = 0) and the task runs alone;
    * S_enter - margin < S < S_enter: stability and the task coexist at
      ``w_S^2 = (1 - rho) / (1 - rho sigma)``, ``w_O^2 = (1 - sigma) / (1 - rho sigma)``:
      the task goes on at a falling share while the stability behaviour turns the base; the
      wider the hysteresis band (exit - enter), the more gradually stability comes in
      (``rho = (S_exit - S_enter) / (S_exit - S)``);
    * S < S_enter - margin (``sigma > 1``): the task is suppressed and stability acts alone,
      the state machine's stability state.

    So the stability behaviour is graded in a band of width ``margin`` below its enter
    threshold instead of a bistable switch (the state machine's hysteresis exists to stop
    chattering, which continuous weights do not have); without hysteresis (enter == exit,
    ``rho = 0``) stability takes full weight below the threshold and the task yields as
    sigma grows. Manipulability keeps the thesis's hysteresis as a bistable band: while the
    task runs it takes over when ``a_M > h_M`` (eta < eta_enter) and, having suppressed the
    objective, keeps going until ``a_M < 0`` (eta > eta_exit).

    Args:
        stability, manipulability: the thresholds (as for the state machine).
        parameters: tuning; default :class:`CompetitiveParameters`.
        seed: noise seed.
        record: keep :attr:`history` (every call: time, S, dominant state, weights and
            advantages by behaviour) for plots.
    """

    def __init__(
        self,
        stability: Hysteresis = THESIS_STABILITY,
        manipulability: Hysteresis = THESIS_MANIPULABILITY,
        parameters: CompetitiveParameters | None = None,
        seed: int = 0,
        record: bool = False,
    ) -> None:
        self.stability = stability
        self.manipulability = manipulability
        self.parameters = parameters if parameters is not None else CompetitiveParameters()
        par = self.parameters
        self.dynamics = CompetitiveDynamics(
            [par.time_constants[b] for b in BEHAVIOURS], par.noise, seed, par.floor
        )
        self.record = record
        self.history: dict[str, list[float | str]] = {}
        self._h_stability = self._saturate(par.stability_gain * (stability.exit - stability.enter))
        self._h_manipulability = self._saturate(
            par.manipulability_gain * (manipulability.exit - manipulability.enter)
        )
        self.state = MOVE_BASE
        self.behaviour = "objective"
        self._t: float | None = None
        self.reset()

    @property
    def weights(self) -> dict[str, float]:
        """Current weights by behaviour name."""
        return dict(zip(BEHAVIOURS, self.dynamics.w))

    def reset(self) -> None:
        """Start a new run: the objective at w = 1, the others at the floor; noise restarts."""
        self.dynamics.reset([1.0 if b == "objective" else 0.0 for b in BEHAVIOURS])
        self.state = MOVE_BASE
        self.behaviour = "objective"
        self._t = None
        keys = ("t", "s", "state", *(f"w_{b}" for b in BEHAVIOURS))
        keys += tuple(f"a_{b}" for b in BEHAVIOURS)
        self.history = {k: [] for k in keys} if self.record else {}

    def _saturate(self, d: float) -> float:
        limit = self.parameters.limit
        return limit * math.tanh(d / limit)

    def advantages(
        self, p: Percept, objective: Proposal, avoid: Proposal | None, obstacle: Behaviour | None
    ) -> list[float]:
        """``a_b`` in :data:`BEHAVIOURS` order for percept p (see the class docstring)."""
        par = self.parameters
        reaching = objective.label == "arm"
        a_stab = self._saturate(par.stability_gain * (self.stability.exit - p.s))
        if reaching:
            a_manip = self._saturate(par.manipulability_gain * (self.manipulability.exit - p.eta))
        else:
            a_manip = -par.off
        if avoid is not None and not reaching:
            a_obst = self._saturate(par.obstacle_gain * _inside_buffer(obstacle, p))
        else:
            a_obst = -par.off
        a_obj = par.objective if p.target is not None else -par.objective
        return [a_stab, a_manip, a_obst, a_obj]

    def task_suppression(self, s: float) -> float:
        """Stability's suppression of the objective and obstacle avoidance at stability s.

        ``objective`` x (low at ``S_enter``, 1 at ``S_enter - margin``, high at
        ``S_enter - 2 margin``), piecewise linear, constant outside.
        """
        par = self.parameters
        low, high = par.task_suppression
        depth = (self.stability.enter - s) / par.margin - 1.0  # -1 at enter, 0: task stops
        if depth <= 0.0:
            ratio = 1.0 + (1.0 - low) * max(-1.0, depth)
        else:
            ratio = 1.0 + (high - 1.0) * min(1.0, depth)
        return par.objective * ratio

    def interactions(self, s: float) -> list[list[float]]:
        """``r[j][i]`` (j suppresses i) in :data:`BEHAVIOURS` order, at stability s."""
        big = self.parameters.suppression
        hs, hm = self._h_stability, self._h_manipulability
        task = self.task_suppression(s)
        #         stability manipulability obstacle objective   (suppressed)
        return [
            [0.0, big, task, task],  # stability
            [hs, 0.0, big, big],  # manipulability
            [hs, hm, 0.0, big],  # obstacle
            [hs, hm, 0.0, 0.0],  # objective
        ]

    def weigh(self, p: Percept, behaviours: Mapping[str, Behaviour]) -> Blend:
        """Advance the weights to time ``p.t`` and return the blend for percept p.

        ``behaviours`` maps "objective", "manipulability", "stability" and optionally
        "obstacle" to behaviours; the objective and obstacle avoidance are evaluated here
        (their proposals decide advantages), the others only by the controller if needed.
        """
        objective = behaviours["objective"].propose(p)
        assert objective is not None  # the objective is always on
        obstacle = behaviours.get("obstacle")
        avoid = obstacle.propose(p) if obstacle is not None else None
        a = self.advantages(p, objective, avoid, obstacle)
        h = 0.0 if self._t is None else max(0.0, p.t - self._t)
        self._t = p.t
        w = self.dynamics.w
        if h > 0.0:
            w = self.dynamics.step(a, self.interactions(p.s), h, check=False)
        proposals: dict[str, Proposal] = {"objective": objective}
        if avoid is not None:
            proposals["obstacle"] = avoid
        available = [
            (name, wi * wi)
            for name, wi in zip(BEHAVIOURS, w)
            if name in behaviours and (name != "obstacle" or avoid is not None)
        ]
        leader, leader_w2 = max(available, key=lambda item: item[1])
        current = dict(available).get(self.behaviour, -1.0)
        dominant = leader if leader_w2 >= DOMINANT_MIN or current < 0.0 else self.behaviour
        kept = {name: w2 for name, w2 in available if w2 >= SHARE_CUTOFF}
        total = max(1.0, sum(kept.values()))
        shares = {name: w2 / total for name, w2 in kept.items()}
        self.behaviour = dominant
        self.state = _state_of(dominant, objective)
        if self.record:
            self._remember(p, w, a)
        return Blend(self.state, dominant, shares, proposals)

    def select(self, p: Percept, behaviours: Mapping[str, Behaviour]) -> Selection:
        """Winner-take-all use of the dynamics: the dominant behaviour's proposal alone."""
        blend = self.weigh(p, behaviours)
        proposal = blend.proposals.get(blend.behaviour)
        if proposal is None:
            proposal = behaviours[blend.behaviour].propose(p)
            assert proposal is not None  # fix behaviours are always on
        return Selection(blend.state, blend.behaviour, proposal)

    def _remember(self, p: Percept, w: Sequence[float], a: Sequence[float]) -> None:
        hist = self.history
        hist["t"].append(p.t)
        hist["s"].append(p.s)
        hist["state"].append(self.state)
        for name, wi, ai in zip(BEHAVIOURS, w, a):
            hist[f"w_{name}"].append(wi)
            hist[f"a_{name}"].append(ai)


def _state_of(behaviour: str, objective: Proposal) -> str:
    if behaviour == "objective":
        return MOVE_ARM if objective.label == "arm" else MOVE_BASE
    return {"stability": STABILITY, "manipulability": MANIPULABILITY, "obstacle": OBSTACLE}[
        behaviour
    ]


def _inside_buffer(obstacle: Behaviour | None, p: Percept) -> float:
    """How far (m) the base is inside the obstacle behaviour's buffer of its threat (>= 0)."""
    threat = getattr(obstacle, "threat", None)
    # ObstacleBehaviour.threat's type: (x, y, radius, distance), m
    found: tuple[float, float, float, float] | None = threat(p) if callable(threat) else None
    if found is None:
        return 0.0
    _, _, radius, distance = found
    buffer: float = obstacle.clearance + obstacle.speed_factor * abs(p.v) + obstacle.bubble + radius  # type: ignore[union-attr]
    return max(0.0, buffer - distance)
