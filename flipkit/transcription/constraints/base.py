"""Base class of constraint blocks and the simplest block, fixed variable values."""

from __future__ import annotations

import numpy as np

from flipkit.transcription.layout import Evaluation, Layout
from flipkit.errors import ConfigError

_PATTERNS: dict = {}  # Block._pattern's cache: (block type, key) -> (rows, cols), read-only


class Block:
    """A group of constraints lo ≤ c(Z) ≤ hi with a fixed Jacobian sparsity pattern.

    Subclasses fill the pattern with :meth:`_add` in the same order as :meth:`evaluate`
    produces the Jacobian entries.

    Attributes:
        name: Constraint group, used in reports ("dynamics", "cone", ...).
        m: Number of rows. rows, cols: Pattern (rows local to the block).
        lo, hi: Bounds (±inf where open). scale: Row scale applied by the solvers.
    """

    def __init__(self, name: str, layout: Layout):
        self.name, self.layout = name, layout
        self._rows: list[np.ndarray] = []
        self._cols: list[np.ndarray] = []
        self.m = 0

    def _pattern(self, key: tuple, fill) -> None:
        """Fill the pattern by ``fill()`` (calls of :meth:`_add`) once per process for each
        ``key`` — everything the pattern depends on — and reuse it (read-only) for later blocks
        with the same key: a chain builds the same patterns for every burger, and filling
        them is a large share of a segment's build."""
        key = (type(self).__name__, *key)
        if key not in _PATTERNS:
            fill()
            rows, cols = (np.concatenate(a) if a else np.zeros(0, int)
                          for a in (self._rows, self._cols))
            rows.setflags(write=False)
            cols.setflags(write=False)
            _PATTERNS[key] = rows, cols
        rows, cols = _PATTERNS[key]
        self._rows, self._cols = [rows], [cols]

    def _add(self, row0: int, nrows: int, cols) -> None:
        """Append a dense nrows × len(cols) sub-block at local rows row0.. (row-major values)."""
        cols = np.asarray(cols, dtype=int)
        self._rows.append(np.repeat(np.arange(row0, row0 + nrows), len(cols)))
        self._cols.append(np.tile(cols, nrows))

    def _finish(self, lo, hi, scale) -> None:
        self.rows = np.concatenate(self._rows) if self._rows else np.zeros(0, int)
        self.cols = np.concatenate(self._cols) if self._cols else np.zeros(0, int)
        self.lo = np.broadcast_to(np.asarray(lo, float), (self.m,)).copy()
        self.hi = np.broadcast_to(np.asarray(hi, float), (self.m,)).copy()
        self.scale = np.broadcast_to(np.asarray(scale, float), (self.m,)).copy()
        if np.any(self.lo > self.hi):
            raise ConfigError(f"constraint block {self.name!r} has lower bounds above upper bounds")

    @property
    def is_equality(self) -> np.ndarray:
        return self.lo == self.hi

    def evaluate(self, ev: Evaluation) -> tuple[np.ndarray, np.ndarray]:
        """Values c (m,) and Jacobian entries (nnz,) at the point of ``ev``."""
        raise NotImplementedError


class FixedValues(Block):
    """Linear equalities Z[idx] = target (start state, rest, home configuration).

    Args:
        name: Group name. layout: Variable layout.
        indices: Variable indices. target: Their required values. scale: Row scale.
    """

    def __init__(self, name: str, layout: Layout, indices, target, scale=1.0):
        super().__init__(name, layout)
        self.indices = np.asarray(indices, dtype=int).ravel()
        self.target = np.asarray(target, dtype=float).ravel()
        if self.target.shape != self.indices.shape or not np.all(np.isfinite(self.target)):
            raise ConfigError(f"{name}: target must be {self.indices.size} finite values")
        self.m = self.indices.size
        self._rows.append(np.arange(self.m))
        self._cols.append(self.indices)
        self._finish(self.target, self.target, scale)

    project_order = 0  # before the dynamics' projection, which reads the fixed q, q̇, q̈

    def project(self, x: np.ndarray, robot) -> np.ndarray:
        """x with Z[idx] = target exactly: a start or end state is held to the bit, not to
        the round-off of a QP step (a plan starts exactly where it was asked to)."""
        x = np.array(x, float)
        x[self.indices] = self.target
        return x

    def evaluate(self, ev):
        return ev.x[self.indices].copy(), np.ones(self.m)
