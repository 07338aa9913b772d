"""Named option presets: the library's defaults and the slides' configuration.

``make_controller(name, robot, preset="slides", **options)`` starts from the preset's
options for ``name`` and lets explicit ``options`` override them. ``"default"`` is the
library's own choice (the constructors' defaults); ``"slides"`` reproduces the
settings of the DDWMMR simulator slides (Samak & Samak, "Redundancy Resolution" and
"Closed-Loop Resolved Rate Motion Control" pages). Each entry cites where it comes from;
docs/theory.md, "The slides' settings and ours", measures what each difference buys.

Settings the slides do not give keep the library's value in both presets: the time
constants (the slides write ``K_i = 1/tau_i`` without numbers; we use 0.5 s), the damping
near the singularity (the slides invert ``J_aug`` and take ``J^#`` undamped; an undamped
inverse is unbounded at ``cos th1 = 0``, so every preset damps it; docs/theory.md,
"Singularities and damping"),
and the run itself (integrator, step, initial offset: simulation settings, not method
settings). Methods the slides do not describe (``qp`` and later ones) have no entry: every
preset gives them their defaults.
"""

from __future__ import annotations

import math
from typing import Any

from ddwmmr.errors import ParameterError, shown

#: Preset names, the default first.
PRESETS = ("default", "slides")

#: The slides' option values per method, with where each comes from.
SLIDES: dict[str, dict[str, Any]] = {
    # "Pseudoinverse method": qdot = J(q)^# Xdot. Nothing to choose.
    "pi": {},
    # "Augmented task-space method 1": th1dot + th2dot = 0, row [0 0 0 1 1]; the slides'
    # CLRRMC pages use the same row (method 2, th1dot = 0, is our default).
    "ats": {"aux": "sum"},
    # "Artificial potential method": V = 0.66 phi^2 + th1^2 + 0.25 th2^2 (also our default).
    "ap": {"K1": 1.0, "K2": 0.25, "K3": 0.66},
    # "CLRRMC (config space)": J_aug with the row [0 0 0 1 1] builds qdot_d = J^-1 Xd_dot.
    "clrrmc-cs": {"aux": "sum"},
    # "CLRRMC (task space)": J_aug with the row [0 0 0 1 1] and K = diag(K1, K2, 0, 0, 0):
    # no orientation feedback (the slides use K3 = 0), i.e. tau_phi = inf.
    "clrrmc-ts": {"aux": "sum", "tau": (0.5, 0.5, math.inf)},
}

#: The library's choices where they differ from the slides (the constructors' defaults),
#: so that reports can name them; every other option is the same in both presets.
DEFAULT: dict[str, dict[str, Any]] = {
    "pi": {},
    # th1dot = 0 keeps the shoulder at its start angle, far from cos th1 = 0 (docs/theory.md).
    "ats": {"aux": "shoulder"},
    "ap": {"K1": 1.0, "K2": 0.25, "K3": 0.66},
    "clrrmc-cs": {"aux": "shoulder"},
    # Feedback on xE, yE and phiE (tau = 0.5 s each), shoulder row.
    "clrrmc-ts": {"aux": "shoulder", "tau": 0.5},
}

_TABLES = {"default": DEFAULT, "slides": SLIDES}


def check_preset(preset: Any) -> str:
    """``preset`` if it is one of :data:`PRESETS` (a text), else :class:`ParameterError`
    naming ``preset`` and the accepted names (a list or a table too: it is not looked up
    as a key, which would fail unhashable)."""
    if not isinstance(preset, str) or preset not in _TABLES:
        raise ParameterError(f"preset must be one of {', '.join(PRESETS)} (got {shown(preset)})")
    return preset


def preset_options(method: str, preset: str) -> dict[str, Any]:
    """Options of ``preset`` for ``method`` (a copy; empty for methods it does not list)."""
    return dict(_TABLES[check_preset(preset)].get(method, {}))


def preset_differences(method: str) -> dict[str, tuple[Any, Any]]:
    """Options whose slides value differs from the default: name -> (slides, default)."""
    slides, default = SLIDES.get(method, {}), DEFAULT.get(method, {})
    return {
        key: (slides[key], default.get(key))
        for key in slides
        if not _same(slides[key], default.get(key))
    }


def _same(a: Any, b: Any) -> bool:
    """Option values equal, a scalar time constant equal to the same value repeated."""
    if isinstance(a, tuple | list) and not isinstance(b, tuple | list):
        return all(x == b for x in a)
    if isinstance(b, tuple | list) and not isinstance(a, tuple | list):
        return all(a == y for y in b)
    same: bool = a == b  # option values: numbers, texts, None
    return same
