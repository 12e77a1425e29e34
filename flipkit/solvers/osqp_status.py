"""OSQP's result statuses by name.

:class:`OSQPStatus` is osqp-python's own enumeration (``osqp.SolverStatus``: ``OSQP_SOLVED``,
``OSQP_PRIMAL_INFEASIBLE``, …), compared with a result's ``info.status_val``. The polishing
status has no Python enumeration in osqp-python; :class:`PolishStatus` names the values of
OSQP's C API (``osqp_api_constants.h``) that a result's ``info.status_polish`` takes.
"""

from __future__ import annotations

from enum import IntEnum

from osqp import SolverStatus as OSQPStatus

__all__ = ["OSQPStatus", "PolishStatus", "SOLVED", "UNPACKED"]


class PolishStatus(IntEnum):
    """``info.status_polish`` of an OSQP result (OSQP's C API names)."""

    OSQP_POLISH_FAILED = -1  #: polishing was tried and did not improve the ADMM solution
    OSQP_POLISH_NOT_PERFORMED = 0  #: polishing off, or no solution to polish
    OSQP_POLISH_SUCCESS = 1  #: the solution is the exact solution of the active set


SOLVED = frozenset({OSQPStatus.OSQP_SOLVED, OSQPStatus.OSQP_SOLVED_INACCURATE})
"""Statuses that carry a primal–dual solution."""

UNPACKED = SOLVED | {OSQPStatus.OSQP_PRIMAL_INFEASIBLE,
                     OSQPStatus.OSQP_PRIMAL_INFEASIBLE_INACCURATE}
"""Statuses whose result cvxpy unpacks onto a problem (on the others it raises): a solution
or a certificate of primal infeasibility."""
