"""QP task-priority control: tasks, limits, the stacked problem and its solver.

Layout (modelled on mink / pink): :mod:`ddwmmr.qp.tasks` holds soft objectives,
:mod:`ddwmmr.qp.limits` hard constraints; :class:`QPProblem` stacks them into
preallocated arrays and :func:`solve` hands them to a qpsolvers backend. The controller
using them is method ``qp`` (:mod:`ddwmmr.qp.controller`).
"""

from ddwmmr.qp.context import NU, StepContext
from ddwmmr.qp.problem import QPProblem
from ddwmmr.qp.solve import MODES, make_backend, solve

__all__ = ["MODES", "NU", "QPProblem", "StepContext", "make_backend", "solve"]
