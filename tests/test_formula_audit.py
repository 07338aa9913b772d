"""Formula audit: independent checks of the documented formulas that had none.

Each formula below was, before this file, tested only against itself (the same expression
evaluated twice), against hard-coded numbers of the formula, or not at all. Each check
here is an independent computation: finite differences of a position-level function, a
closed-form solution of the motion the formula describes, a second formulation (SciPy's
convex hull, numpy's SVD and least squares). Every check is a function returning the
largest deviation; its test asserts a tolerance, and a mutation test asserts that the same
check reports a deviation far above that tolerance once the library's formula is
perturbed (a sign flipped, a term dropped), so no check here can pass vacuously.

Sources: docs/theory.md ("Manipulability", "Input form", "Tip-over stability", "Tip-over
while moving: the zero moment point", "Singularities and damping"), docs/qp.md ("Tasks",
"Limits"), docs/thesis.md ("What is simulated").
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from ddwmmr import Robot
from ddwmmr.model import kinematics, stability
from ddwmmr.model.stability import GRAVITY_M_S2, STABILITY_CAP
from ddwmmr.plants import thesis as thesis_plant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits import JointLimit
from ddwmmr.qp.tasks import PostureTask

SEED = 116
DEFAULT = Robot()
HEAVY = Robot().with_payload(3.0)
#: A caster layout whose support polygon is a pentagon, not the footprint rectangle: the
#: wheels (0, +-0.175) and three casters (docs/theory.md, "Tip-over stability").
PENTAGON = Robot(caster_positions=((0.3, 0.0), (-0.3, 0.1), (-0.3, -0.1))).with_payload(3.0)


def hand_fk(q, L1: float, L2: float) -> np.ndarray:
    """End-effector pose (xE, yE, phiE) written from docs/theory.md, not the library's."""
    x, y, phi, th1, th2 = q
    return np.array(
        [
            x + L1 * math.cos(phi + th1) + L2 * math.cos(phi + th1 + th2),
            y + L1 * math.sin(phi + th1) + L2 * math.sin(phi + th1 + th2),
            phi + th1 + th2,
        ]
    )


def hand_qdot(phi: float, u) -> np.ndarray:
    """qdot of a unicycle base with the arm's joint rates: (v cos phi, v sin phi, w, r1, r2)."""
    v, w, r1, r2 = u
    return np.array([v * math.cos(phi), v * math.sin(phi), w, r1, r2])


def hand_jacobian(q, L1: float, L2: float, h: float = 1e-6) -> np.ndarray:
    """4x5 J: central differences of :func:`hand_fk` and the constraint row by hand."""
    q = np.asarray(q, dtype=float)
    columns = [
        (hand_fk(q + h * e, L1, L2) - hand_fk(q - h * e, L1, L2)) / (2 * h) for e in np.eye(5)
    ]
    row = [-math.sin(q[2]), math.cos(q[2]), 0.0, 0.0, 0.0]
    return np.vstack([np.column_stack(columns), row])


# -- manipulability (docs/theory.md, "Manipulability") -----------------------------------


def manipulability_deviation(robot: Robot, n: int = 200) -> float:
    """Largest |eta - |det J_arm| / (L1 L2)| over random poses, J_arm the 2x2 Jacobian of
    the arm's tip in the base frame by central differences (h = 1e-6 rad)."""
    rng = np.random.default_rng(SEED)
    L1, L2, h = robot.L1, robot.L2, 1e-6
    worst = 0.0
    for th1, th2 in rng.uniform(-math.pi, math.pi, (n, 2)):

        def tip(a1: float, a2: float) -> np.ndarray:
            return hand_fk([0.0, 0.0, 0.0, a1, a2], L1, L2)[:2]

        arm = np.column_stack(
            [
                (tip(th1 + h, th2) - tip(th1 - h, th2)) / (2 * h),
                (tip(th1, th2 + h) - tip(th1, th2 - h)) / (2 * h),
            ]
        )
        expected = abs(np.linalg.det(arm)) / (L1 * L2)
        worst = max(worst, abs(robot.manipulability([0.0, 0.0, 0.3, th1, th2]) - expected))
    return worst


def test_manipulability_is_the_arm_jacobians_normalised_determinant():
    """``eta = |sin th2|`` is ``w_m / (L1 L2)`` with ``w_m = |det J_arm|`` (thesis 4.1.1),
    J_arm by finite differences of the arm's forward kinematics; measured 5e-10."""
    assert manipulability_deviation(DEFAULT) < 1e-8
    assert manipulability_deviation(Robot(L1=0.5, L2=0.2)) < 1e-8


def test_mutation_manipulability_check_catches_a_perturbed_formula(monkeypatch):
    monkeypatch.setattr(stability, "manipulability", lambda th2: abs(math.sin(th2 + 0.01)))
    assert manipulability_deviation(DEFAULT) > 1e-3


# -- input form: B(phi), A = J_E B, the projection of qdot (docs/theory.md, "Input form") --


def input_form_deviation(n: int = 100) -> float:
    """Largest deviation over random states of: ``A u`` against the central difference of
    the hand-written forward kinematics along the hand-written unicycle rate; ``B u`` and
    ``qdot_from_u`` against that rate; ``u_from_qdot`` recovering u and the sideways
    speed added to it; ``B^T B = I`` and ``n^T B = 0``."""
    rng = np.random.default_rng(SEED)
    L1, L2, h = DEFAULT.L1, DEFAULT.L2, 1e-6
    worst = 0.0
    for _ in range(n):
        q = rng.uniform(-math.pi, math.pi, 5)
        u = rng.normal(size=4)
        phi = float(q[2])
        qdot = hand_qdot(phi, u)
        numeric = (hand_fk(q + h * qdot, L1, L2) - hand_fk(q - h * qdot, L1, L2)) / (2 * h)
        A = kinematics.end_effector_jacobian_u(L1, L2, q)
        B = kinematics.input_matrix(phi)
        sideways = float(rng.normal())
        normal = np.array([-math.sin(phi), math.cos(phi), 0.0, 0.0, 0.0])
        back, residual = kinematics.u_from_qdot(phi, qdot + sideways * normal)
        worst = max(
            worst,
            float(np.max(np.abs(A @ u - numeric))),
            float(np.max(np.abs(B @ u - qdot))),
            float(np.max(np.abs(kinematics.qdot_from_u(phi, u) - qdot))),
            float(np.max(np.abs(back - u))),
            abs(residual - sideways),
            float(np.max(np.abs(B.T @ B - np.eye(4)))),
            float(np.max(np.abs(normal @ B))),
        )
    return worst


def test_input_form_against_finite_differences_and_the_unicycle():
    """Measured 1e-9 (the central difference's rounding)."""
    assert input_form_deviation() < 1e-8


def _flip_elbow_x(original: Callable) -> Callable:
    def perturbed(L1, L2, q):
        phi, dx, dy, dx2, dy2 = original(L1, L2, q)
        return phi, dx, dy, -dx2, dy2

    return perturbed


def _flip_residual(original: Callable) -> Callable:
    def perturbed(phi, qdot):
        u, residual = original(phi, qdot)
        return u, -residual

    return perturbed


def _swap_input_columns(original: Callable) -> Callable:
    return lambda phi: original(phi)[:, [0, 1, 3, 2]]


@pytest.mark.parametrize(
    ("name", "perturb"),
    [
        ("_arm_rates", _flip_elbow_x),
        ("u_from_qdot", _flip_residual),
        ("input_matrix", _swap_input_columns),
    ],
)
def test_mutation_input_form_check_catches_a_perturbed_formula(monkeypatch, name, perturb):
    monkeypatch.setattr(kinematics, name, perturb(getattr(kinematics, name)))
    assert input_form_deviation() > 1e-2


# -- S on a support polygon that is not the footprint, and its gradient --------------------


def hull_lines(robot: Robot) -> np.ndarray:
    """Outward unit normals and offsets ``(n_x, n_y, d)`` of the hull of the wheels'
    (0, +-track_width/2) and casters' contact points, by SciPy (``n . p <= d`` inside)."""
    points = [(0.0, 0.5 * robot.track_width), (0.0, -0.5 * robot.track_width)]
    points += list(robot.casters)
    equations = ConvexHull(np.array(points)).equations  # a . p + b <= 0 inside, |a| = 1
    return np.column_stack([equations[:, :2], -equations[:, 2]])


def scale_to_edge(robot: Robot, c: np.ndarray) -> float:
    """The factor s by which the centre of mass ``c`` can move away from the base centre
    before it leaves the support polygon (the definition of S), by bisection on SciPy's
    hull, capped at :data:`STABILITY_CAP`."""
    lines = hull_lines(robot)

    def inside(s: float) -> bool:
        return bool(np.all(lines[:, :2] @ (s * c) <= lines[:, 2]))

    if inside(STABILITY_CAP):
        return STABILITY_CAP
    low, high = 0.0, STABILITY_CAP
    for _ in range(100):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if inside(middle) else (low, middle)
    return low


def split_terms(robot: Robot, c: np.ndarray) -> tuple[float, float]:
    """(S_lon, S_lat): the least ``d / (n . c)`` over the hull's edges facing front or
    back (``|n_x| >= |n_y|``), resp. the others, capped (docs/theory.md)."""
    terms = [STABILITY_CAP, STABILITY_CAP]
    for n_x, n_y, d in hull_lines(robot):
        reach = n_x * c[0] + n_y * c[1]
        if reach > 0.0:
            side = 0 if abs(n_x) >= abs(n_y) else 1
            terms[side] = min(terms[side], d / reach)
    return terms[0], terms[1]


def polygon_deviation(robot: Robot, n: int = 150) -> float:
    """Largest relative deviation of ``Robot.stability`` from the bisection (S) and from
    SciPy's edges (S_lon, S_lat), the centre of mass written from the point masses."""
    rng = np.random.default_rng(SEED)
    m1, m2 = robot.link_masses
    total = robot.base_mass + m1 + m2 + robot.payload
    worst = 0.0
    for th1, th2 in rng.uniform(-math.pi, math.pi, (n, 2)):
        elbow = robot.L1 * np.array([math.cos(th1), math.sin(th1)])
        tip = elbow + robot.L2 * np.array([math.cos(th1 + th2), math.sin(th1 + th2)])
        c = (m1 * 0.5 * elbow + m2 * 0.5 * (elbow + tip) + robot.payload * tip) / total
        s_lon, s_lat, s = robot.stability([0.0, 0.0, 0.0, th1, th2])
        lon, lat = split_terms(robot, c)
        worst = max(
            worst,
            abs(s / scale_to_edge(robot, c) - 1.0),
            abs(s_lon / lon - 1.0),
            abs(s_lat / lat - 1.0),
        )
    return worst


@pytest.mark.parametrize("robot", [PENTAGON, HEAVY], ids=["pentagon", "footprint"])
def test_stability_is_the_scale_to_the_support_polygons_edge(robot):
    """S on the caster pentagon (the general polygon path) and on the footprint (the
    rectangle's closed form) against bisection on SciPy's hull; measured 9e-16."""
    assert polygon_deviation(robot) < 1e-9


def polygon_gradient_deviation(robot: Robot, n: int = 200) -> tuple[float, int]:
    """Largest deviation of ``Robot.stability_gradient`` from central differences of
    ``Robot.stability`` (h = 1e-6 rad) and the number of poses checked: those below the
    cap whose least and second least edge ratio are 1 % apart (no kink within h)."""
    rng = np.random.default_rng(SEED)
    lines = hull_lines(robot)
    h, worst, checked = 1e-6, 0.0, 0
    for th1, th2 in rng.uniform(-math.pi, math.pi, (n, 2)):
        c = robot.centre_of_mass([0.0, 0.0, 0.0, th1, th2])
        reach = lines[:, :2] @ c
        ratios = np.sort(lines[reach > 0.0, 2] / reach[reach > 0.0])
        if ratios.size < 2 or ratios[0] >= STABILITY_CAP or ratios[1] < 1.01 * ratios[0]:
            continue

        def s_at(a1: float, a2: float) -> float:
            return robot.stability([0.0, 0.0, 0.0, a1, a2])[2]

        numeric = np.array(
            [
                (s_at(th1 + h, th2) - s_at(th1 - h, th2)) / (2 * h),
                (s_at(th1, th2 + h) - s_at(th1, th2 - h)) / (2 * h),
            ]
        )
        gradient = robot.stability_gradient([0.0, 0.0, 0.0, th1, th2])
        worst = max(worst, float(np.max(np.abs(gradient[3:] - numeric) / (1.0 + abs(numeric)))))
        assert not gradient[:3].any()
        checked += 1
    return worst, checked


def test_stability_gradient_on_a_caster_polygon_matches_finite_differences():
    """Measured 1e-9 over the 198 poses checked."""
    worst, checked = polygon_gradient_deviation(PENTAGON)
    assert checked > 50
    assert worst < 1e-6


def test_mutation_polygon_checks_catch_perturbed_formulas(monkeypatch):
    original_margins = stability.polygon_margins
    original_gradient = stability.polygon_terms_gradient

    def margins(support, x, y):
        s_lon, s_lat, _ = original_margins(support, x, y)
        return s_lon, 1.001 * s_lat, min(s_lon, 1.001 * s_lat)

    def gradient(k, s1, c1, s12, c12):
        lon, lat = original_gradient(k, s1, c1, s12, c12)
        return lon, (lat[0], lat[1], -lat[2])

    monkeypatch.setattr(stability, "polygon_margins", margins)
    assert polygon_deviation(PENTAGON) > 1e-4
    monkeypatch.setattr(stability, "polygon_margins", original_margins)
    monkeypatch.setattr(stability, "polygon_terms_gradient", gradient)
    assert polygon_gradient_deviation(PENTAGON)[0] > 1e-2


# -- the damping's singularity measures (docs/theory.md, "Singularities and damping") ------


def singular_value_ranges(n: int = 4000, l1_in_measure: float = DEFAULT.L1) -> dict:
    """Over random (phi, th1, th2) with |cos th1| > 1e-3, from numpy's SVD of J and of
    ``A = J_E B`` built from the hand-written Jacobian: the documented lower bound
    ``2 sqrt(2) L1 |cos th1| / trace(A A^T)`` over ``sigma_min(A)``, ``sigma_min(J) /
    |cos th1|``, the deviation of ``det(A A^T)`` from ``2 L1^2 cos^2 th1``, and of
    ``sigma_min(J)`` between two headings. ``l1_in_measure`` is the L1 the bound uses."""
    rng = np.random.default_rng(SEED)
    L1, L2 = DEFAULT.L1, DEFAULT.L2
    ratios, slopes, det_error, heading_error = [], [], 0.0, 0.0
    for phi, th1, th2 in rng.uniform(-math.pi, math.pi, (n, 3)):
        cos1 = math.cos(th1)
        if abs(cos1) < 1e-3:
            continue
        J = hand_jacobian([0.0, 0.0, phi, th1, th2], L1, L2)
        A = J[:3] @ np.column_stack([hand_qdot(phi, e) for e in np.eye(4)])
        gram = A @ A.T
        measure = 2.0 * math.sqrt(2.0) * l1_in_measure * abs(cos1) / np.trace(gram)
        ratios.append(measure / np.linalg.svd(A, compute_uv=False)[-1])
        sigma_j = np.linalg.svd(J, compute_uv=False)[-1]
        slopes.append(sigma_j / abs(cos1))
        det_error = max(det_error, abs(np.linalg.det(gram) - 2.0 * (L1 * cos1) ** 2))
        turned = hand_jacobian([0.0, 0.0, phi + 1.0, th1, th2], L1, L2)
        heading_error = max(
            heading_error, abs(np.linalg.svd(turned, compute_uv=False)[-1] - sigma_j)
        )
    return {
        "ratio": (min(ratios), max(ratios)),
        "slope": (min(slopes), max(slopes)),
        "det": det_error,
        "heading": heading_error,
    }


def test_documented_singular_value_figures():
    """docs/theory.md section 4: the pseudoinverse's measure is 0.73-0.88 of the true
    sigma_min(A) (measured 0.7301-0.8798), sigma_min(J) lies between 0.187 |cos th1| and
    0.200 |cos th1| (measured 0.18741-0.19999) and does not depend on phi, and
    det(A A^T) = 2 L1^2 cos^2 th1. The ranges are asserted tight on both sides, so a
    documented range that is off by more than 0.005 (0.001 for the slope) fails."""
    ranges = singular_value_ranges()
    low, high = ranges["ratio"]
    assert 0.73 <= low < 0.735 and 0.875 < high <= 0.88
    low, high = ranges["slope"]
    assert 0.187 <= low < 0.188 and 0.199 < high <= 0.200
    assert ranges["det"] < 1e-8
    assert ranges["heading"] < 1e-8


def test_mutation_singular_value_check_catches_a_perturbed_measure():
    """With L2 in place of L1 in the documented measure the range no longer holds."""
    low, high = singular_value_ranges(n=500, l1_in_measure=DEFAULT.L2)["ratio"]
    assert low < 0.73 or high > 0.88


# -- the zero moment point in a pure spin (docs/theory.md, "Tip-over while moving") --------


def spin_deviation(n: int = 100) -> float:
    """Largest deviation (m) of the zero moment point from ``(1 + h w^2 / g) c``: spinning
    on the spot (v = 0) at a constant rate with the arm still, each mass m at radius r feels
    ``m w^2 r`` outwards at the arm's height h (the base's masses sit on the axis), so the
    centre of pressure moves out by ``h w^2 / g`` times the centre of mass."""
    rng = np.random.default_rng(SEED)
    k, terms = HEAVY.com_coefficients, stability.inertial_terms(HEAVY)
    worst = 0.0
    for th1, th2, w in rng.uniform(-1.0, 1.0, (n, 3)) * [math.pi, math.pi, 3.0]:
        point = stability.zero_moment_point(k, terms, th1, th2, 0.0, 0.0, 0.0, w, 0.0, 0.0)
        factor = 1.0 + HEAVY.arm_height * w * w / GRAVITY_M_S2
        expected = factor * np.array(stability.centre_of_mass(k, th1, th2))
        worst = max(worst, float(np.max(np.abs(np.array(point) - expected))))
    return worst


def test_zero_moment_point_of_a_pure_spin_is_the_scaled_centre_of_mass():
    """Measured 3e-17 m. And the documented example (3 kg, payload out to the side,
    1.5 rad/s): the centripetal term alone takes 1 - 1/(1 + h w^2/g) = 7.43 % off S
    (docs/theory.md says "about 8 %")."""
    assert spin_deviation() < 1e-12
    k, terms = HEAVY.com_coefficients, stability.inertial_terms(HEAVY)
    static = stability.stability_terms(k, math.pi / 2, 0.0)[2]
    spinning = stability.dynamic_stability(k, terms, math.pi / 2, 0.0, 0, 0, 0, 1.5, 0, 0)[2]
    assert 1.0 - spinning / static == pytest.approx(0.0743, abs=5e-4)


def test_mutation_spin_check_catches_a_flipped_centripetal_sign(monkeypatch):
    original = stability.zero_moment_point

    def flipped(k, terms, th1, th2, rate1, rate2, v, w, v_dot, w_dot, *rest, **named):
        # the arm's inertial term with the opposite sign: h M -> -h M
        negated = stability.InertialTerms(terms.height_moment, -terms.arm_moment, terms.weight)
        return original(k, negated, th1, th2, rate1, rate2, v, w, v_dot, w_dot, *rest, **named)

    monkeypatch.setattr(stability, "zero_moment_point", flipped)
    assert spin_deviation() > 1e-3


# -- the joint-position damper (docs/qp.md, "Limits": Joints) ---------------------------------


def damper_deviation(gain: float = 5.0, margin: float = 0.02, duration: float = 1.0) -> float:
    """Largest deviation (rad) of a joint driven at its damper's upper (and, mirrored,
    lower) bound, integrated by RK4 at 1 ms, from the closed form of the velocity damper
    ``dh/dt = -gain h``: ``h(t) = h0 exp(-gain t)``, h the distance to ``limit - margin``.
    Started 0.3 rad short, where ``gain h0 = 1.5 rad/s`` is below the 2 rad/s speed limit.
    Also counts any crossing of ``limit - margin``."""
    robot = Robot(joint_limits=((-1.0, 1.0), (-2.0, 2.0)))
    limit = JointLimit(robot, gain=gain, margin=margin)
    worst, dt = 0.0, 1e-3
    for joint, (low, high) in enumerate(robot.joint_limits):
        for side, start, stop in (
            (1, high - margin - 0.3, high - margin),
            (0, low + margin + 0.3, low + margin),
        ):

            def rate(angle: float, side=side, joint=joint) -> float:
                return limit.joint_bounds(angle, joint)[side]

            angle = start
            for step in range(1, round(duration / dt) + 1):
                k1 = rate(angle)
                k2 = rate(angle + 0.5 * dt * k1)
                k3 = rate(angle + 0.5 * dt * k2)
                k4 = rate(angle + dt * k3)
                angle += dt * (k1 + 2 * k2 + 2 * k3 + k4) / 6.0
                expected = stop - (stop - start) * math.exp(-gain * step * dt)
                crossed = max(0.0, (angle - stop) if side else (stop - angle))
                worst = max(worst, abs(angle - expected), crossed)
    return worst


def test_joint_damper_approaches_its_limit_exponentially():
    """Measured 6e-13 rad (RK4 at 1 ms on a linear ODE)."""
    assert damper_deviation() < 1e-9


def test_mutation_damper_check_catches_a_perturbed_margin(monkeypatch):
    original = JointLimit.joint_bounds

    def loose(self, angle, joint):
        low, high = original(self, angle, joint)
        shift = 2.0 * self.gain * self.margin  # gain (limit + margin - angle): sign flipped
        return low - shift, high + shift

    monkeypatch.setattr(JointLimit, "joint_bounds", loose)
    assert damper_deviation() > 1e-2


# -- the posture task: gradient descent of V (docs/qp.md, "Tasks": Posture) -----------------


def posture_deviation(n: int = 50) -> float:
    """Largest relative deviation of ``dV/dt`` from ``-2 gain V`` under the weighted
    least-squares solution (numpy's lstsq) of the posture task's rows, ``V = K1 th1^2 +
    K2 th2^2 + K3 phi^2``: the rows ask ``(w, th1dot, th2dot) = -gain (phi, th1, th2)``,
    so ``dV/dt = grad V . qdot = -2 gain V`` exactly."""
    rng = np.random.default_rng(SEED)
    K1, K2, K3, gain = 1.0, 0.25, 0.66, 0.7
    task = PostureTask(weight=0.3, K1=K1, K2=K2, K3=K3, gain=gain)
    worst = 0.0
    for q in rng.uniform(-3.0, 3.0, (n, 5)):
        ctx = StepContext(DEFAULT, 0.02)
        ctx.update(0.0, q, np.zeros(3), np.zeros(3))
        jac, error = np.zeros((3, 4)), np.zeros(3)
        task.compute(ctx, jac, error)
        root = np.sqrt(task.row_weights())[:, None]
        u = np.linalg.lstsq(root * jac, root[:, 0] * error, rcond=None)[0]
        qdot = hand_qdot(float(q[2]), u)
        grad = np.array([0.0, 0.0, 2 * K3 * q[2], 2 * K1 * q[3], 2 * K2 * q[4]])
        potential = K1 * q[3] ** 2 + K2 * q[4] ** 2 + K3 * q[2] ** 2
        worst = max(worst, abs(grad @ qdot + 2.0 * gain * potential) / potential)
    return worst


def test_posture_rows_descend_the_potential_at_its_documented_rate():
    """Measured 5e-16."""
    assert posture_deviation() < 1e-12


def test_mutation_posture_check_catches_a_flipped_target(monkeypatch):
    original = PostureTask.targets

    def flipped(self, ctx):
        e0, e1, e2 = original(self, ctx)
        return e0, e1, -e2

    monkeypatch.setattr(PostureTask, "targets", flipped)
    assert posture_deviation() > 1e-2


# -- the damped base's envelope (docs/thesis.md, "What is simulated"; docs/qp.md) -----------


def envelope_deviation() -> float:
    """Largest relative deviation of :meth:`ThesisPlant.velocity_envelope` (fraction 1)
    from the plant's own response to full wheel forces: the terminal speed and yaw rate
    after 60 s, and the acceleration and yaw acceleration from rest over the first 1e-6 s
    with the arm stretched (th2 = 0, the largest yaw inertia)."""
    plant = ThesisPlant(HEAVY)
    envelope = plant.velocity_envelope(fraction=1.0)
    force = plant.force_limit
    measured = {}
    for key, forces, duration, read in (
        ("max_base_speed", (force, force), 60.0, "v"),
        ("max_yaw_rate", (-force, force), 60.0, "w"),
        ("max_acceleration", (force, force), 1e-6, "v"),
        ("max_yaw_acceleration", (-force, force), 1e-6, "w"),
    ):
        state = ThesisState(0.0, 0.0, 0.0, 0.0, 0.0)
        plant.advance(state, *forces, (0.0, 0.0), duration)
        value = getattr(state, read)
        measured[key] = value if duration > 1.0 else value / duration
    return max(abs(envelope[key] / measured[key] - 1.0) for key in measured)


def test_velocity_envelope_is_the_plants_own_limits():
    """2 F / c1, 2 F b / c2, 2 F / m and 2 F b / I(stretched) against the plant;
    measured 1e-6 (the first-order term over 1e-6 s)."""
    assert envelope_deviation() < 1e-5


def test_mutation_envelope_check_catches_a_swapped_damping(monkeypatch):
    original = thesis_plant.damped_base_envelope

    def swapped(force_limit, c1, c2, *rest, **named):
        return original(force_limit, c2, c1, *rest, **named)

    monkeypatch.setattr(thesis_plant, "damped_base_envelope", swapped)
    assert envelope_deviation() > 1e-2
