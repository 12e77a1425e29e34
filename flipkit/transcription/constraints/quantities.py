"""Spatula quantities: vector functions of one node's (q, q̇, q̈) that a
:class:`~flipkit.transcription.constraints.kinematic.KinematicBlock` bounds at its nodes.

Each quantity holds its value with analytic Jacobians (``__call__``, from pinocchio's
:class:`~flipkit.model.robot.SpatulaState`) and the same value as CasADi SX (``symbolic``, from
:class:`~flipkit.model.casadi_dynamics.Kinematics`), or says why it has none. Its independent
check is its block's (:mod:`flipkit.transcription.constraints.registry`).
"""

from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np

from flipkit.errors import NoSymbolicFormError
from flipkit.model.contact import ConeForm
from flipkit.model.orientation import axis_jacobian, rpy_jacobian
from flipkit.model.robot import BLADE_CORNERS, SpatulaState, skew
from flipkit.transcription.constraints.registry import QUANTITY_TERMS


def rpy(R: ca.SX) -> ca.SX:
    """o = (o_x, o_y, o_z) (rad) with R = R_z(o_z) R_y(o_y) R_x(o_x): pinocchio's
    ``rpy.matrixToRpy`` away from o_y = ±π/2 (its gimbal-lock branch is not used)."""
    m = ca.sqrt(R[2, 1] ** 2 + R[2, 2] ** 2)
    return ca.vertcat(ca.atan2(R[2, 1], R[2, 2]), ca.atan2(-R[2, 0], m), ca.atan2(R[1, 0], R[0, 0]))


def framed(k, frame):
    """Symbolic kinematics (:class:`~flipkit.model.casadi_dynamics.Kinematics`) seen in a
    :class:`~flipkit.model.task_frame.TaskFrame`: positions turned about its centre, vectors
    and the rotation turned by −ψ (the numeric counterpart is ``TaskFrame.state``)."""
    if frame.identity:
        return k
    A = ca.DM(frame.rotation(np.eye(3)))
    c = ca.DM([*frame.centre, 0.0])
    return replace(k, p=A @ (k.p - c) + c, R=A @ k.R, v=A @ k.v, a=A @ k.a, w=A @ k.w,
                   dw=A @ k.dw)


def _blade_height(k, r) -> ca.SX:
    """Height (m) of the blade point r (spatula frame, m) at the symbolic kinematics k."""
    return k.p[2] + k.R[2, :] @ ca.DM(np.asarray(r, float))


def _physical_cone(form, k) -> ca.SX:
    """:class:`~flipkit.model.contact.PhysicalCone`'s h as SX."""
    w = k.a - ca.DM(form.gravity)
    mu = form.mu
    S = ca.DM([[0, 0, 1], [-1, 0, mu], [1, 0, mu], [0, -1, mu], [0, 1, mu]])
    return S @ (k.R.T @ w)


def _paper_cone(form, k) -> ca.SX:
    """:class:`~flipkit.model.contact.PaperCone`'s h as SX."""
    w = k.a - ca.DM(form.gravity)
    return ca.dot(k.R[:, 2], w) / ca.norm_2(w) - np.cos(form.mu)


_CONE_FORMS = {"physical": _physical_cone, "paper": _paper_cone}  # by ConeForm.name


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
    :meth:`symbolic` states the value as SX (or ``no_symbolic_form`` says why not). Defining a
    subclass registers it in :data:`~flipkit.transcription.constraints.registry.QUANTITY_TERMS`
    (or in the ``registry`` given as a class keyword).
    """

    order = 0
    size = 3
    broadcasts = False
    no_symbolic_form = ""

    def __init_subclass__(cls, registry=None, **kwargs):
        super().__init_subclass__(**kwargs)
        (QUANTITY_TERMS if registry is None else registry).register(cls)

    def __call__(self, st: SpatulaState, ctx) -> tuple:
        """(value, ∂/∂q[, ∂/∂q̇[, ∂/∂q̈]])."""
        raise NotImplementedError

    def symbolic(self, k, ctx) -> ca.SX:
        """The value as SX at the symbolic kinematics ``k``
        (:class:`~flipkit.model.casadi_dynamics.Kinematics`); ``ctx`` as for ``__call__``.

        Raises:
            NoSymbolicFormError: The quantity has no symbolic form.
        """
        raise NoSymbolicFormError(f"spatula quantity {type(self).__name__} has no symbolic form")

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

    def symbolic(self, k, ctx):
        return k.p


class Height(Quantity):
    size = 1
    broadcasts = True

    def __call__(self, st, ctx):
        return st.p[..., 2:], st.dp_dq[..., 2:, :]

    def symbolic(self, k, ctx):
        return k.p[2]


class Rpy(Quantity):
    broadcasts = True

    def __call__(self, st, ctx):
        return rpy_jacobian(st.R, st.Jw)

    def symbolic(self, k, ctx):
        return rpy(k.R)


class Pitch(Quantity):
    """The pitch o_y = −asin(x̂_z) (rad): it depends on the blade's x axis alone, so it stays
    continuous while the roll o_x wraps at ±π (the flip rolls the blade over)."""

    size = 1
    broadcasts = True

    def __call__(self, st, ctx):
        o, J = rpy_jacobian(st.R, st.Jw)
        return o[..., 1:2], J[..., 1:2, :]

    def symbolic(self, k, ctx):
        return rpy(k.R)[1]


class Normal(Quantity):
    broadcasts = True

    def __call__(self, st, ctx):
        return axis_jacobian(st.R, st.Jw, 2)

    def symbolic(self, k, ctx):
        return k.R[:, 2]


class XAxis(Quantity):
    broadcasts = True

    def __call__(self, st, ctx):
        return axis_jacobian(st.R, st.Jw, 0)

    def symbolic(self, k, ctx):
        return k.R[:, 0]


class TipHeight(Quantity):
    """Height of the blade tip, p_z − (l_l/2) sin o_y for a level blade (eq. 24)."""

    size = 1
    broadcasts = True

    def __call__(self, st, ctx):
        return _point_height(st, (ctx["length"] / 2, 0.0, 0.0))

    def symbolic(self, k, ctx):
        return _blade_height(k, (ctx["length"] / 2, 0.0, 0.0))


class TipPosition(Quantity):
    """Position (m, world) of the middle of the blade's tip edge, p + R (l_l/2, 0, 0)."""

    broadcasts = True
    no_symbolic_form = ("no SX form is stated: the segment that applies it (the approach's "
                        "descent and slide) is solved by the SQP")

    def __call__(self, st, ctx):
        return _point_position(st, (ctx["length"] / 2, 0.0, 0.0))


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

    def symbolic(self, k, ctx):
        l, w = ctx["length"] / 2, ctx["width"] / 2
        return ca.vertcat(*[_blade_height(k, (a * l, b * w, 0.0)) for a, b in BLADE_CORNERS])


class Velocity(Quantity):
    order = 1
    broadcasts = True

    def __call__(self, st, ctx):
        return st.v, st.dv_dq, st.dv_dqd

    def symbolic(self, k, ctx):
        return k.v


class Acceleration(Quantity):
    order = 2
    broadcasts = True

    def __call__(self, st, ctx):
        return st.a, st.da_dq, st.da_dqd, st.da_dqdd

    def symbolic(self, k, ctx):
        return k.a


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

    def symbolic(self, k, ctx):
        if self.cone.name not in _CONE_FORMS:
            raise NoSymbolicFormError(f"cone form {self.cone.name!r} has no symbolic form")
        return _CONE_FORMS[self.cone.name](self.cone, k)


QUANTITIES = {"position": Position, "height": Height, "rpy": Rpy, "pitch": Pitch, "normal": Normal,
              "xaxis": XAxis, "tip_height": TipHeight, "tip_position": TipPosition,
              "blade_heights": BladeCornerHeights,
              "velocity": Velocity, "acceleration": Acceleration}
