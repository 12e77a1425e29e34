"""Base class of constraint blocks and the simplest block, fixed variable values.

A block's module holds its three parts (:mod:`flipkit.transcription.constraints.registry`):
``evaluate`` (numeric rows and Jacobian), ``symbolic`` (the same rows as CasADi SX, for the
stage-wise graph of :mod:`flipkit.transcription.ocp_graph`) and ``check`` (the groups of
``verify`` that recompute what it requires independently, or why there are none).
"""

from __future__ import annotations

import numpy as np

from flipkit.errors import ConfigError, NoSymbolicFormError
from flipkit.transcription.constraints.registry import BLOCK_TERMS, Check
from flipkit.transcription.layout import Evaluation, Layout

class Patterns:
    """Sparsity patterns of constraint blocks by (block type, key), each filled by the first
    block that asks for it and shared, read-only, by later blocks with the same key.

    A chain builds the same patterns for every burger, and filling them is a large share of
    a segment's build: whoever transcribes many segments keeps one and passes it in their
    :class:`~flipkit.transcription.layout.Layout` (``patterns``), as the planners do
    (:class:`~flipkit.planning.planners.caches.PlannerCaches`).
    """

    def __init__(self):
        self._filled: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}

    def get(self, key: tuple, fill):
        """(rows, cols) of ``key``, from ``fill()`` (which returns them) the first time."""
        if key not in self._filled:
            rows, cols = fill()
            rows.setflags(write=False)
            cols.setflags(write=False)
            self._filled[key] = rows, cols
        return self._filled[key]

    def __len__(self) -> int:
        return len(self._filled)


class Block:
    """A group of constraints lo ≤ c(Z) ≤ hi with a fixed Jacobian sparsity pattern.

    Subclasses fill the pattern with :meth:`_add` in the same order as :meth:`evaluate`
    produces the Jacobian entries, state the rows as SX in :meth:`symbolic` (or say why not
    in ``no_symbolic_form``) and name their independent check in ``check``. Defining a
    subclass registers it in :data:`~flipkit.transcription.constraints.registry.BLOCK_TERMS`
    (or in the ``registry`` given as a class keyword).

    Attributes:
        name: Constraint group, used in reports ("dynamics", "cone", ...).
        m: Number of rows. rows, cols: Pattern (rows local to the block).
        lo, hi: Bounds (±inf where open). scale: Row scale applied by the solvers.
        check: Where ``verify`` checks the block (class attribute).
        no_symbolic_form: Why the block has no :meth:`symbolic` (class attribute; empty
            when it has one).
    """

    check: Check | None = None
    no_symbolic_form = ""

    def __init_subclass__(cls, registry=None, **kwargs):
        super().__init_subclass__(**kwargs)
        (BLOCK_TERMS if registry is None else registry).register(cls)

    def __init__(self, name: str, layout: Layout):
        self.name, self.layout = name, layout
        self._rows: list[np.ndarray] = []
        self._cols: list[np.ndarray] = []
        self.m = 0

    def _pattern(self, key: tuple, fill) -> None:
        """Fill the pattern by ``fill()`` (calls of :meth:`_add`), or take it from the
        layout's :class:`Patterns` (if it has them) where a block of this type with the same
        ``key`` — everything the pattern depends on — filled it before."""
        patterns = self.layout.patterns
        if patterns is None:
            fill()
            return

        def filled():
            fill()
            return tuple(np.concatenate(a) if a else np.zeros(0, int)
                         for a in (self._rows, self._cols))

        rows, cols = patterns.get((type(self).__name__, *key), filled)
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

    def symbolic(self, acc) -> list:
        """The rows as SX, grouped by stage: (stage, SX values, block-local row indices) per
        group, in the block's units before the row scale; ``acc`` gives the variables
        (:mod:`flipkit.transcription.symbolic_blocks`).

        Raises:
            NoSymbolicFormError: The block has no symbolic form (``no_symbolic_form``).
        """
        why = f" ({self.no_symbolic_form})" if self.no_symbolic_form else ""
        raise NoSymbolicFormError(
            f"constraint block {self.name!r} ({type(self).__name__}) has no symbolic form{why}; "
            "build the segment without it (SegmentOptions(arm_clearance=False) for "
            "arm_clearance)")


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

    check = Check(("continuity", "endpoints"))  # start state; end state, rest, q_home

    def evaluate(self, ev):
        return ev.x[self.indices].copy(), np.ones(self.m)

    def symbolic(self, acc):
        L, out = self.layout, []
        for r, idx in enumerate(self.indices):
            s = acc.stage_of(int(idx) // L.node_size) if idx < L.alpha_start else 0
            out.append((s, acc.var(int(idx), s), np.array([r])))
        return out
