"""The condensed SQP subproblem: the hard QP in the null space of its equality rows, in cvxpy,
solved by OSQP.

The equality rows of a segment (dynamics, Hermite–Simpson defects, Bezier outputs, endpoint
states: 516–528 of 547 variables) leave a null space of only 19–31 dimensions, where the condensed problem lives. Split the
variables into basic B and free N columns of the scaled equality Jacobian E = [E_B E_N]
(E_B square and nonsingular, chosen by a pivoted LU of Eᵀ); every step that satisfies the
linearised equalities E d = −r_E is then

    d = d_p + Z w,   Z = [−E_B⁻¹E_N; I],   d_p = [−E_B⁻¹ r_E; 0]     (B rows first)

With RᵀR = Zᵀ diag(h) Z (Cholesky, r × r; + M, the rows' curvature estimated by
:mod:`flipkit.solvers.reduced_hessian`, when the SQP passes one) and T = Z R⁻¹, w = R⁻¹v and
the subproblem of :mod:`flipkit.solvers.full_qp` becomes

    minimise ½‖v‖² + g_vᵀv   s.t.  lo ≤ [J_I T; T] v ≤ hi

with g_v = Tᵀ(g + h ⊙ d_p) and the inequality rows J_I and the step box d_lo ≤ d ≤ d_hi
shifted by d_p. OSQP sees an identity Hessian and no equality rows: the linearised equalities
hold to the accuracy of a sparse LU solve whatever its ADMM tolerance, and its iterations are
spent on the active inequality rows, and an infeasible linearisation is detected where the
full-space QP runs out of iterations.

Multipliers of the equality rows, which the SQP's penalty update needs, are recovered from the
full-space stationarity condition restricted to B: E_Bᵀ y_E = −(g + h ⊙ d + J_Iᵀy_I + y_box)_B.

Elastic form (``elastic=True``, the SQP's restoration step): the inequality rows get slacks
penalised by ½σ‖s‖², the equality rows stay hard and are eliminated as above, and the step box
stays hard:

    minimise ½‖v‖² + g_vᵀv + ½σ(‖s_lo‖² + ‖s_hi‖²)   s.t.  J_I T v + s_lo ≥ lo,  J_I T v − s_hi ≤ hi,
                                                          box_lo ≤ T v ≤ box_hi

The full-space elastic QP (:mod:`flipkit.solvers.full_qp`) also softens the equality rows; it
stays the fallback when the hard equalities and the box are incompatible. The full-space
restoration QP runs ADMM on ~550 variables, their slacks and every row, and costs an order of
magnitude more than the condensed one (docs/history.md).
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from flipkit.errors import ConfigError, SingularBasisError, SolverError
from flipkit.solvers.fixed_sparse import FixedPattern
from flipkit.solvers.osqp_driver import OSQPDriver, run_osqp
from flipkit.solvers.osqp_status import PolishStatus
from flipkit.solvers.subproblem import QPSolution
from flipkit.transcription.nlp import NLP


class CondensedQP:
    """The condensed hard subproblem (a :class:`~flipkit.solvers.subproblem.Subproblem`) for
    NLPs sharing one structure.

    Args:
        nlp: An NLP of the structure (its pattern and bound types are used, not its values).
        elastic: Build the restoration variant: slacks, penalised by ½σ‖s‖², on the inequality
            rows (the equality rows and the step box stay hard).

    Raises:
        ConfigError: As many equality rows as variables or more (nothing left to optimise).
    """

    def __init__(self, nlp: NLP, elastic: bool = False):
        self.elastic = elastic
        n, m = nlp.n, nlp.m
        eq = nlp.c_lo == nlp.c_hi
        self.n, self.m = n, m
        self.eq_rows, self.ineq_rows = np.flatnonzero(eq), np.flatnonzero(~eq)
        self.r = n - len(self.eq_rows)
        if self.r <= 0:
            raise ConfigError(f"segment {nlp.name!r}: {len(self.eq_rows)} equality rows for {n} "
                              "variables leave no null space to optimise in")
        # Jacobian entries of the equality / inequality rows, and their row numbers there:
        # E (CSC, for its LU and column split) and J_I (CSR) on fixed patterns.
        entries = eq[nlp.jac_rows]
        self._eq_entries, self._ineq_entries = np.flatnonzero(entries), np.flatnonzero(~entries)
        rank = np.full(m, -1)
        rank[self.eq_rows] = np.arange(len(self.eq_rows))
        rank[self.ineq_rows] = np.arange(len(self.ineq_rows))
        sub_rows = rank[nlp.jac_rows]
        e, i = self._eq_entries, self._ineq_entries
        self._E = FixedPattern(sub_rows[e], nlp.jac_cols[e], (len(self.eq_rows), n), "csc")
        self._JI = FixedPattern(sub_rows[i], nlp.jac_cols[i], (len(self.ineq_rows), n), "csr")
        ineq_lo, ineq_hi = np.isfinite(nlp.c_lo[self.ineq_rows]), np.isfinite(nlp.c_hi[self.ineq_rows])
        self.lo_sel, self.hi_sel = np.flatnonzero(ineq_lo), np.flatnonzero(ineq_hi)
        self.v = cp.Variable(self.r, name="v")
        self.g = cp.Parameter(self.r, name="condensed_gradient")
        self.G_lo = cp.Parameter((len(self.lo_sel), self.r), name="rows_lo")
        self.G_hi = cp.Parameter((len(self.hi_sel), self.r), name="rows_hi")
        self.b_lo = cp.Parameter(len(self.lo_sel), name="lo_minus_row")
        self.b_hi = cp.Parameter(len(self.hi_sel), name="hi_minus_row")
        self.T = cp.Parameter((n, self.r), name="null_space_basis")
        self.box_lo = cp.Parameter(n, name="box_lo")
        self.box_hi = cp.Parameter(n, name="box_hi")
        lo_rows, hi_rows = self.G_lo @ self.v, self.G_hi @ self.v
        obj = 0.5 * cp.sum_squares(self.v) + self.g @ self.v
        if elastic:
            self.slack_reg = cp.Parameter(nonneg=True, name="slack_regularisation")
            s_lo = cp.Variable(len(self.lo_sel), name="s_lo")
            s_hi = cp.Variable(len(self.hi_sel), name="s_hi")
            lo_rows, hi_rows = lo_rows + s_lo, hi_rows - s_hi
            obj = obj + 0.5 * self.slack_reg * (cp.sum_squares(s_lo) + cp.sum_squares(s_hi))
        self.rows = {"lo": lo_rows >= self.b_lo, "hi": hi_rows <= self.b_hi,
                     "box_lo": self.T @ self.v >= self.box_lo, "box_hi": self.T @ self.v <= self.box_hi}
        self.problem = cp.Problem(cp.Minimize(obj), list(self.rows.values()))
        if not self.problem.is_dpp():  # pragma: no cover - a programming error
            raise SolverError("the condensed subproblem must be DPP")
        self.basis: np.ndarray | None = None
        self.Z: np.ndarray | None = None  # null-space basis of the last update (n × r)
        self.curved = False  # the last update added a curvature estimate M

    # ------------------------------------------------------------------ basis
    def _split(self, jac: np.ndarray):
        """(E's CSC data array, J_I as a CSR matrix) from scaled Jacobian entries on the NLP's
        pattern (:class:`~flipkit.solvers.fixed_sparse.FixedPattern`)."""
        return self._E.data(jac[self._eq_entries]), self._JI.matrix(jac[self._ineq_entries])

    def _set_basis(self, basis: np.ndarray, free: np.ndarray) -> None:
        self.basis, self.free = basis, free
        self._EB, self._EN = self._E.columns(basis), self._E.columns(free)

    def choose_basis(self, jac: np.ndarray, method: str = "lu") -> None:
        """Basic columns B of E at these Jacobian values: the pivot rows of a partially pivoted
        LU of Eᵀ (``"lu"``), or the pivots of a column-pivoted QR of E (``"qr"``, rank-revealing).

        The LU's row pivoting picks, column by column of Eᵀ, the largest remaining entry:
        dense ``getrf`` on the 547 × 516–528 matrix, a few times faster than ``geqp3``, with
        a basis about as well conditioned as the QR's. :meth:`update` falls back to the QR
        when the LU's E_B fails the pivot check.
        """
        E = self._E.matrix(jac[self._eq_entries]).toarray()
        m = len(self.eq_rows)
        if method == "lu":
            _, ipiv = sla.lu_factor(E.T, check_finite=False)
            order = np.arange(self.n)
            for i, j in enumerate(ipiv):  # LAPACK's row interchanges, applied in turn
                order[i], order[j] = order[j], order[i]
        else:
            _, order = sla.qr(E, mode="r", pivoting=True, check_finite=False)
        self._set_basis(np.sort(order[:m]), np.sort(order[m:]))

    def _factor(self, E):
        """Sparse LU of E_B (E given by its CSC data array), or None if it is singular or its
        pivots span more than 1e12."""
        try:
            lu = spla.splu(self._EB.matrix(E))
        except RuntimeError:
            return None
        pivots = np.abs(lu.U.diagonal())
        return lu if pivots.min() > 1e-12 * pivots.max() else None

    def reset(self) -> None:
        """Forget OSQP's state and the basis."""
        self.basis = None
        if hasattr(self, "_driver"):
            self._driver.reset()

    def cold(self) -> None:
        """Drop OSQP's warm start and working set (the next solve starts from zero; OSQP's
        setup is kept)."""
        if hasattr(self, "_driver"):
            self._driver.cold()

    def compile(self) -> OSQPDriver:
        """Canonicalise with cvxpy (once) and return the OSQP driver."""
        if not hasattr(self, "_driver"):
            self._driver = OSQPDriver(self.problem, compact=True)
        return self._driver

    # ------------------------------------------------------------------ values
    def update(self, nlp: NLP, c: np.ndarray, jac: np.ndarray, grad: np.ndarray, hess: np.ndarray,
               d_lo: np.ndarray, d_hi: np.ndarray, slack_reg: float = 1e2,
               curvature: np.ndarray | None = None) -> None:
        """Condense the subproblem of a linearisation (scaled units, as
        :meth:`flipkit.solvers.full_qp.QPSubproblem.update`; ``hess`` must be positive;
        ``slack_reg`` is σ of the elastic form's ½σ‖s‖², unused by the hard form).

        ``curvature``: an r × r estimate M of the rows' curvature in the reduced coordinates
        w = d_N of the current basis (:mod:`flipkit.solvers.reduced_hessian`), added to the
        reduced Hessian ZᵀHZ. It is dropped (:attr:`curved` False) when ZᵀHZ + M is not
        positive definite here, or when the basis is chosen in this update (M belongs to the
        coordinates of the basis it was estimated in)."""
        E, JI = self._split(jac)
        basis = self.basis
        fresh = basis is None  # chosen at this point just now: pivoting again repeats it
        if fresh:
            self.choose_basis(jac)
        lu = self._factor(E)
        if lu is None and not fresh:  # E_B (nearly) singular here: pivot again at this point
            self.choose_basis(jac)
            lu = self._factor(E)
        if lu is None:  # then by the rank-revealing QR
            self.choose_basis(jac, "qr")
            lu = self._factor(E)
            if lu is None:
                raise SingularBasisError("the equality rows' Jacobian is rank deficient")
        if self.basis is not basis:
            curvature = None
        B, N, n, r = self.basis, self.free, self.n, self.r
        lo_s, hi_s = nlp.c_scale * nlp.c_lo, nlp.c_scale * nlp.c_hi
        Z = np.zeros((n, r))
        Z[B] = -lu.solve(self._EN.dense(E))
        Z[N, np.arange(r)] = 1.0
        d_p = np.zeros(n)
        d_p[B] = -lu.solve(c[self.eq_rows] - lo_s[self.eq_rows])
        reduced = Z.T @ (hess[:, None] * Z)
        R, self.curved = None, False
        if curvature is not None:
            try:
                R, self.curved = sla.cholesky(reduced + curvature), True
            except np.linalg.LinAlgError:
                pass
        if R is None:
            R = sla.cholesky(reduced)  # upper: RᵀR = Zᵀ H Z (+ M)
        T = sla.solve_triangular(R, Z.T, trans="T").T  # Z R⁻¹
        self._state = (lu, T, d_p, JI, grad, hess)
        self.Z = Z  # the null-space basis of this linearisation (reduced_hessian reads it)
        I = self.ineq_rows
        G = np.asarray(JI @ T)
        base = c[I] + JI @ d_p
        values = {self.g: T.T @ (grad + hess * d_p), self.T: T,
                  self.G_lo: G[self.lo_sel], self.b_lo: (lo_s[I] - base)[self.lo_sel],
                  self.G_hi: G[self.hi_sel], self.b_hi: (hi_s[I] - base)[self.hi_sel],
                  self.box_lo: d_lo - d_p, self.box_hi: np.maximum(d_hi, d_lo) - d_p}
        if self.elastic:
            values[self.slack_reg] = slack_reg
        compiled = getattr(self, "_driver", None)  # the first values go through cvxpy, which
        for prm, value in values.items():  # compiles with them; later ones to the map
            if compiled is None:
                prm.value = value
            else:
                compiled.assign(prm, value)

    def solve(self, eps: float | None = None, max_iter: int | None = None) -> QPSolution:
        """Solve with OSQP and map back: the full-space step d and row multipliers y (m,), in
        the sign convention of :class:`~flipkit.solvers.subproblem.QPSolution`."""
        res, iterations, status, solved = run_osqp(self.compile(), self.problem, eps, max_iter)
        y = np.zeros(self.m)
        if not solved:
            return QPSolution(np.zeros(self.n), status, iterations, y, False)
        lu, T, d_p, JI, grad, hess = self._state
        d = d_p + T @ self.v.value
        dual = {k: np.asarray(con.dual_value) for k, con in self.rows.items()}
        y_I = np.zeros(len(self.ineq_rows))
        y_I[self.lo_sel] -= dual["lo"]
        y_I[self.hi_sel] += dual["hi"]
        residual = grad + hess * d + JI.T @ y_I + dual["box_hi"] - dual["box_lo"]
        y[self.eq_rows] = -lu.solve(residual[self.basis], trans="T")
        y[self.ineq_rows] = y_I
        polished = res.info.status_polish == PolishStatus.OSQP_POLISH_SUCCESS
        return QPSolution(d, status, iterations, y, polished)
