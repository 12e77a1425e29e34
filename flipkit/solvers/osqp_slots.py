"""A working set of rows on an OSQP solver set up once: rows in fixed slots, updated in place.

The condensed subproblems have 19–31 variables and ~2 000 inequality rows, of which a few
dozen are active; OSQP's ADMM iteration costs in proportion to the rows it holds, so
:class:`~flipkit.solvers.osqp_driver.OSQPDriver` hands it a working set of rows that changes
from round to round. :class:`RowSlots` holds that working set without setting OSQP up again:
its OSQP problem has ``capacity`` row slots on a fixed sparsity pattern, set up once, and
each round writes the working rows into the first slots (``update(Ax=…, l=…, u=…)``), the
other slots being zero rows without bounds, which ADMM leaves at zero.

Columns. A column of the full problem is *shared* unless it is *private*: in exactly one row
of A, with only a diagonal entry in P (the elastic forms' slacks: ½σs² and one row each).
Every slot is dense over the shared columns, and has its own copies of the private columns
of the row it holds (as many as the row with the most). A dropped row's private columns are
decoupled from everything else, so their optimum is −q/P on their own (0 for a slack);
the full solution is assembled from the slots and those values.

Capacity. Slots that hold no row still cost ADMM work, so a solver is set up for the
smallest power of two ≥ the rows it must hold (at least :data:`MIN_SLOTS`), and one solver is
kept per capacity reached.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import osqp
import scipy.sparse as sp

__all__ = ["MIN_SLOTS", "RowSlots"]

MIN_SLOTS = 16


def _capacity(rows: int) -> int:
    """The smallest power of two ≥ ``rows`` and :data:`MIN_SLOTS`."""
    return max(MIN_SLOTS, 1 << max(int(rows) - 1, 0).bit_length())


class RowSlots:
    """OSQP on row slots for one QP's fixed pattern (P upper triangle and A, CSC).

    Args:
        P_pattern, A_pattern: The sparsity of P (upper triangle) and A for every value, CSC
            with sorted indices; the data arrays given to :meth:`solve` follow them.
    """

    def __init__(self, P_pattern: sp.csc_matrix, A_pattern: sp.csc_matrix):
        m, n = A_pattern.shape
        self.m, self.n = m, n
        a_rows = A_pattern.indices
        a_cols = np.repeat(np.arange(n), np.diff(A_pattern.indptr))
        p_rows = P_pattern.indices
        p_cols = np.repeat(np.arange(n), np.diff(P_pattern.indptr))
        off = p_rows != p_cols
        coupled = np.zeros(n, bool)
        coupled[p_rows[off]] = coupled[p_cols[off]] = True
        has_diag = np.zeros(n, bool)
        has_diag[p_cols[~off]] = True
        private = (np.bincount(a_cols, minlength=n) == 1) & has_diag & ~coupled
        self.shared = np.flatnonzero(~private)
        self.private = np.flatnonzero(private)
        pos = np.full(n, -1)
        pos[self.shared] = np.arange(len(self.shared))
        # A's shared entries, for a dense (m + 1) × shared table (row m: an empty slot's)
        sh = pos[a_cols] >= 0
        self._a_shared = (np.flatnonzero(sh), a_rows[sh], pos[a_cols[sh]])
        # private columns: their row, their rank in it, and where their A and P entries lie
        owner_entry = np.flatnonzero(private[a_cols])
        owner = a_rows[owner_entry]
        order = np.lexsort((a_cols[owner_entry], owner))
        owner_entry, owner = owner_entry[order], owner[order]
        cols = a_cols[owner_entry]
        first = np.searchsorted(owner, owner)
        rank = np.arange(len(owner)) - first
        self.K = int(rank.max(initial=-1)) + 1
        self._priv_col = np.full((m + 1, self.K), -1)
        self._priv_col[owner, rank] = cols
        self._priv_a = (owner, rank, owner_entry)
        diag_at = np.full(n, -1)
        diag_at[p_cols[~off]] = np.flatnonzero(~off)
        self._diag_at = diag_at
        # P on the shared columns: its entries in CSC order (the shared columns keep theirs)
        keep = (pos[p_rows] >= 0) & (pos[p_cols] >= 0)
        self._p_shared = np.flatnonzero(keep)
        ns = len(self.shared)
        self._Ps_indices = pos[p_rows[keep]].astype(np.int32)
        self._Ps_indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(pos[p_cols[keep]], minlength=ns))]).astype(np.int32)
        self._solvers: dict[int, osqp.OSQP] = {}
        self._adapted: set[int] = set()  # capacities whose solver's ρ ADMM has adapted
        self._values = None

    # ------------------------------------------------------------------ data
    def load(self, P_data: np.ndarray, q: np.ndarray, A_data: np.ndarray) -> None:
        """The QP's values (P and A data on the patterns, q) for the rounds that follow."""
        m, ns = self.m, len(self.shared)
        table = np.zeros((m + 1, ns))
        e, r, c = self._a_shared
        table[r, c] = A_data[e]
        priv_a = np.zeros((m + 1, self.K))
        owner, rank, entry = self._priv_a
        priv_a[owner, rank] = A_data[entry]
        col = self._priv_col
        valid = col >= 0
        priv_p = np.ones((m + 1, self.K))  # an empty private slot: ½x², x = 0
        priv_p[valid] = P_data[self._diag_at[col[valid]]]
        priv_q = np.zeros((m + 1, self.K))
        priv_q[valid] = q[col[valid]]
        alone = np.zeros(self.n)  # a dropped row's private columns: −q/P (0 where P ≤ 0)
        pp = P_data[self._diag_at[self.private]] if len(self.private) else np.zeros(0)
        alone[self.private] = np.where(pp > 0, -q[self.private] / np.where(pp > 0, pp, 1.0), 0.0)
        self._values = SimpleNamespace(table=table, priv_a=priv_a, priv_p=priv_p, priv_q=priv_q,
                                       Ps=P_data[self._p_shared], qs=q[self.shared], alone=alone)

    def _matrices(self, slots: np.ndarray):
        """(P data, q, A data) of the slot problem holding the rows ``slots`` (padded with m,
        the empty row), on the patterns of :meth:`_patterns`."""
        v = self._values
        A_data = np.concatenate([v.table[slots].ravel(order="F"), v.priv_a[slots].ravel()])
        P_data = np.concatenate([v.Ps, v.priv_p[slots].ravel()])
        q = np.concatenate([v.qs, v.priv_q[slots].ravel()])
        return P_data, q, A_data

    def _patterns(self, C: int):
        """(P, A) CSC patterns of the slot problem with ``C`` slots (data to be filled)."""
        ns, K = len(self.shared), self.K
        nv = ns + C * K
        P_indices = np.concatenate([self._Ps_indices, np.arange(ns, nv, dtype=np.int32)])
        P_indptr = np.concatenate([self._Ps_indptr,
                                   self._Ps_indptr[-1] + np.arange(1, C * K + 1)]).astype(np.int32)
        A_indices = np.concatenate([np.tile(np.arange(C, dtype=np.int32), ns),
                                    np.repeat(np.arange(C, dtype=np.int32), K)])
        A_indptr = np.concatenate([np.arange(0, ns * C + 1, C),
                                   ns * C + np.arange(1, C * K + 1)]).astype(np.int32)
        return (P_indices, P_indptr, (nv, nv)), (A_indices, A_indptr, (C, nv))

    # ------------------------------------------------------------------ solve
    def solve(self, rows: np.ndarray, l: np.ndarray, u: np.ndarray, x0, y0, settings: dict,
              cold: bool):
        """Solve with the working ``rows`` (indices into A) in the slots.

        Args:
            rows: The working rows, ascending. l, u: Every row's bounds (m,).
            x0, y0: The full problem's previous primal–dual pair (warm start), or None.
            settings: OSQP settings; on a solver already set up, the tolerances and the
                iteration cap are updated.
            cold: Start from zero with OSQP's initial ρ (``settings["rho"]``) on a solver
                already set up.

        Returns:
            A result with the full problem's ``x`` (n,), ``y`` and ``prim_inf_cert`` (m,)
            and OSQP's ``info``.
        """
        C = _capacity(len(rows))
        slots = np.full(C, self.m)
        slots[:len(rows)] = rows
        P_data, q, A_data = self._matrices(slots)
        lw = np.full(C, -np.inf)
        uw = np.full(C, np.inf)
        lw[:len(rows)], uw[:len(rows)] = l[rows], u[rows]
        solver = self._solvers.get(C)
        if solver is None:
            (pi, pp, ps), (ai, ap, ashape) = self._patterns(C)
            solver = osqp.OSQP(algebra="builtin")  # named: no probing of cuda/mkl modules
            solver.setup(sp.csc_matrix((P_data, pi, pp), shape=ps), q,
                         sp.csc_matrix((A_data, ai, ap), shape=ashape), lw, uw, **settings)
            self._solvers[C] = solver
        else:
            # P and q too: a slot's private columns take its row's weights (refactorised
            # with the A update in any case)
            solver.update(q=q, l=lw, u=uw, Px=P_data, Ax=A_data)
            # every round from OSQP's initial ρ, as on a fresh setup: ρ adapted to another
            # working set (or another QP) can slow ADMM down on this one. (A ρ update
            # refactorises: skipped while ADMM has not adapted ρ since the last one.)
            if C in self._adapted:
                solver.update_settings(rho=settings["rho"])
                self._adapted.discard(C)
            solver.update_settings(eps_abs=settings["eps_abs"], eps_rel=settings["eps_rel"],
                                   max_iter=settings["max_iter"])
            if cold:
                solver.warm_start(x=np.zeros(len(q)), y=np.zeros(C))
        if x0 is not None:
            col = self._priv_col[slots]
            xp = np.where(col >= 0, x0[np.maximum(col, 0)], 0.0)
            yw = np.zeros(C)
            yw[:len(rows)] = y0[rows]
            solver.warm_start(x=np.concatenate([x0[self.shared], xp.ravel()]), y=yw)
        res = solver.solve(raise_error=False)
        if res.info.rho_updates > 0:
            self._adapted.add(C)
        return self._full(res, rows, slots)

    def _full(self, res, rows: np.ndarray, slots: np.ndarray):
        """The slot problem's result as the full problem's."""
        x = None
        if res.x is not None:
            x = self._values.alone.copy()
            x[self.shared] = res.x[:len(self.shared)]
            col = self._priv_col[slots].ravel()
            mine = col >= 0
            x[col[mine]] = res.x[len(self.shared):][mine]
        out = SimpleNamespace(x=x, info=res.info, dual_inf_cert=None)
        for name in ("y", "prim_inf_cert"):
            full = np.zeros(self.m)
            value = getattr(res, name, None)
            if value is not None:
                full[rows] = np.asarray(value)[:len(rows)]
            setattr(out, name, full)
        return out
