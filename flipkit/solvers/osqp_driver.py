"""OSQP behind a compiled cvxpy problem: set up once, ``update`` on a fixed pattern, warm start,
and a working set of inequality rows.

cvxpy canonicalises the (DPP) problem; this driver keeps one ``osqp.OSQP`` object per
problem, as osqp-python recommends: values are updated on the sparsity of the first setup
and each solve is warm-started from the previous primal–dual pair. When every Parameter is
dense, the values reach OSQP through :class:`~flipkit.solvers.param_map.ParameterMap` (cvxpy's
own parameter map, applied as sparse products) instead of ``get_problem_data`` per solve.

Working set. On the SQP subproblems OSQP's ADMM is slowed by the ~1600 inequality rows
(variable box, task-space bounds, cone) of which ~15 are active: the same QP with only its
active rows converges in a twentieth of the iterations. So after the
first solve the inequality rows handed to OSQP are those active in the previous solve (its
working set); the solution is then checked against *every* row, the most violated dropped
rows are added and the solve repeated (warm-started): the :data:`ADD_PER_ROUND` most violated
in compact mode, where a round's cost grows with its rows, and every violated one on the
persistent solver, where a round costs the same whatever the working set (so fewer
rounds). The returned point satisfies all rows
and, the dropped rows being inactive with zero multipliers, solves the full QP. A subset of
rows being infeasible proves the full QP infeasible. The working set carried from one solve
to the next holds at most :data:`INITIAL_ROWS` rows per variable (see :func:`_capped`).

Compact mode (``compact=True``, used by the condensed subproblem of
:mod:`flipkit.solvers.condensed_qp`): OSQP holds the working rows alone, in the row slots of
a :class:`~flipkit.solvers.osqp_slots.RowSlots` solver set up once and updated round to round
(with 19–31 variables each ADMM iteration then touches a few dozen rows instead of ~2 000),
warm-started from the previous primal–dual pair. A compact solve's solution reaches the cvxpy
variables and duals through a :class:`~flipkit.solvers.solution_map.SolutionMap` (cvxpy's
unpacking found once), not through ``unpack_results`` at each solve.

Setup. Each OSQP object is set up on the first solve after :meth:`OSQPDriver.reset` and only
updated after that (``update(q=…, l=…, u=…, Px=…, Ax=…)`` on the setup's sparsity, then a
warm start); :meth:`OSQPDriver.cold` keeps it and restarts ADMM from zero with OSQP's
initial ρ. The SQP resets its subproblems at the start of every solve, so OSQP is set up once
per structure and solve, and updated in every iteration and working-set round of the solve.
The objects are not kept from one solve to the next: a solve on an updated object does not
repeat a fresh setup's last bits, and results must not depend on what was solved before.

Statuses are named by :mod:`flipkit.solvers.osqp_status`; cvxpy's compiled problem is read
through :mod:`flipkit.solvers.cvxpy_adapter`.
"""

from __future__ import annotations

import warnings

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

import osqp

from flipkit.errors import SolverError
from flipkit.solvers.cvxpy_adapter import osqp_form, problem_data, sparsity
from flipkit.solvers.osqp_slots import RowSlots
from flipkit.solvers.osqp_status import SOLVED, UNPACKED
from flipkit.solvers.param_map import ParameterMap
from flipkit.solvers.solution_map import SolutionMap
from flipkit.solvers.stdout_redirect import c_stdout_silenced

MAX_ROUNDS = 12  # then every row is handed to OSQP
# A row whose norm is below NULL_ROW times the largest row's is numerically zero: a
# row that the equality rows fix (its gradient lies outside the condensed null space, e.g. a
# bound on a state the endpoint rows pin), left at ~1e-15 by round-off. Handed to OSQP it
# wrecks the ADMM: OSQP reports "primal infeasible" where the zero step is feasible. Such a
# row is
# constant, so it is left out of the working set whenever its bounds hold at zero.
NULL_ROW = 1e-10
ADD_PER_ROUND = 10  # compact mode: most violated dropped rows added per round
INITIAL_SLACK = 1e-2  # first working set: inequality rows this close to a bound at d = 0
INITIAL_ROWS = 2  # working set carried between solves: at most this many rows per variable
def _capped(rows: np.ndarray, first: np.ndarray, then: np.ndarray, cap: int) -> np.ndarray:
    """The mask ``rows`` keeping at most ``cap`` of them: smallest ``first``, ties by ``then``.

    A working set larger than a few rows per variable is degenerate (the condensed QP has
    19–31 variables): in a small trust box every step-box row can lie within INITIAL_SLACK
    of its bound, and OSQP then runs to its iteration cap on them."""
    if rows.sum() <= cap:
        return rows
    keep = np.flatnonzero(rows)
    keep = keep[np.lexsort((then[keep], first[keep]))[:cap]]
    out = np.zeros_like(rows)
    out[keep] = True
    return out


class OSQPDriver:
    """Solve a compiled cvxpy QP with a persistent OSQP object.

    Args:
        problem: A DPP cvxpy problem (OSQP-compatible).
        compact: Hand OSQP only the working rows (in the row slots of a
            :class:`~flipkit.solvers.osqp_slots.RowSlots` solver) instead of updating one
            solver holding every row with the dropped rows unbounded; for problems with few
            variables.
    """

    def __init__(self, problem: cp.Problem, compact: bool = False):
        self.problem, self.compact = problem, compact
        self._map, self._solution_map, self.status = None, None, None
        if all(sparsity(prm) is None for prm in problem.parameters()):
            # cvxpy's parameter map applied directly (fixed patterns, no round trip)
            self._map = ParameterMap(problem, self._cvxpy_data()[0])
        else:
            self._fixed_pattern()
        self.reset()

    def assign(self, prm: cp.Parameter, value) -> None:
        """Set a parameter's value: straight into the parameter map when there is one
        (:meth:`~flipkit.solvers.param_map.ParameterMap.assign`), else ``prm.value``."""
        if self._map is not None:
            self._map.assign(prm, value)
        else:
            prm.value = value

    def reset(self) -> None:
        """Forget OSQP's objects, warm start and working set: the next solve sets up afresh."""
        self._osqp, self._slots = None, None
        self.cold()

    def cold(self) -> None:
        """Drop the warm start and the working set, keeping OSQP's objects: the next solve
        starts ADMM from zero with OSQP's initial ρ."""
        self._x, self._y, self._active, self._cold = None, None, None, True

    def _cvxpy_data(self):
        """cvxpy's (data, chain, inverse data) for the current parameters; the chain and inverse
        data do not depend on the values (DPP) and are kept for unpacking."""
        data, self._chain, self._inverse = problem_data(self.problem)
        return data, self._chain, self._inverse

    def _data(self):
        """(P upper triangle, A, q, l, u, chain, inverse data) for the current parameters."""
        if self._map is not None:
            return (*self._map.data(), self._chain, self._inverse)
        data, chain, inverse = self._cvxpy_data()
        return (*osqp_form(data), chain, inverse)

    def _fixed_pattern(self) -> None:
        """Sparsity of P and A for every parameter value: cvxpy drops explicit zeros, OSQP's
        ``update`` needs the pattern of its setup. Found once with random parameter values."""
        rng = np.random.default_rng(0)
        saved = {prm: prm.value_sparse if sparsity(prm) is not None else prm.value
                 for prm in self.problem.parameters()}
        for prm in self.problem.parameters():
            pattern = sparsity(prm)
            if pattern is not None:  # a sparse parameter: random values on its pattern
                prm.value_sparse = sp.coo_array(
                    (rng.uniform(0.5, 1.5, len(pattern[0])), pattern), shape=prm.shape)
            else:
                prm.value = rng.uniform(0.5, 1.5, prm.shape) if prm.shape else 1.0
        P, A, *_ = self._data()
        for prm, val in saved.items():
            if val is None:
                continue
            if sparsity(prm) is not None:
                prm.value_sparse = val
            else:
                prm.value = val
        self._patterns = []
        self._keys = []
        for M in (P, A):
            pat = sp.csc_matrix((np.ones(M.nnz), M.nonzero()), shape=M.shape)
            pat.sort_indices()
            self._patterns.append(pat)
            self._keys.append(pat.indices.astype(np.int64) + M.shape[0] * np.repeat(
                np.arange(M.shape[1], dtype=np.int64), np.diff(pat.indptr)))

    def _on_pattern(self, k: int, M: sp.csc_matrix) -> sp.csc_matrix:
        """M with the fixed pattern k (0: P, 1: A), explicit zeros where M has none."""
        M = M.tocoo()
        keys = M.row.astype(np.int64) + M.shape[0] * M.col.astype(np.int64)
        pos = np.searchsorted(self._keys[k], keys)
        if np.any(pos >= len(self._keys[k])) or np.any(self._keys[k][np.minimum(
                pos, len(self._keys[k]) - 1)] != keys):
            raise SolverError("QP data outside the fixed sparsity pattern")  # pragma: no cover
        out = self._patterns[k].copy()
        out.data = np.zeros(len(self._keys[k]))
        np.add.at(out.data, pos, M.data)
        return out

    def _solve_persistent(self, P, q, A, l, u, work, settings, first=True):
        """One round on the persistent solver: every row, the dropped ones unbounded; the
        matrices are updated (and refactorised) in a solve's first round only."""
        lw, uw = np.where(work, l, -np.inf), np.where(work, u, np.inf)
        if self._osqp is None:
            self._osqp = osqp.OSQP(algebra="builtin")  # named: no probing of cuda/mkl modules
            self._osqp.setup(P, q, A, lw, uw, **settings)
        else:
            if first:
                self._osqp.update(q=q, l=lw, u=uw, Px=P.data, Ax=A.data)
            else:
                self._osqp.update(l=lw, u=uw)
            self._osqp.update_settings(eps_abs=settings["eps_abs"], eps_rel=settings["eps_rel"],
                                       max_iter=settings["max_iter"])
            if self._x is not None:
                self._osqp.warm_start(x=self._x, y=self._y)
            elif first and self._cold:  # from zero, with OSQP's initial ρ
                self._osqp.update_settings(rho=settings["rho"])
                self._osqp.warm_start(x=np.zeros(A.shape[1]), y=np.zeros(A.shape[0]))
        return self._osqp.solve(raise_error=False)

    def _solve_compact(self, P, q, A, l, u, work, settings, first=True):
        """One round with the working rows alone, in the row slots of the solver set up once
        (:class:`~flipkit.solvers.osqp_slots.RowSlots`; P, A and q loaded in a solve's first
        round); the result's dual vectors are returned at full length (zero on the dropped
        rows), as cvxpy unpacks."""
        if self._slots is None:
            self._slots = RowSlots(P, A)
        if first:
            self._slots.load(P.data, q, A.data)
        return self._slots.solve(np.flatnonzero(work), l, u, self._x, self._y, settings,
                                 cold=first and self._cold)

    def solve(self, settings: dict):
        """Solve for the current parameter values; returns (OSQP result, total ADMM iterations).

        The cvxpy variables and constraint duals are set as by ``problem.solve``, and
        :attr:`status` to cvxpy's name of the status (``None`` when OSQP failed). With a
        parameter map, ``problem.value`` carries the objective's constant term of the first
        compile, not the current one; in compact mode a solution is stored by a
        :class:`~flipkit.solvers.solution_map.SolutionMap`, which does not set
        ``problem.value`` and ``problem.status`` (the SQP reads the variables, the duals and
        :attr:`status` only).
        """
        P, A, q, l, u, chain, inverse = self._data()
        if self._map is None:  # `update` needs the setup's sparsity pattern
            P, A = self._on_pattern(0, P), self._on_pattern(1, A)
        ineq = ~(l == u)
        cap = INITIAL_ROWS * A.shape[1]
        A = A.tocsc()  # (a no-op: every path builds CSC) row norms from its row indices
        size = np.sqrt(np.bincount(A.indices, weights=A.data ** 2, minlength=A.shape[0]))
        constant = size <= NULL_ROW * size.max(initial=0.0)
        if self._active is None:  # first solve: the rows within INITIAL_SLACK of a bound
            margin = np.where(ineq, np.minimum(u, -l), np.inf)
            self._active = _capped(margin <= INITIAL_SLACK, np.zeros(len(l)), margin, cap)
        tol = settings["eps_abs"] + settings["eps_rel"] * np.maximum(np.abs(np.where(np.isfinite(l), l, 0)),
                                                                     np.abs(np.where(np.isfinite(u), u, 0)))
        constant &= (l <= tol) & (u >= -tol)  # held by every x: left out (NULL_ROW)
        work = (~ineq | self._active) & ~constant
        total = 0
        for rnd in range(MAX_ROUNDS + 1):
            if rnd == MAX_ROUNDS:
                work[:] = ~constant
            round_solve = self._solve_compact if self.compact else self._solve_persistent
            res = round_solve(P, q, A, l, u, work, settings, rnd == 0)
            total += res.info.iter
            if res.x is None or not np.all(np.isfinite(res.x)):
                break
            self._x, self._y = res.x, res.y
            if res.info.status_val not in SOLVED or work.all() or rnd == MAX_ROUNDS:
                # solved (inaccurate), or every row that is not constant was in
                break
            z = A @ res.x
            viol = np.where(work, 0.0, np.maximum(l - z, z - u))
            if np.all(viol <= tol):
                break
            add = np.argsort(-viol)[:ADD_PER_ROUND if self.compact else len(viol)]
            work[add[viol[add] > tol[add]]] = True
        if res.info.status_val in SOLVED and np.all(np.isfinite(res.x)):
            z = A @ res.x
            margin = np.minimum(z - l, u - z)
            self._active = _capped(ineq & ((np.abs(res.y) > 0) | (margin <= tol)),
                                   -np.abs(res.y), margin, cap)
        self.status = None
        if self.compact and res.info.status_val in SOLVED and self._solution_map is None:
            try:  # cvxpy's unpacking, found once; if it is not a selection, cvxpy's own
                self._solution_map = SolutionMap(self.problem, chain, inverse, A.shape[1],
                                                 A.shape[0])
            except SolverError:
                self._solution_map = False
        if self.compact and res.info.status_val in SOLVED and self._solution_map:
            self.status = self._solution_map.apply(res)
        elif res.info.status_val in UNPACKED:  # cvxpy raises on the other statuses
            with warnings.catch_warnings():  # an inaccurate solve is reported by its status
                warnings.simplefilter("ignore", UserWarning)
                self.problem.unpack_results(res, chain, inverse)
            self.status = str(self.problem.status)
        else:
            self.cold()  # no solution to warm-start from: the next solve starts from zero
        if self._x is not None:
            self._cold = False
        return res, total


# OSQP: polishing turns an ADMM iterate into the exact solution of the identified active set;
# the SQP passes its own tolerance per solve (this eps is the default for a direct solve).
# Deterministic: a fixed adaptive-rho interval (interval 0 would time the setup and adapt rho
# after a fraction of it, which varies run to run).
# rho is OSQP's own initial value, named so that a cold restart can return to it.
OSQP_SETTINGS = dict(eps_abs=1e-6, eps_rel=1e-6, max_iter=10000, rho=0.1, adaptive_rho_interval=25,
                     polishing=True, polish_refine_iter=3, check_termination=10, verbose=False)


def run_osqp(driver: OSQPDriver, problem: cp.Problem, eps: float | None, max_iter: int | None):
    """Solve ``problem`` through its driver with :data:`OSQP_SETTINGS` (``eps`` and
    ``max_iter`` overriding); returns (OSQP result, ADMM iterations, status, solved), status
    cvxpy's, or ``osqp:<status>`` when cvxpy could not unpack it, solved for (inaccurately)
    optimal."""
    settings = dict(OSQP_SETTINGS)
    if eps is not None:
        settings.update(eps_abs=eps, eps_rel=eps)
    if max_iter is not None:
        settings.update(max_iter=int(max_iter))
    try:
        with c_stdout_silenced():
            res, iterations = driver.solve(settings)
    except cp.error.SolverError as exc:  # OSQP broke down (cvxpy's error): ours, one line
        raise SolverError(f"OSQP failed inside a subproblem: {' '.join(str(exc).split())}") from None
    ok = res.info.status_val in UNPACKED
    status = driver.status if ok else f"osqp:{res.info.status}"
    return res, iterations, status, res.info.status_val in SOLVED
