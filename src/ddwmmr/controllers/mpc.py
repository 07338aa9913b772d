"""Method ``mpc``: nonlinear model predictive control with CasADi (issue 11, docs/mpc.md).

Receding-horizon optimal control by multiple shooting: the trajectory's future poses are
the reference (tracking), or the waypoint is reached as early as possible (waypoint mode,
a free-final-time horizon). Tip-over stability ``S >= stability_min + stability_margin``
(the margin 0.01 by default) is a hard constraint
at every node in its exact nonlinear form; wheel-speed, joint-speed, joint-limit and
obstacle constraints likewise; manipulability is a soft cost. The previous solution,
shifted, warm-starts one Gauss-Newton iteration per step (the real-time iteration) with the
structure-exploiting QP solver HPIPM::

    make_controller("mpc", Robot())    # kinematic model (run on MuJoCo: the force model)
    make_controller("mpc", Robot().with_payload(3.0), model="thesis",
                    track_orientation=False)                          # wheel forces

With ``model="thesis"`` the controller declares ``interface = "force"`` and
``wants_base_velocity = True``: ``command(t, q, pose_d, velocity_d, base_velocity=(v, w))``
returns :class:`ddwmmr.commands.WheelForces`. Every ``mpc`` controller is a sampled-data
controller (``zero_order_hold = True``): one call per control step, the command held over
the step.

``summarize`` adds to the run summary, among others, ``stability_min``,
``stability_violations`` (recorded steps with S < floor), ``mpc_fallbacks`` (steps that
used the ``qp`` fallback), ``mpc_brakes`` (braking steps), ``mpc_model``, ``mpc_solver``;
the full list is in docs/mpc.md, "Options".
"""

from __future__ import annotations

from ddwmmr.controllers.base import register
from ddwmmr.mpc.controller import MPCControllerCore


@register("mpc")
class MPCController(MPCControllerCore):
    """Nonlinear MPC: multiple shooting, hard exact S >= S_min, soft manipulability, preview."""

    #: ~0.5 ms a step: ranked in the comparison, left out of its studies by default
    #: (``--study-methods mpc`` adds it).
    in_studies = False


__all__ = ["MPCController"]
