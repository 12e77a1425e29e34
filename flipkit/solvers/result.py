"""The outcome of one NLP solve, shared by the SQP and the IPOPT cross-check."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class SolveResult:
    """Outcome of a solve: iterate, status, statistics and the iteration log.

    Attributes:
        x: Final iterate Z (unscaled). status: ``solved`` or the reason it is not.
        iterations: Solver iterations (SQP: QP solves). wall_time_s: Wall time (s).
        objective: Σu² at x (N²·m²). max_violation: Largest scaled constraint violation.
        solver: Solver name. log: Per-iteration rows. qp_iterations: Total OSQP iterations.
    """

    x: np.ndarray
    status: str
    iterations: int
    wall_time_s: float
    objective: float
    max_violation: float
    solver: str = "sqp"
    log: list = field(default_factory=list)
    qp_iterations: int = 0

    @property
    def success(self) -> bool:
        return self.status == "solved"
