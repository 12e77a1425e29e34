"""The SQP's convex subproblem, written once in cvxpy (DPP) and solved by OSQP.

In scaled variables d (Z = Z_k + Z_scale ⊙ d) the subproblem at Z_k is

    minimise   gᵀd + ½ dᵀ H d + ρ (1ᵀ s_lo + 1ᵀ s_hi)
    subject to (c + J d − c_lo)[equality rows] = 0
               (c + J d − c_lo)[finite lo] ≥ 0,  (c_hi − c − J d)[finite hi] ≥ 0
               d_lo ≤ d ≤ d_hi     (variable bounds ∩ trust box |d| ≤ Δ)

with c, J scaled. The linearised constraints are hard (OSQP treats equality rows with its
larger step parameter) unless they are incompatible with the bounds, when the *elastic*
variant with ℓ1-penalised slacks s on every row (and ½σ‖s‖²) is used, so that every
linearisation still yields a step. A proximal term ½μ‖d‖² makes the QP strongly convex:
without it, and with slacks on every row, OSQP (ADMM) needs thousands of iterations on this
LP-like structure; hard rows and the proximal term bring it to tens or hundreds. J enters as a
parameter vector of its nonzeros on the NLP's fixed pattern: J d = S_r (j ⊙ S_c d), with
constant selection matrices S_c, S_r, so the problem is DPP and is canonicalised once;
re-solves only update parameter values and OSQP warm-starts from the previous solution.
Build (:class:`QPSubproblem`) is separate from solve, so the QP can be inspected alone.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from .nlp import NLP

# Tolerances 1e-4 with solution polishing: polishing makes a solve exact once the active
# set is found, and looser ADMM tolerances cut OSQP iterations ~4x (measured).
# Deterministic OSQP: a fixed adaptive-rho interval (interval 0 would time the setup and
# adapt rho after a fraction of it, which varies run to run; OSQP 1.x rejects fraction 0).
OSQP_SETTINGS = dict(eps_abs=1e-4, eps_rel=1e-4, max_iter=4000, adaptive_rho_interval=25,
                     polishing=True, polish_refine_iter=5,
                     check_termination=25, verbose=False)


@dataclass
class QPSolution:
    """d (scaled step), the model's penalised objective value, OSQP status and iterations."""

    d: np.ndarray
    model_value: float
    linear_violation: float
    status: str
    iterations: int
    eq_duals: np.ndarray | None = None


class QPSubproblem:
    """The convex subproblem for NLPs sharing one structure (pattern and bound types).

    Args:
        nlp: An NLP of the structure; its values are not used, only the pattern.
    """

    def __init__(self, nlp: NLP, elastic: bool = False):
        n, m, nnz = nlp.n, nlp.m, len(nlp.jac_rows)
        self.elastic = elastic
        self.key = nlp.structure_key
        eq = nlp.c_lo == nlp.c_hi
        self.eq_rows = np.flatnonzero(eq)
        self.lo_rows = np.flatnonzero(np.isfinite(nlp.c_lo) & ~eq)
        self.hi_rows = np.flatnonzero(np.isfinite(nlp.c_hi) & ~eq)
        S_c = sp.csr_matrix((np.ones(nnz), (np.arange(nnz), nlp.jac_cols)), shape=(nnz, n))
        S_r = sp.csr_matrix((np.ones(nnz), (nlp.jac_rows, np.arange(nnz))), shape=(m, nnz))
        self.d = cp.Variable(n, name="d")
        self.jac = cp.Parameter(nnz, name="jacobian")
        self.r_eq = cp.Parameter(len(self.eq_rows), name="c_minus_target")
        self.r_lo = cp.Parameter(len(self.lo_rows), name="c_minus_lo")
        self.r_hi = cp.Parameter(len(self.hi_rows), name="hi_minus_c")
        self.grad = cp.Parameter(n, name="gradient")
        self.d_lo = cp.Parameter(n, name="d_lo")
        self.d_hi = cp.Parameter(n, name="d_hi")
        self.rho = cp.Parameter(nonneg=True, name="penalty")
        self.slack_reg = cp.Parameter(nonneg=True, name="slack_regularisation")
        self.hess_sqrt = cp.Parameter(n, nonneg=True, name="hessian_sqrt")
        # Curvature of the Lagrangian on per-node blocks: ½‖F d‖², F stacked factors
        # F_i (b x b, on the block's variables) with H_i = F_iᵀF_i ⪰ 0, as a parameter on
        # a fixed pattern (the same selection trick as the Jacobian).
        self.blocks = [np.asarray(b, int) for b in nlp.curvature_blocks]
        f_rows = np.concatenate([np.repeat(np.arange(len(b)) + sum(map(len, self.blocks[:k])), len(b))
                                 for k, b in enumerate(self.blocks)]) if self.blocks else np.zeros(0, int)
        f_cols = np.concatenate([np.tile(b, len(b)) for b in self.blocks]) if self.blocks else np.zeros(0, int)
        nf = len(f_cols)
        self.factor = cp.Parameter(nf, name="curvature_factor")
        F_c = sp.csr_matrix((np.ones(nf), (np.arange(nf), f_cols)), shape=(nf, n))
        F_r = sp.csr_matrix((np.ones(nf), (f_rows, np.arange(nf))),
                            shape=(int(f_rows.max(initial=-1)) + 1, nf))
        Fd = F_r @ cp.multiply(self.factor, F_c @ self.d)
        Jd = cp.multiply(self.jac, S_c @ self.d)
        cons = [self.d >= self.d_lo, self.d <= self.d_hi]
        slacks = []

        def slack(k: int, name: str):
            if not elastic:
                return 0
            s = cp.Variable(k, nonneg=True, name=name)
            slacks.append(s)
            return s

        self.eq_constraint = None
        if len(self.eq_rows):
            k = len(self.eq_rows)
            self.eq_constraint = self.r_eq + S_r[self.eq_rows] @ Jd == slack(k, "s_plus") - slack(k, "s_minus")
            cons.append(self.eq_constraint)
        if len(self.lo_rows):
            cons.append(self.r_lo + S_r[self.lo_rows] @ Jd + slack(len(self.lo_rows), "s_lo") >= 0)
        if len(self.hi_rows):
            cons.append(self.r_hi - S_r[self.hi_rows] @ Jd + slack(len(self.hi_rows), "s_hi") >= 0)
        obj = self.grad @ self.d + 0.5 * cp.sum_squares(cp.multiply(self.hess_sqrt, self.d))
        if nf:
            obj = obj + 0.5 * cp.sum_squares(Fd)
        if elastic:
            obj = obj + self.rho * sum(cp.sum(s) for s in slacks) \
                + 0.5 * self.slack_reg * sum(cp.sum_squares(s) for s in slacks)
        self.problem = cp.Problem(cp.Minimize(obj), cons)
        self._slacks = slacks
        if not self.problem.is_dpp():  # pragma: no cover - a programming error
            raise RuntimeError("the SQP subproblem must be DPP")

    def update(self, nlp: NLP, c: np.ndarray, jac: np.ndarray, grad: np.ndarray, hess: np.ndarray,
               d_lo: np.ndarray, d_hi: np.ndarray, rho: float, slack_reg: float = 1e-2,
               curvature: list[np.ndarray] | None = None) -> None:
        """Set the parameter values for a linearisation (all in scaled units).

        ``curvature``: per block of ``nlp.curvature_blocks`` a PSD matrix (scaled units);
        None means zero.
        """
        if curvature is None:
            self.factor.value = np.zeros(self.factor.shape)
        else:
            parts = []
            for H in curvature:
                w, V = np.linalg.eigh(0.5 * (H + H.T))
                parts.append((np.sqrt(np.maximum(w, 0.0))[:, None] * V.T).ravel())
            self.factor.value = np.concatenate(parts)
        self.jac.value = jac
        self.r_eq.value = (c - nlp.c_scale * nlp.c_lo)[self.eq_rows]
        self.r_lo.value = (c - nlp.c_scale * nlp.c_lo)[self.lo_rows]
        self.r_hi.value = (nlp.c_scale * nlp.c_hi - c)[self.hi_rows]
        self.grad.value, self.hess_sqrt.value = grad, np.sqrt(hess)
        self.d_lo.value, self.d_hi.value, self.rho.value = d_lo, d_hi, rho
        self.slack_reg.value = slack_reg

    def reset(self) -> None:
        """Forget OSQP's state: the next solve sets up afresh (no warm start)."""
        self.problem._solver_cache.clear()

    def solve(self, eps: float | None = None) -> QPSolution:
        """Solve with OSQP, warm-started from the previous solve of this problem.

        Args:
            eps: Absolute/relative tolerance overriding :data:`OSQP_SETTINGS` (for a final,
                accurate solve).
        """
        settings = dict(OSQP_SETTINGS)
        if eps is not None:
            settings.update(eps_abs=eps, eps_rel=eps)
        with warnings.catch_warnings():  # inaccurate solves are reported through the status
            warnings.simplefilter("ignore", UserWarning)
            self.problem.solve(solver=cp.OSQP, warm_start=True, **settings)
        stats = self.problem.solver_stats
        d = self.d.value
        if d is None:
            d = np.zeros(self.d.shape)
        return QPSolution(d=np.asarray(d), model_value=float(self.problem.value or np.inf),
                          linear_violation=float(sum(np.sum(s.value) for s in self._slacks
                                                     if s.value is not None)),
                          status=str(self.problem.status), iterations=int(stats.num_iters or 0),
                          eq_duals=None if self.eq_constraint is None or self.eq_constraint.dual_value
                          is None else np.asarray(self.eq_constraint.dual_value))


_CACHE: dict[tuple[str, bool], QPSubproblem] = {}


def subproblem_for(nlp: NLP, elastic: bool = False) -> QPSubproblem:
    """The compiled subproblem for the NLP's structure, built on first use and then reused."""
    key = (nlp.structure_key, elastic)
    qp = _CACHE.get(key)
    if qp is None:
        qp = _CACHE[key] = QPSubproblem(nlp, elastic)
    return qp
