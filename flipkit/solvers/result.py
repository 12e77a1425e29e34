"""The outcome of one NLP solve, shared by the SQP and the IPOPT cross-check."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from flipkit.errors import InvalidChoiceError


class Status(StrEnum):
    """How a solve ended. A ``StrEnum``: it compares equal to, and is written to plan files
    as, its string value.

    flipkit's own statuses come first; a failed IPOPT solve keeps IPOPT's own return status
    (the ``ApplicationReturnStatus`` names of IPOPT's documentation), so the log and the plan
    file say what IPOPT said.
    """

    SOLVED = "solved"  #: converged and the max scaled violation is within tolerance
    MAX_ITER = "max_iter"  #: SQP: iteration limit
    STALLED = "stalled"  #: SQP: no progress on the merit function (plateau)
    INFEASIBLE = "infeasible"  #: SQP: restoration steps stopped reducing the violation
    QP_SOLVER_ERROR = "qp_solver_error"  #: SQP: OSQP broke down inside a subproblem
    INCONSISTENT_BOUNDS = "inconsistent_bounds"  #: a lower bound above its upper bound
    VIOLATION_ABOVE_TOL = "violation_above_tol"  #: IPOPT converged, our violation check did not
    FATROP_FAILED = "fatrop_failed"  #: FATROP did not report success
    # IPOPT's failure statuses, verbatim.
    INFEASIBLE_PROBLEM_DETECTED = "Infeasible_Problem_Detected"
    SEARCH_DIRECTION_TOO_SMALL = "Search_Direction_Becomes_Too_Small"
    DIVERGING_ITERATES = "Diverging_Iterates"
    USER_REQUESTED_STOP = "User_Requested_Stop"
    FEASIBLE_POINT_FOUND = "Feasible_Point_Found"
    MAXIMUM_ITERATIONS_EXCEEDED = "Maximum_Iterations_Exceeded"
    RESTORATION_FAILED = "Restoration_Failed"
    ERROR_IN_STEP_COMPUTATION = "Error_In_Step_Computation"
    MAXIMUM_CPUTIME_EXCEEDED = "Maximum_CpuTime_Exceeded"
    MAXIMUM_WALLTIME_EXCEEDED = "Maximum_WallTime_Exceeded"
    NOT_ENOUGH_DEGREES_OF_FREEDOM = "Not_Enough_Degrees_Of_Freedom"
    INVALID_PROBLEM_DEFINITION = "Invalid_Problem_Definition"
    INVALID_OPTION = "Invalid_Option"
    INVALID_NUMBER_DETECTED = "Invalid_Number_Detected"
    UNRECOVERABLE_EXCEPTION = "Unrecoverable_Exception"
    NONIPOPT_EXCEPTION_THROWN = "NonIpopt_Exception_Thrown"
    INSUFFICIENT_MEMORY = "Insufficient_Memory"
    INTERNAL_ERROR = "Internal_Error"
    IPOPT_UNKNOWN = "ipopt_unknown"  #: an IPOPT return status not listed above

    @classmethod
    def parse(cls, value) -> "Status":
        """``value`` as a Status.

        Raises:
            InvalidChoiceError: Not a status (the message lists them).
        """
        try:
            return cls(value)
        except ValueError:
            raise InvalidChoiceError("solver status", value, [s.value for s in cls]) from None

    @classmethod
    def from_ipopt(cls, return_status: str) -> "Status":
        """The status of a failed IPOPT solve: IPOPT's own, or :attr:`IPOPT_UNKNOWN`."""
        try:
            return cls(return_status)
        except ValueError:
            return cls.IPOPT_UNKNOWN


@dataclass
class SolveResult:
    """Outcome of a solve: iterate, status, statistics and the iteration log.

    Attributes:
        x: Final iterate Z (unscaled). status: :attr:`Status.SOLVED` or the reason it is not
            (a string is parsed into a :class:`Status`).
        iterations: Solver iterations (SQP: QP solves). wall_time_s: Wall time (s).
        objective: Σu² at x (N²·m²). max_violation: Largest scaled constraint violation.
        solver: Solver name. log: Per-iteration rows. qp_iterations: Total OSQP iterations.
    """

    x: np.ndarray
    status: Status
    iterations: int
    wall_time_s: float
    objective: float
    max_violation: float
    solver: str = "sqp"
    log: list = field(default_factory=list)
    qp_iterations: int = 0

    def __post_init__(self):
        self.status = Status.parse(self.status)

    @property
    def success(self) -> bool:
        return self.status == Status.SOLVED
