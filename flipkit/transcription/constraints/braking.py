"""Braking margin: a segment that ends moving must leave room to stop inside the limits."""

from __future__ import annotations

import casadi as ca
import numpy as np

from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.registry import Check


class BrakingMargin(Block):
    """q_j + q̇_j|q̇_j| / (2 q̈_max,j) ∈ [q_min,j, q_max,j] at one node (usually the last).

    The position where joint j would stop under full deceleration. Without it a segment
    that ends in motion (pickup, flip) may end at a joint limit moving outwards, and the
    next segment, which starts from that state (29), is then infeasible.

    Args:
        layout: Variable layout. node: Node index.
        q_min, q_max: Joint limits (rad). qdd_max: Deceleration available (rad/s²).
    """

    def __init__(self, layout, node: int, q_min, q_max, qdd_max):
        super().__init__("braking_margin", layout)
        self.node, self.qdd_max = int(node), np.asarray(qdd_max, float)
        nq = layout.nq
        for j in range(nq):
            self._add(j, 1, [layout.iq(node)[j], layout.iqd(node)[j]])
        self.m = nq
        self._finish(q_min, q_max, 1.0)

    def evaluate(self, ev):
        q, qd = ev.node(self.node)[:2]
        a = 2.0 * self.qdd_max
        vals = q + qd * np.abs(qd) / a
        jac = np.column_stack([np.ones_like(q), 2.0 * np.abs(qd) / a]).ravel()
        return vals, jac

    check = Check(none="a margin the planner keeps for the next segment: what it protects, "
                       "that segment's q_limits from its continuous start, is checked there")

    def symbolic(self, acc):
        s = acc.stage_of(self.node)
        q, qd = acc.node(self.node, s)[:2]
        return [(s, q + qd * ca.fabs(qd) / ca.DM(2.0 * self.qdd_max), np.arange(self.m))]
