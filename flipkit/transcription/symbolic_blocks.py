"""Symbolic (CasADi SX) forms of the constraint blocks, row for row.

:func:`symbolic_rows` states one :class:`~flipkit.transcription.constraints.Block` as SX
expressions with exact derivatives: the same rows, in the block's row order and its units
(before the row scale), as :meth:`Block.evaluate` computes numerically. Each block states its
own form (:meth:`Block.symbolic`, in the block's module; a kinematic block asks its quantity's
``symbolic``); this module checks that the form covers the block's rows. Each group of rows
comes with the stage of the stage-wise graph (:mod:`flipkit.transcription.ocp_graph`) whose
variables it reads; the variables come from an accessor with

* ``var(index, stage)``: the SX of variable Z[index] as stage ``stage`` holds it,
* ``node(i, stage)``: (q_i, q̇_i, q̈_i, u_i) as stage ``stage`` holds them,
* ``kinematics(i, stage, point)``: the spatula's symbolic kinematics at node i
  (:class:`~flipkit.model.casadi_dynamics.Kinematics`), cached,
* ``rnea(i, stage)``: the inverse dynamics at node i, and ``stage_of(i)``: the stage that
  holds node i.

A block with no symbolic form (its ``no_symbolic_form`` says why: the arm's clearance rows,
distances computed by coal; the flip's landing and flight rows) raises
:class:`~flipkit.errors.NoSymbolicFormError`: build the NLP without it
(``SegmentOptions(arm_clearance=False)``) to compare solvers on it.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from flipkit.errors import NoSymbolicFormError
from flipkit.transcription.constraints.base import Block

Rows = list[tuple[int, ca.SX, np.ndarray]]  # (stage, values, block-local row indices)


def symbolic_rows(block: Block, acc) -> Rows:
    """The rows of ``block`` as SX, grouped by stage (see the module docstring).

    Raises:
        NoSymbolicFormError: The block (e.g. ``arm_clearance``) has no symbolic form, or its
            form does not cover its rows.
    """
    rows = block.symbolic(acc)
    covered = np.sort(np.concatenate([r for _, _, r in rows])) if rows else np.zeros(0)
    if not np.array_equal(covered, np.arange(block.m)):
        raise NoSymbolicFormError(f"block {block.name!r}: symbolic rows do not cover it")
    return rows
