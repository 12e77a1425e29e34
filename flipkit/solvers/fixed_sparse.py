"""Sparse matrices on a fixed pattern: the pattern is analysed once, then each new set of entry
values becomes a CSC or CSR matrix (or a column subset, or a dense block of columns) by one
precomputed gather, without SciPy's COO sorting and duplicate summing on every call.

The condensed SQP subproblem (:mod:`flipkit.solvers.condensed_qp`) rebuilds its equality and
inequality Jacobians from the NLP's entries at every iteration, always on the same pattern
(the NLP's ``jac_rows``, ``jac_cols``); SciPy's COO → CSC/CSR conversions and column slicing
took about a third of a condensing step (docs/history.md).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from flipkit.errors import ConfigError


class FixedPattern:
    """A (rows × cols) sparse pattern given entry by entry, in compressed column (``"csc"``) or
    row (``"csr"``) order. Entries at the same position are summed, as SciPy sums duplicates.

    Args:
        rows, cols: Row and column of each entry (the order in which values will come).
        shape: (n rows, n cols). fmt: ``"csc"`` or ``"csr"``.

    Raises:
        ConfigError: Unknown ``fmt``, mismatched or out-of-range indices.
    """

    def __init__(self, rows, cols, shape, fmt: str = "csc"):
        if fmt not in ("csc", "csr"):
            raise ConfigError(f"sparse format must be one of csc, csr; got {fmt!r}")
        rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
        m, n = int(shape[0]), int(shape[1])
        if rows.shape != cols.shape or (rows.size and (rows.min() < 0 or rows.max() >= m
                                                       or cols.min() < 0 or cols.max() >= n)):
            raise ConfigError(f"pattern entries must be paired and inside the {m} x {n} shape")
        self.shape, self.fmt = (m, n), fmt
        major, minor, n_major = (cols, rows, n) if fmt == "csc" else (rows, cols, m)
        keys, self._slot = np.unique(major * max(m, n) + minor, return_inverse=True)
        self._slot = self._slot.ravel()
        self.nnz = len(keys)
        self.indices = (keys % max(m, n)).astype(np.int32)
        self._major = keys // max(m, n)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(self._major, minlength=n_major))
                                      ]).astype(np.int32)

    def data(self, values) -> np.ndarray:
        """The compressed data array of ``values`` (one per entry, in the pattern's order)."""
        return np.bincount(self._slot, weights=values, minlength=self.nnz)

    def matrix(self, values):
        """The matrix of ``values`` (``scipy.sparse.csc_matrix`` or ``csr_matrix``)."""
        kind = sp.csc_matrix if self.fmt == "csc" else sp.csr_matrix
        return kind((self.data(values), self.indices, self.indptr), shape=self.shape)

    def columns(self, cols) -> "ColumnSubset":
        """The gather of the columns ``cols`` of a CSC pattern, for :class:`ColumnSubset`."""
        if self.fmt != "csc":
            raise ConfigError("column subsets need a csc pattern")
        return ColumnSubset(self, np.asarray(cols, np.int64))


class ColumnSubset:
    """Columns ``cols`` of a :class:`FixedPattern` (CSC), as a sparse CSC matrix or as a dense
    array, from the pattern's data array."""

    def __init__(self, pattern: FixedPattern, cols: np.ndarray):
        start, stop = pattern.indptr[cols], pattern.indptr[cols + 1]
        counts = stop - start
        # positions of the chosen columns' entries in the data array, column by column
        self._take = np.repeat(start - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
        self.indices = pattern.indices[self._take]
        self.indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
        self._dense_at = (self.indices, np.repeat(np.arange(len(cols)), counts))
        self.shape = (pattern.shape[0], len(cols))

    def matrix(self, data: np.ndarray) -> sp.csc_matrix:
        """The columns as a CSC matrix, from the pattern's data array."""
        return sp.csc_matrix((data[self._take], self.indices, self.indptr), shape=self.shape)

    def dense(self, data: np.ndarray) -> np.ndarray:
        """The columns as a dense (rows × len(cols)) array."""
        out = np.zeros(self.shape)
        out[self._dense_at] = data[self._take]
        return out


__all__ = ["ColumnSubset", "FixedPattern"]
