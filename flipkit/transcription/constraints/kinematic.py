"""Spatula task-space constraints at chosen nodes: poses, bounds, cone, grill contact.

A :class:`KinematicBlock` applies one *quantity* of the spatula state — a vector function
of (q, q̇, q̈) with analytic Jacobians — at a list of nodes with bounds lo ≤ value ≤ hi.
"""

from __future__ import annotations

import numpy as np

from flipkit.model.contact import ConeForm
from flipkit.errors import InvalidChoiceError
from flipkit.model.orientation import axis_jacobian, rpy_jacobian
from flipkit.model.robot import SpatulaState, skew
from flipkit.transcription.constraints.base import Block


def _point_height(st: SpatulaState, r_local) -> tuple[np.ndarray, np.ndarray]:
    """Height of the blade point p + R r (m) and its ∂/∂q (1 row), over leading node axes."""
    r = st.R @ np.asarray(r_local, float)
    return ((st.p[..., 2] + r[..., 2])[..., None],
            (st.dp_dq[..., 2, :] - (skew(r) @ st.Jw)[..., 2, :])[..., None, :])


def _point_position(st: SpatulaState, r_local) -> tuple[np.ndarray, np.ndarray]:
    """The blade point p + R r (m) and its ∂/∂q (3 rows), over leading node axes."""
    r = st.R @ np.asarray(r_local, float)
    return st.p + r, st.dp_dq - skew(r) @ st.Jw


class Quantity:
    """A spatula quantity of derivative order 0 (q), 1 (q, q̇) or 2 (q, q̇, q̈).

    ``__call__`` maps one node's :class:`SpatulaState` to the value (size,) and its
    Jacobians (size x nq). A quantity whose ``__call__`` also maps a batch of nodes (every
    array with a leading node axis) sets ``broadcasts``; the others are applied node by node.
    """

    order = 0
    size = 3
    broadcasts = False

    def __call__(self, st: SpatulaState, ctx) -> tuple:
        """(value, ∂/∂q[, ∂/∂q̇[, ∂/∂q̈]])."""
        raise NotImplementedError

    def batch(self, st: SpatulaState, ctx) -> tuple:
        """Values (n, size) and Jacobians (n, size, nq) at a batch of n nodes."""
        if self.broadcasts:
            return self(st, ctx)
        outs = [self(st.take(k), ctx) for k in range(len(st))]
        return tuple(np.stack(parts) for parts in zip(*outs))


class Position(Quantity):
    broadcasts = True

    def __call__(self, st, ctx):
        return st.p, st.dp_dq


class Height(Quantity):
    size = 1
    broadcasts = True

    def __call__(self, st, ctx):
        return st.p[..., 2:], st.dp_dq[..., 2:, :]


class Rpy(Quantity):
    broadcasts = True

    def __call__(self, st, ctx):
        return rpy_jacobian(st.R, st.Jw)


class Pitch(Quantity):
    """The pitch o_y = −asin(x̂_z) (rad): it depends on the blade's x axis alone, so it stays
    continuous while the roll o_x wraps at ±π (the flip rolls the blade over)."""

    size = 1
    broadcasts = True

    def __call__(self, st, ctx):
        o, J = rpy_jacobian(st.R, st.Jw)
        return o[..., 1:2], J[..., 1:2, :]


class Normal(Quantity):
    broadcasts = True

    def __call__(self, st, ctx):
        return axis_jacobian(st.R, st.Jw, 2)


class XAxis(Quantity):
    broadcasts = True

    def __call__(self, st, ctx):
        return axis_jacobian(st.R, st.Jw, 0)


class TipHeight(Quantity):
    """Height of the blade tip, p_z − (l_l/2) sin o_y for a level blade (eq. 24)."""

    size = 1
    broadcasts = True

    def __call__(self, st, ctx):
        return _point_height(st, (ctx["length"] / 2, 0.0, 0.0))


class TipPosition(Quantity):
    """Position (m, world) of the middle of the blade's tip edge, p + R (l_l/2, 0, 0)."""

    broadcasts = True

    def __call__(self, st, ctx):
        return _point_position(st, (ctx["length"] / 2, 0.0, 0.0))


BLADE_CORNERS = ((1, 1), (1, -1), (-1, 1), (-1, -1))  # (±l/2, ±w/2): tip left, tip right, ...


class BladeCornerHeights(Quantity):
    """Heights of the blade's four corners (±l/2, ±w/2): the lowest point of the flat blade
    is always one of them, so the whole blade stays above a floor that they do (its edges'
    midpoints do not suffice once the blade rolls: a corner then reaches lower)."""

    size = 4
    broadcasts = True

    def __call__(self, st, ctx):
        l, w = ctx["length"] / 2, ctx["width"] / 2
        r = st.R @ np.array([[a * l for a, _ in BLADE_CORNERS], [b * w for _, b in BLADE_CORNERS],
                             [0.0] * 4])
        # height p_z + r_z; ∂/∂q: ∂p_z/∂q − (r × J_ω)_z = ∂p_z/∂q + r_y J_ωx − r_x J_ωy
        Jw = st.Jw
        return (st.p[..., 2, None] + r[..., 2, :],
                st.dp_dq[..., 2, None, :] + r[..., 1, :, None] * Jw[..., 0, None, :]
                - r[..., 0, :, None] * Jw[..., 1, None, :])


class Velocity(Quantity):
    order = 1
    broadcasts = True

    def __call__(self, st, ctx):
        return st.v, st.dv_dq, st.dv_dqd


class Acceleration(Quantity):
    order = 2
    broadcasts = True

    def __call__(self, st, ctx):
        return st.a, st.da_dq, st.da_dqd, st.da_dqdd


class Cone(Quantity):
    """Friction-cone margin h ≥ 0 of a :class:`~flipkit.model.contact.ConeForm`, for the burger
    resting over the blade point ``point`` (spatula frame, m; default the blade centre)."""

    order = 2
    broadcasts = True

    def __init__(self, cone: ConeForm, point=None):
        self.cone, self.size = cone, cone.rows
        self.point = None if point is None or not np.any(point) else np.asarray(point, float)

    def __call__(self, st, ctx):
        return self.cone.jacobians(st)


QUANTITIES = {"position": Position, "height": Height, "rpy": Rpy, "pitch": Pitch, "normal": Normal,
              "xaxis": XAxis, "tip_height": TipHeight, "tip_position": TipPosition,
              "blade_heights": BladeCornerHeights,
              "velocity": Velocity, "acceleration": Acceleration}


class KinematicBlock(Block):
    """lo ≤ quantity(q_i, q̇_i, q̈_i) ≤ hi at each node i in ``nodes``.

    Args:
        name: Group name. layout: Variable layout.
        quantity: A key of :data:`QUANTITIES` or a :class:`Quantity` (e.g. :class:`Cone`).
        nodes: Node indices. lo, hi: Bounds, broadcast to (len(nodes), size).
        scale: Row scale. ctx: Geometry the quantity needs (blade length, width).
    """

    def __init__(self, name, layout, quantity, nodes, lo, hi, scale=1.0, ctx=None):
        super().__init__(name, layout)
        if isinstance(quantity, str):
            if quantity not in QUANTITIES:
                raise InvalidChoiceError("spatula quantity", quantity, QUANTITIES)
            quantity = QUANTITIES[quantity]()
        self.quantity, self.nodes, self.ctx = quantity, [int(i) for i in nodes], ctx or {}
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

    def evaluate(self, ev):
        if not self.nodes:
            return np.zeros(0), np.zeros(0)
        out = self.quantity.batch(ev.states(self._index, self._point), self.ctx)
        # ∂/∂q, ∂/∂q̇, ∂/∂q̈ side by side per row
        jac = np.concatenate(out[1:], axis=-1) if len(out) > 2 else out[1]
        return np.ravel(out[0]), np.ravel(jac)
