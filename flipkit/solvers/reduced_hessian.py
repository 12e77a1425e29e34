"""The rows' curvature in the condensed subproblem: a damped BFGS estimate in the null space.

The SQP's model is Gauss–Newton: the cost's exact Hessian H (2 on the torques) and no
curvature of the constraint rows. On a flip the rows that decide the step are strongly
curved (the landing, the flight, the cone, the blade heights), so the model over-predicts
the decrease and the line search halves the step. The Lagrangian's Hessian of those rows has
no symbolic form for every block (the arm clearance and the flight have none), so this module
estimates its projection on the condensed subproblem's null space, as reduced-Hessian SQP
methods do (Nocedal & Wright, *Numerical Optimization*, 2nd ed., §18.7; Powell's damping,
§18.3, eq. 18.15).

With the basis B of :class:`~flipkit.solvers.condensed_qp.CondensedQP`, a step satisfying
the linearised equalities is d = d_p + Z w with Z = [−E_B⁻¹E_N; I], so w = d_N, the step of
the free variables: the reduced coordinates are the same from one iteration to the next while
the basis stays. The reduced Hessian B_k = Z_kᵀ H Z_k + M_k (r × r) is updated after every
accepted hard step s (its free part) by damped BFGS with

    y = Z_kᵀ (∇L(Z_{k+1}, λ) − ∇L(Z_k, λ)),   ∇L = ∇J̃ + J̃ᵀλ,

λ the subproblem's row multipliers, and M_{k+1} = B⁺ − Z_kᵀ H Z_k keeps the part H does not
give. Powell's damping keeps B⁺ positive definite where the curvature along s is negative or
small (sᵀy < 0.2 sᵀBs). The QP then minimises ½wᵀ(Zᵀ(H + μ)Z + M)w + …; if that matrix is
not positive definite at the next linearisation (Z changed), the subproblem drops M for that
iteration (:attr:`CondensedQP.curved` is False). A new basis starts from M = 0, and so does
every solve: the estimate never carries over from another solve.
"""

from __future__ import annotations

import numpy as np

DAMPING = 0.2  # Powell: damp when sᵀy < DAMPING · sᵀBs (Nocedal & Wright, eq. 18.15)


class ReducedHessian:
    """The estimate M (r × r) of one solve, tied to the condensed subproblem's basis.

    Args:
        qp: The solve's :class:`~flipkit.solvers.condensed_qp.CondensedQP` (hard form).
    """

    def __init__(self, qp):
        self.qp, self.M, self._basis = qp, None, None

    def _sync(self) -> None:
        """Forget M when the subproblem's basis is not the one M was estimated in."""
        if self.qp.basis is not self._basis:
            self.M, self._basis = None, self.qp.basis

    def curvature(self) -> np.ndarray | None:
        """M for the next subproblem, or None (no estimate yet, or the basis changed since)."""
        self._sync()
        return self.M

    def model_term(self, d: np.ndarray) -> float:
        """½ wᵀ M w of a step d (scaled) of the subproblem just solved, w = d_N; 0 when the
        subproblem did not use M."""
        if self.M is None or not self.qp.curved:
            return 0.0
        w = d[self.qp.free]
        return 0.5 * float(w @ self.M @ w)

    def update(self, s_full: np.ndarray, grad_change: np.ndarray, hess: np.ndarray) -> None:
        """Damped BFGS update along an accepted step.

        Args:
            s_full: The accepted step, scaled (Z_{k+1} − Z_k) / x_scale (n,).
            grad_change: ∇L(Z_{k+1}, λ) − ∇L(Z_k, λ) in scaled units (n,).
            hess: The cost's Hessian diagonal H, scaled (n,), without the proximal weight.
        """
        self._sync()  # pivoted again in this iteration: start afresh
        Z, free = self.qp.Z, self.qp.free
        s, y = s_full[free], Z.T @ grad_change
        base = Z.T @ (hess[:, None] * Z)
        B = base if self.M is None else base + self.M
        Bs = B @ s
        sBs = float(s @ Bs)
        if not (sBs > 0.0 and np.all(np.isfinite(y)) and np.all(np.isfinite(Bs))):
            return  # a zero (or non-finite) step carries no curvature information
        sy = float(s @ y)
        if sy < DAMPING * sBs:  # Powell's damping: y moved toward Bs, sᵀy = DAMPING · sᵀBs
            theta = (1.0 - DAMPING) * sBs / (sBs - sy)
            y = theta * y + (1.0 - theta) * Bs
            sy = float(s @ y)
        self.M = B - np.outer(Bs, Bs) / sBs + np.outer(y, y) / sy - base
