"""cvxpy's parameter map, applied without cvxpy's per-solve round trip.

A DPP problem is canonicalised by cvxpy once; its problem data are then an affine function of
the parameter vector p (every parameter flattened in Fortran order, then a constant 1). cvxpy
keeps that function as sparse tensors on the compiled problem, which
:func:`~flipkit.solvers.cvxpy_adapter.affine_program` reads from ``get_problem_data``'s
result: the cone form's ``[A | b]``, ``P`` and ``q``, each flattened column-major.
``get_problem_data`` re-applies them on every call and then reshapes, splits and converts the
result through its reduction chain, which costs far more than the products themselves.

:class:`ParameterMap` composes, once, those tensors with what the chain does for OSQP
(equality rows first, inequality rows negated into ``F x ≤ g``, the upper triangle of P) into
three sparse matrices, so that every solve is a matrix–vector product per matrix onto a fixed
sparsity pattern, which is what ``osqp.update`` needs. The composition is checked against
cvxpy's own ``get_problem_data`` at random parameter values when it is built, so a change in
cvxpy's internals is caught there, not in a plan.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from flipkit.errors import SolverError
from flipkit.solvers.cvxpy_adapter import affine_program, osqp_form, problem_data, sparsity

__all__ = ["ParameterMap", "osqp_form"]


class ParameterMap:
    """OSQP's data (P, q, A, l, u) of a compiled DPP problem as sparse products of its parameters.

    Args:
        problem: A DPP cvxpy problem that OSQP accepts, every parameter dense.
        data: ``problem.get_problem_data(cp.OSQP)[0]``, from a call already made.

    Raises:
        SolverError: A sparse parameter, or the composition disagrees with cvxpy's own data.
    """

    def __init__(self, problem: cp.Problem, data: dict):
        prog = affine_program(data)
        self.problem = problem
        self._columns = []  # (parameter, first column in p)
        by_id = {prm.id: prm for prm in problem.parameters()}
        for pid, col in prog.columns.items():
            prm = by_id.get(pid)
            if prm is None or sparsity(prm) is not None:
                raise SolverError("ParameterMap needs dense parameters only")
            self._columns.append((prm, col))
        self._size = prog.size
        self._col = {prm.id: col for prm, col in self._columns}
        self._p = np.zeros(self._size)
        self._p[-1] = 1.0
        self._assigned: set[int] = set()
        n, n_eq = prog.n, prog.n_eq
        m = prog.A.shape[0] // (n + 1)
        sign = np.where(np.arange(m) < n_eq, 1.0, -1.0)  # F = −A_cone on the inequality rows
        TA = sp.csr_matrix(prog.A)
        ent = np.flatnonzero(np.diff(TA.indptr))  # structurally nonzero entries of [A | b]
        i, j = ent % m, ent // m
        mat = j < n
        order = np.lexsort((i[mat], j[mat]))  # CSC order: by column, then row
        rows_A, cols_A, ent_A = i[mat][order], j[mat][order], ent[mat][order]
        self.A_map = sp.diags(sign[rows_A]) @ TA[ent_A]
        self.A_pattern = sp.csc_matrix((np.ones(len(ent_A)), (rows_A, cols_A)), shape=(m, n))
        self.A_pattern.sort_indices()
        off = ~mat  # the offset column b: entry k of row i[k]
        pick = sp.csr_matrix((np.ones(int(off.sum())), (i[off], np.arange(int(off.sum())))),
                             shape=(m, int(off.sum())))
        self.b_map = sp.csr_matrix(pick @ TA[ent[off]])  # b_cone = b_map @ p
        self.n_eq, self.m, self.n = n_eq, m, n
        TP = sp.csr_matrix(prog.P)
        ent = np.flatnonzero(np.diff(TP.indptr))
        i, j = ent % n, ent // n
        up = i <= j
        order = np.lexsort((i[up], j[up]))
        self.P_map = TP[ent[up][order]]
        self.P_pattern = sp.csc_matrix((np.ones(int(up.sum())), (i[up][order], j[up][order])),
                                       shape=(n, n))
        self.P_pattern.sort_indices()
        self.q_map = sp.csr_matrix(prog.q)[:n]
        self._check()

    def assign(self, prm: cp.Parameter, value) -> None:
        """Give ``prm`` a value for :meth:`data` without cvxpy's validation of ``.value`` (a
        cost of the order of the subproblem's solve); from then on ``prm`` is read from
        here, not from ``prm.value``.

        Raises:
            SolverError: ``prm`` is not a parameter of the problem or ``value`` not its shape.
        """
        value = np.asarray(value, float)
        if prm.id not in self._col or value.shape != prm.shape:
            raise SolverError(f"cannot assign a {value.shape} value to parameter {prm.name()!r}")
        col = self._col[prm.id]
        self._p[col:col + prm.size] = value.ravel(order="F")
        self._assigned.add(prm.id)

    def vector(self) -> np.ndarray:
        """The parameter vector p: assigned values, else the parameters' ``.value``."""
        p = self._p.copy()
        for prm, col in self._columns:
            if prm.id not in self._assigned:
                p[col:col + prm.size] = np.asarray(prm.value, float).ravel(order="F")
        return p

    def data(self):
        """(P upper triangle, A, q, l, u) at the current values; P and A on their fixed
        patterns (explicit zeros kept), as ``osqp.update`` needs."""
        p = self.vector()  # the patterns' index arrays are shared, not copied: read-only
        P = sp.csc_matrix((self.P_map @ p, self.P_pattern.indices, self.P_pattern.indptr),
                          shape=self.P_pattern.shape)
        A = sp.csc_matrix((self.A_map @ p, self.A_pattern.indices, self.A_pattern.indptr),
                          shape=self.A_pattern.shape)
        b = self.b_map @ p
        u = np.where(np.arange(self.m) < self.n_eq, -b, b)
        l = np.where(np.arange(self.m) < self.n_eq, -b, -np.inf)
        return P, A, self.q_map @ p, l, u

    def _check(self) -> None:
        """Compare with cvxpy's ``get_problem_data`` at random values (then restored)."""
        rng = np.random.default_rng(1)
        saved = {prm: prm.value for prm, _ in self._columns}
        try:
            for prm, _ in self._columns:
                prm.value = rng.uniform(0.5, 1.5, prm.shape) if prm.shape else 1.0
            P, A, q, l, u = self.data()
            P_ref, A_ref, q_ref, l_ref, u_ref = osqp_form(problem_data(self.problem)[0])
            fin = np.isfinite(l_ref)
            gaps = (abs(P - P_ref).max(), abs(A - A_ref).max(),
                    np.abs(q - q_ref).max(), np.abs(l[fin] - l_ref[fin]).max(initial=0),
                    np.abs(u - u_ref).max(initial=0), float(np.any(np.isfinite(l) != fin)))
        finally:
            for prm, val in saved.items():
                prm.value = val
        if max(gaps) > 1e-9:
            raise SolverError(f"ParameterMap disagrees with cvxpy's problem data by {max(gaps):.1e}")
