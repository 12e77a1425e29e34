"""Spatula task-space constraints at chosen nodes: poses, bounds, cone, grill contact.

A :class:`KinematicBlock` applies one *quantity* of the spatula state
(:mod:`flipkit.transcription.constraints.quantities`) at a list of nodes with bounds
lo ≤ value ≤ hi.
"""

from __future__ import annotations

import numpy as np

from flipkit.errors import InvalidChoiceError
from flipkit.model.task_frame import WORLD, TaskFrame
from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.quantities import QUANTITIES, framed
from flipkit.transcription.constraints.registry import Check


class KinematicBlock(Block):
    """lo ≤ quantity(q_i, q̇_i, q̈_i) ≤ hi at each node i in ``nodes``.

    Its independent check is the verify group of the spec hook that states the block: end
    poses (``endpoints``), a behaviour's path (``behavior_path``), the cone and the release
    (``cone``, ``release``), the blade's floor (``grill_clearance``) and the pitch range
    (``orientation``); the cell's task-space position, velocity and acceleration bounds are
    not checked (:mod:`flipkit.planning.plans.verify`).

    Args:
        name: Group name. layout: Variable layout.
        quantity: A key of :data:`~flipkit.transcription.constraints.quantities.QUANTITIES`
            or a :class:`~flipkit.transcription.constraints.quantities.Quantity` (e.g.
            :class:`~flipkit.transcription.constraints.quantities.Cone`).
        nodes: Node indices. lo, hi: Bounds, broadcast to (len(nodes), size).
        scale: Row scale. ctx: Geometry the quantity needs (blade length, width).
        frame: The :class:`~flipkit.model.task_frame.TaskFrame` the quantity is seen in
            (the scoop heading's); default the world's.
    """

    def __init__(self, name, layout, quantity, nodes, lo, hi, scale=1.0, ctx=None,
                 frame: TaskFrame = WORLD):
        super().__init__(name, layout)
        if isinstance(quantity, str):
            if quantity not in QUANTITIES:
                raise InvalidChoiceError("spatula quantity", quantity, QUANTITIES)
            quantity = QUANTITIES[quantity]()
        self.quantity, self.nodes, self.ctx = quantity, [int(i) for i in nodes], ctx or {}
        self.frame = frame
        point = getattr(quantity, "point", None)
        self.points = () if point is None else (tuple(float(c) for c in point),)
        self._point = self.points[0] if self.points else None
        n = len(self.nodes)
        contiguous = n and self.nodes == list(range(self.nodes[0], self.nodes[0] + n))
        self._index = slice(self.nodes[0], self.nodes[0] + n) if contiguous else np.array(self.nodes)
        k = quantity.size
        fields = (layout.iq, layout.iqd, layout.iqdd)[: quantity.order + 1]

        def fill():
            for r, i in enumerate(self.nodes):
                self._add(r * k, k, np.concatenate([f(i) for f in fields]))

        self._pattern((*layout.key, k, quantity.order, *self.nodes), fill)
        self.m = k * len(self.nodes)
        shape = (len(self.nodes), k)
        self._finish(np.broadcast_to(lo, shape).ravel(), np.broadcast_to(hi, shape).ravel(),
                     np.broadcast_to(scale, shape).ravel())

    check = Check(("endpoints", "behavior_path", "cone", "release", "grill_clearance",
                   "orientation"))

    def evaluate(self, ev):
        if not self.nodes:
            return np.zeros(0), np.zeros(0)
        st = self.frame.state(ev.states(self._index, self._point))
        out = self.quantity.batch(st, self.ctx)
        # ∂/∂q, ∂/∂q̇, ∂/∂q̈ side by side per row
        jac = np.concatenate(out[1:], axis=-1) if len(out) > 2 else out[1]
        return np.ravel(out[0]), np.ravel(jac)

    def symbolic(self, acc):
        k, out = self.quantity.size, []
        point = getattr(self.quantity, "point", None)
        for r, i in enumerate(self.nodes):
            s = acc.stage_of(i)
            k_i = framed(acc.kinematics(i, s, point), self.frame)
            value = self.quantity.symbolic(k_i, self.ctx)
            out.append((s, value, np.arange(r * k, (r + 1) * k)))
        return out
