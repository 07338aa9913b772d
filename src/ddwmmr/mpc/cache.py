"""The OCPs the ``mpc`` controllers share: built once per problem and thread, kept a while.

Building an OCP and its solvers' QP functions costs more than a short scenario's steps
(docs/mpc.md, "Integration notes"). The OCP is symbolic and keeps no state of a run, so
every controller that asks for the same one may use it.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Hashable

from ddwmmr.model import Robot
from ddwmmr.mpc.models import PredictionModel
from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP

#: Most OCPs kept for reuse by :func:`shared_ocp`. A run uses one or two (the lookahead
#: adds the one through the next waypoint); the bounds search's mpc runs (with lookahead,
#: following the plan, with margins, arriving as it does) use eight, the same for every
#: scenario, so a worker's scenarios rebuild none. A waypoint OCP with its QP solvers
#: holds about 12 MB.
SHARED_OCPS = 8
_OCPS: OrderedDict[tuple[int, Robot, Hashable, OCPConfig], ShootingOCP] = OrderedDict()
_OCPS_LOCK = threading.Lock()


def shared_ocp(
    robot: Robot, choice: Hashable, model: PredictionModel, config: OCPConfig
) -> ShootingOCP:
    """The OCP of ``robot``, the model ``choice`` (what ``model`` was made from: its name,
    options and base facts) and ``config``: built once and shared by every controller that
    asks for the same one, the least recently used dropped beyond :data:`SHARED_OCPS`.
    Shared within a thread only: a solver reads its QP's statistics after the call, which
    another thread's call on the same function could replace."""
    key = (threading.get_ident(), robot, choice, config)
    try:
        hash(key)
    except TypeError:  # an unhashable option from somewhere: build it, do not share
        return ShootingOCP(robot, model, config)
    with _OCPS_LOCK:
        ocp = _OCPS.get(key)
        if ocp is not None:
            _OCPS.move_to_end(key)
            return ocp
    ocp = ShootingOCP(robot, model, config)  # outside the lock: it takes a while
    with _OCPS_LOCK:
        _OCPS[key] = ocp
        if len(_OCPS) > SHARED_OCPS:
            _OCPS.popitem(last=False)
    return ocp


def clear() -> None:
    """Forget every shared OCP (tests, or to free their memory)."""
    with _OCPS_LOCK:
        _OCPS.clear()
