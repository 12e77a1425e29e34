"""An SQP iterate in scaled units, and the minimum-norm Newton correction onto its rows."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from flipkit.transcription.nlp import NLP


class Iterate:
    """Z with its scaled cost, constraint values, violation and (on first use) the scaled
    Jacobian J̃ = c_scale · ∂c/∂Z · Z_scale on the NLP's pattern.

    Args:
        nlp: The NLP. x: Z (unscaled). jscale: Scale of each Jacobian entry (pattern order).
    """

    def __init__(self, nlp: NLP, x: np.ndarray, jscale: np.ndarray):
        self.x, self._nlp, self._J = x, nlp, None
        self.c, jac = nlp.evaluate(x)
        self.jac = jac * jscale  # scaled entries, pattern order
        self.cs = nlp.c_scale * self.c
        self.f = nlp.objective(x) * nlp.obj_scale
        self.f = self.f if np.isfinite(self.f) else np.inf
        # a row that cannot be evaluated here (NaN: e.g. a landing with no real time of
        # flight) counts as infinitely violated, so that no comparison accepts the point
        self.v = np.nan_to_num(nlp.scaled_violation(self.c), nan=np.inf)
        if not np.all(np.isfinite(self.jac)):  # nor a point without a linear model
            self.v = np.full_like(self.v, np.inf)

    @property
    def J(self) -> sp.csr_matrix:
        if self._J is None:
            n = self._nlp
            self._J = sp.csr_matrix((self.jac, (n.jac_rows, n.jac_cols)), shape=(n.m, n.n))
        return self._J

    @property
    def v_max(self) -> float:
        return float(self.v.max(initial=0.0))

    def merit(self, rho: float) -> float:
        """ℓ1 merit φ = J̃ + ρ‖v‖₁."""
        return self.f + rho * float(self.v.sum())


def _spd_solve(K: sp.spmatrix, b: np.ndarray) -> np.ndarray:
    """K⁻¹b for the Gram matrix K = J_R J_Rᵀ + 1e-12 I: a dense Cholesky, else a sparse LU.

    K is about half full (the Bezier rows share the 42 α columns and the defect rows the
    duration T), so the dense Cholesky is the faster, about twice SuperLU's speed on the
    520–590 rows of a Table I chain. When K is not numerically
    positive definite (dependent rows) the sparse LU solves it as before.
    """
    try:
        factor = sla.cho_factor(K.toarray(), check_finite=False)
    except np.linalg.LinAlgError:
        return spla.spsolve(K.tocsc(), b)
    return sla.cho_solve(factor, b, check_finite=False)


def newton_correction(nlp: NLP, p: Iterate, active: np.ndarray | None = None) -> np.ndarray:
    """Minimum-norm Newton step (scaled) onto the equalities and violated inequalities:
    Δ = −J_Rᵀ(J_R J_Rᵀ)⁻¹ r_R, r the scaled residual to the nearest bound, over the variables
    strictly inside their bounds (J_R's other columns dropped; those variables stay put).

    Args:
        nlp: The NLP. p: The point to correct.
        active: Optional (m,) side of each inequality row active in the subproblem that
            produced ``p`` (+1 at its upper bound, −1 at its lower bound, 0 inactive). These
            rows are held at that bound too: the second-order correction of a step keeps the
            step's active set. Without them, the correction of the rows the step violated
            pushes the rows it left exactly at their bounds — the landing disc and the cone
            at the flip's optimum — out by as much, and the summed violation grows.
    """
    lo, hi = nlp.c_scale * nlp.c_lo, nlp.c_scale * nlp.c_hi
    r = p.cs - np.clip(p.cs, lo, hi)
    rows = (nlp.c_lo == nlp.c_hi) | (r != 0)
    if active is not None:
        held = (active != 0) & ~rows
        bound = np.where(active > 0, hi, lo)
        r = np.where(held & np.isfinite(bound), p.cs - bound, r)
        rows |= held & np.isfinite(bound)
    rows = np.flatnonzero(rows)
    # Variables fixed or at a bound do not move: a correction through them is clipped away
    # by the projection and breaks the rows it fixed (a q̈ on its bound moved and clipped back
    # leaves the dynamics rows violated, and the SQP cycles).
    span = np.maximum(nlp.x_ub - nlp.x_lb, 0.0)
    tight = 1e-9 * np.maximum(np.abs(p.x), 1.0)
    free = np.flatnonzero((span > tight) & (p.x - nlp.x_lb > tight) & (nlp.x_ub - p.x > tight))
    JR = p.J[rows][:, free]
    K = JR @ JR.T + 1e-12 * sp.identity(len(rows))
    delta = np.zeros(nlp.n)
    delta[free] = -(JR.T @ _spd_solve(K, r[rows]))
    return np.where(np.isfinite(delta), delta, 0.0)
