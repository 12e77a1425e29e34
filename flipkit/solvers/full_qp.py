"""The SQP's convex subproblem, written once in cvxpy (DPP) and solved by OSQP.

In scaled variables d (Z = Z_k + Z_scale ⊙ d) the subproblem at Z_k is

    minimise   gᵀd + ½ dᵀ diag(h) d  [+ ½σ‖s‖²]
    subject to (c + J d − c_lo)[equality rows] = 0        [= s⁺ − s⁻]
               (c + J d − c_lo)[finite lo] ≥ 0,  (c_hi − c − J d)[finite hi] ≥ 0   [+ s ≥ 0]
               d_lo ≤ d ≤ d_hi     (variable bounds ∩ trust box |d|∞ ≤ Δ)

with c, J scaled. h is the cost's exact (diagonal) Hessian plus a small proximal weight, so
with the hard linearised dynamics rows this is the Gauss–Newton model of Σu². The bracketed
slacks form the *elastic* variant, used only when the hard rows are incompatible with the
box (or OSQP fails on them), so that every linearisation still yields a step. Its slacks are
penalised quadratically, a least-squares compromise between the rows: with an ℓ1 term
ρ1ᵀs the QP is LP-like and OSQP hits its iteration cap on the flip segments.

J enters as sparse cvxpy Parameters (one per row group: equalities, finite lower and finite
upper bounds) on the NLP's fixed pattern, so the problem is DPP and is canonicalised once per
structure, quickly (J d written as a dense parameter vector times selection matrices
took a hundred times as long); re-solves only map new parameter values and OSQP
warm-starts. Written as Σ h_k d_k² the Hessian adds no auxiliary variables to the OSQP
problem. Build (:class:`QPSubproblem`) is separate from solve, so the QP can be inspected
alone.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from flipkit.errors import SolverError
from flipkit.solvers.osqp_driver import OSQPDriver, run_osqp
from flipkit.solvers.osqp_status import PolishStatus
from flipkit.solvers.subproblem import QPSolution
from flipkit.transcription.nlp import NLP

class _SparseRows:
    """A sparse cvxpy Parameter holding the Jacobian rows ``rows`` on the NLP's pattern
    (duplicate pattern entries summed)."""

    def __init__(self, nlp: NLP, rows: np.ndarray, name: str):
        rank = np.full(nlp.m, -1)
        rank[rows] = np.arange(len(rows))
        self.entries = np.flatnonzero(rank[nlp.jac_rows] >= 0)
        keys = rank[nlp.jac_rows[self.entries]] * nlp.n + nlp.jac_cols[self.entries]
        unique, self._slot = np.unique(keys, return_inverse=True)
        self._ij = (unique // nlp.n, unique % nlp.n)
        self.shape = (len(rows), nlp.n)
        self.param = cp.Parameter(self.shape, sparsity=self._ij, name=name)

    def set(self, jac: np.ndarray) -> None:
        """Values from the Jacobian entries ``jac`` (pattern order)."""
        vals = np.bincount(self._slot, weights=jac[self.entries], minlength=len(self._ij[0]))
        self.param.value_sparse = sp.coo_array((vals, self._ij), shape=self.shape)


class QPSubproblem:
    """The full-space subproblem (a :class:`~flipkit.solvers.subproblem.Subproblem`) for NLPs sharing one structure (pattern and bound types).

    Args:
        nlp: An NLP of the structure; its values are not used, only the pattern.
        elastic: Build the variant with quadratically penalised slacks on every row.
    """

    def __init__(self, nlp: NLP, elastic: bool = False):
        n, m = nlp.n, nlp.m
        self.elastic, self.m = elastic, m
        eq = nlp.c_lo == nlp.c_hi
        self.eq_rows = np.flatnonzero(eq)
        self.lo_rows = np.flatnonzero(np.isfinite(nlp.c_lo) & ~eq)
        self.hi_rows = np.flatnonzero(np.isfinite(nlp.c_hi) & ~eq)
        self.d = cp.Variable(n, name="d")
        self._jacobians = {key: _SparseRows(nlp, rows, f"jacobian_{key}") for key, rows in
                           (("eq", self.eq_rows), ("lo", self.lo_rows), ("hi", self.hi_rows))}
        Jd = {key: J.param @ self.d for key, J in self._jacobians.items()}
        self.r_eq = cp.Parameter(len(self.eq_rows), name="c_minus_target")
        self.r_lo = cp.Parameter(len(self.lo_rows), name="c_minus_lo")
        self.r_hi = cp.Parameter(len(self.hi_rows), name="hi_minus_c")
        self.grad = cp.Parameter(n, name="gradient")
        self.hess = cp.Parameter(n, nonneg=True, name="hessian_diagonal")
        self.d_lo = cp.Parameter(n, name="d_lo")
        self.d_hi = cp.Parameter(n, name="d_hi")
        self.slack_reg = cp.Parameter(nonneg=True, name="slack_regularisation")
        cons = [self.d >= self.d_lo, self.d <= self.d_hi]
        slacks = []

        def slack(k: int, name: str):
            # Free, not s ≥ 0: with ½σ‖s‖² the optimum has s ≥ 0 on the inequality rows anyway
            # (a negative s only tightens its row), and one free slack per equality row
            # replaces s⁺ − s⁻ at the same optimum: a smaller KKT system, no s ≥ 0 rows.
            if not elastic:
                return 0
            s = cp.Variable(k, name=name)
            slacks.append(s)
            return s

        self.rows = {}
        if len(self.eq_rows):
            self.rows["eq"] = self.r_eq + Jd["eq"] == slack(len(self.eq_rows), "s_eq")
        if len(self.lo_rows):
            self.rows["lo"] = self.r_lo + Jd["lo"] + slack(len(self.lo_rows), "s_lo") >= 0
        if len(self.hi_rows):
            self.rows["hi"] = self.r_hi - Jd["hi"] + slack(len(self.hi_rows), "s_hi") >= 0
        cons += list(self.rows.values())
        obj = self.grad @ self.d + 0.5 * cp.sum(cp.multiply(self.hess, cp.square(self.d)))
        if elastic:
            obj = obj + 0.5 * self.slack_reg * sum(cp.sum_squares(s) for s in slacks)
        self.problem = cp.Problem(cp.Minimize(obj), cons)
        if not self.problem.is_dpp():  # pragma: no cover - a programming error
            raise SolverError("the SQP subproblem must be DPP")

    def update(self, nlp: NLP, c: np.ndarray, jac: np.ndarray, grad: np.ndarray, hess: np.ndarray,
               d_lo: np.ndarray, d_hi: np.ndarray, slack_reg: float = 1e2) -> None:
        """Set the parameter values for a linearisation (all in scaled units).

        Args:
            nlp: The NLP (for its bounds and row scales). c: Scaled constraint values (m,).
            jac: Scaled Jacobian entries on the pattern. grad, hess: Cost gradient and
                Hessian diagonal (with any proximal weight). d_lo, d_hi: Step box.
            slack_reg: Weight σ of ½σ‖s‖² on the elastic slacks.
        """
        for J in self._jacobians.values():
            J.set(jac)
        self.r_eq.value = (c - nlp.c_scale * nlp.c_lo)[self.eq_rows]
        self.r_lo.value = (c - nlp.c_scale * nlp.c_lo)[self.lo_rows]
        self.r_hi.value = (nlp.c_scale * nlp.c_hi - c)[self.hi_rows]
        self.grad.value, self.hess.value = grad, hess
        self.d_lo.value, self.d_hi.value = d_lo, np.maximum(d_hi, d_lo)
        self.slack_reg.value = slack_reg

    def cold(self) -> None:
        """Drop OSQP's warm start and working set (the next solve starts from zero; OSQP's
        setup is kept)."""
        if hasattr(self, "_driver"):
            self._driver.cold()

    def compile(self) -> OSQPDriver:
        """Canonicalise with cvxpy (once) and return the OSQP driver."""
        if not hasattr(self, "_driver"):
            self._driver = OSQPDriver(self.problem)
        return self._driver

    def reset(self) -> None:
        """Forget OSQP's state: the next solve sets OSQP up afresh (no warm start)."""
        if hasattr(self, "_driver"):
            self._driver.reset()

    def solve(self, eps: float | None = None, max_iter: int | None = None) -> QPSolution:
        """Solve with OSQP (:class:`~flipkit.solvers.osqp_driver.OSQPDriver`: persistent solver,
        fixed pattern, warm start, working set of inequality rows).

        Args:
            eps: Absolute/relative tolerance overriding :data:`~flipkit.solvers.osqp_driver.OSQP_SETTINGS`.
            max_iter: ADMM iteration cap overriding :data:`~flipkit.solvers.osqp_driver.OSQP_SETTINGS`.
        """
        res, iterations, status, solved = run_osqp(self.compile(), self.problem, eps, max_iter)
        d = self.d.value if solved else None
        y = np.zeros(self.m)
        # cvxpy's duals: L = f − μᵀ(expr) for `expr ≥ 0` (μ ≥ 0), f + λᵀ(expr) for `expr == 0`.
        for key, rows, sign in (("eq", self.eq_rows, 1.0), ("lo", self.lo_rows, -1.0),
                                ("hi", self.hi_rows, 1.0)):
            con = self.rows.get(key)
            if d is not None and con is not None and con.dual_value is not None:
                y[rows] = sign * np.asarray(con.dual_value)
        return QPSolution(d=np.zeros(self.d.shape) if d is None else np.asarray(d),
                          status=status, iterations=iterations,
                          multipliers=y,
                          polished=res.info.status_polish == PolishStatus.OSQP_POLISH_SUCCESS)
