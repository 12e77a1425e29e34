"""The SQP's subproblem interface: the protocol both QP forms follow, and their solution.

Two forms state the same convex subproblem (:mod:`flipkit.solvers.full_qp`):

* **full** (:class:`~flipkit.solvers.full_qp.QPSubproblem`): every variable, the linearised
  equality rows kept as rows; with ``elastic=True`` every row gets slacks (the restoration
  step);
* **condensed** (:class:`~flipkit.solvers.condensed_qp.CondensedQP`): the equality rows
  eliminated with a sparse LU, leaving the step in their null space (19–31 variables); with
  ``elastic=True`` the inequality rows get slacks (the restoration step, equalities hard).

:mod:`flipkit.solvers.compiled` keeps one compiled instance per NLP structure and form.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from flipkit.transcription.nlp import NLP


@dataclass
class QPSolution:
    """d (scaled step), OSQP status and iterations, and the row multipliers y (m,) in scaled
    row units with ∇(gᵀd + ½dᵀHd) + Jᵀy + (box multipliers) = 0 at the solution: y ≥ 0 on an
    active upper bound, ≤ 0 on an active lower bound, free on an equality."""

    d: np.ndarray
    status: str
    iterations: int
    multipliers: np.ndarray
    polished: bool = False


class Subproblem(Protocol):
    """What the SQP asks of a subproblem: set the linearisation, solve, forget state.

    Attributes:
        elastic: True for the restoration forms (slacks on every row in full space, on the
            inequality rows in condensed form).
    """

    elastic: bool

    def update(self, nlp: NLP, c: np.ndarray, jac: np.ndarray, grad: np.ndarray,
               hess: np.ndarray, d_lo: np.ndarray, d_hi: np.ndarray,
               slack_reg: float = 1e2) -> None:
        """Set the parameter values of a linearisation (scaled units)."""

    def solve(self, eps: float | None = None, max_iter: int | None = None) -> QPSolution:
        """Solve with OSQP (warm-started) and return the step and row multipliers."""

    def cold(self) -> None:
        """Drop OSQP's warm start and working set (the next solve starts from zero)."""

    def reset(self) -> None:
        """Forget every state kept between solves (OSQP's, and a condensed basis)."""
