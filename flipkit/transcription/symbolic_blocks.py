"""Symbolic (CasADi SX) forms of the constraint blocks, row for row.

:func:`symbolic_rows` states one :class:`~flipkit.transcription.constraints.Block` as SX
expressions with exact derivatives: the same rows, in the block's row order and its units
(before the row scale), as :meth:`Block.evaluate` computes numerically. Each group of rows
comes with the stage of the stage-wise graph (:mod:`flipkit.transcription.ocp_graph`) whose
variables it reads; the variables come from an accessor with

* ``var(index, stage)``: the SX of variable Z[index] as stage ``stage`` holds it,
* ``node(i, stage)``: (q_i, q̇_i, q̈_i, u_i) as stage ``stage`` holds them,
* ``kinematics(i, stage, point)``: the spatula's symbolic kinematics at node i
  (:class:`~flipkit.model.casadi_dynamics.Kinematics`), cached,
* ``rnea(i, stage)``: the inverse dynamics at node i, and ``stage_of(i)``: the stage that
  holds node i.

A block with no symbolic form (the arm's clearance rows, distances computed by coal; the
flip's landing and flight rows) raises :class:`~flipkit.errors.NoSymbolicFormError`: build
the NLP without it (``SegmentOptions(arm_clearance=False)``) to compare solvers on it.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from flipkit.errors import NoSymbolicFormError
from flipkit.model.casadi_dynamics import Kinematics
from flipkit.model.contact import PaperCone, PhysicalCone
from flipkit.transcription.constraints.base import Block, FixedValues
from flipkit.transcription.constraints.braking import BrakingMargin
from flipkit.transcription.constraints.dynamics import BezierOutput, Dynamics, HermiteSimpson
from flipkit.transcription.constraints.interpolant import InterpolantLimits, interval_terms
from flipkit.transcription.constraints.kinematic import (BLADE_CORNERS, Acceleration,
                                                         BladeCornerHeights, Cone,
                                                         Height, KinematicBlock, Normal, Pitch,
                                                         Position, Rpy, TipHeight, Velocity,
                                                         XAxis)

Rows = list[tuple[int, ca.SX, np.ndarray]]  # (stage, values, block-local row indices)


def rpy(R: ca.SX) -> ca.SX:
    """o = (o_x, o_y, o_z) (rad) with R = R_z(o_z) R_y(o_y) R_x(o_x): pinocchio's
    ``rpy.matrixToRpy`` away from o_y = ±π/2 (its gimbal-lock branch is not used)."""
    m = ca.sqrt(R[2, 1] ** 2 + R[2, 2] ** 2)
    return ca.vertcat(ca.atan2(R[2, 1], R[2, 2]), ca.atan2(-R[2, 0], m), ca.atan2(R[1, 0], R[0, 0]))


def _blade_height(k: Kinematics, r) -> ca.SX:
    """Height (m) of the blade point r (spatula frame, m)."""
    return k.p[2] + k.R[2, :] @ ca.DM(np.asarray(r, float))


def quantity(q, k: Kinematics, ctx: dict) -> ca.SX:
    """The symbolic value of a spatula :class:`~flipkit.transcription.constraints.kinematic.
    Quantity` at kinematics ``k``; ``ctx`` holds the blade's length and width (m).

    Raises:
        NoSymbolicFormError: A quantity this module does not know.
    """
    if isinstance(q, Position):
        return k.p
    if isinstance(q, Height):
        return k.p[2]
    if isinstance(q, Pitch):
        return rpy(k.R)[1]
    if isinstance(q, Rpy):
        return rpy(k.R)
    if isinstance(q, Normal):
        return k.R[:, 2]
    if isinstance(q, XAxis):
        return k.R[:, 0]
    if isinstance(q, TipHeight):
        return _blade_height(k, (ctx["length"] / 2, 0.0, 0.0))
    if isinstance(q, BladeCornerHeights):
        l, w = ctx["length"] / 2, ctx["width"] / 2
        return ca.vertcat(*[_blade_height(k, (a * l, b * w, 0.0)) for a, b in BLADE_CORNERS])
    if isinstance(q, Velocity):
        return k.v
    if isinstance(q, Acceleration):
        return k.a
    if isinstance(q, Cone):
        form = q.cone
        w = k.a - ca.DM(form.gravity)
        if isinstance(form, PhysicalCone):
            mu = form.mu
            S = ca.DM([[0, 0, 1], [-1, 0, mu], [1, 0, mu], [0, -1, mu], [0, 1, mu]])
            return S @ (k.R.T @ w)
        if isinstance(form, PaperCone):
            return ca.dot(k.R[:, 2], w) / ca.norm_2(w) - np.cos(form.mu)
    raise NoSymbolicFormError(f"spatula quantity {type(q).__name__} has no symbolic form")


def _dynamics(b: Dynamics, acc) -> Rows:
    nq = b.layout.nq
    out = []
    for i in range(b.layout.n_nodes):
        s = acc.stage_of(i)
        out.append((s, acc.rnea(i, s) - acc.node(i, s)[3], np.arange(i * nq, (i + 1) * nq)))
    return out


def _hermite_simpson(b: HermiteSimpson, acc) -> Rows:
    L, nq, out, row = b.layout, b.layout.nq, [], 0
    for i in range(1, L.N, 2):
        s = acc.stage_of(i - 1)
        na, ni, nb = (acc.node(n, s) for n in (i - 1, i, i + 1))
        dt = 2 * acc.var(L.T_index, s) / L.N
        for k in (0, 1):
            xa, xi, xb = na[k], ni[k], nb[k]
            da, di, db = na[k + 1], ni[k + 1], nb[k + 1]
            delta = xi - (xa + xb) / 2 - dt * (da - db) / 8
            sigma = xb - xa - dt * (da + 4 * di + db) / 6
            out.append((s, delta, np.arange(row, row + nq)))
            out.append((s, sigma, np.arange(row + nq, row + 2 * nq)))
            row += 2 * nq
    return out


def _interpolant(b: InterpolantLimits, acc) -> Rows:
    L, nq, out = b.layout, b.layout.nq, []
    for i in range(L.N):
        s = acc.stage_of(i)  # holds node i and node i + 1 (itself or the copy of the next)
        (q0, qd0), (q1, qd1) = acc.node(i, s)[:2], acc.node(i + 1, s)[:2]
        terms = interval_terms(q0, qd0, q1, qd1, acc.var(L.T_index, s) / L.N)
        for r, value in enumerate(terms):
            row = (3 * i + r) * nq
            out.append((s, value, np.arange(row, row + nq)))
    return out


def _alpha(L, acc, s) -> ca.SX:
    """α as an (nq, M+1) SX matrix, held by stage s."""
    idx = np.arange(L.alpha_start, L.T_index)
    flat = ca.vertcat(*[acc.var(int(j), s) for j in idx])
    return ca.reshape(flat, L.bezier.n_coeffs, L.nq).T  # row-major (nq, M+1)


def _bezier(b: BezierOutput, acc) -> Rows:
    L, nq, e, out = b.layout, b.layout.nq, b.eps, []
    B0, B1, B2 = b.B
    for i in range(L.n_nodes):
        s = acc.stage_of(i)
        q, qd, qdd, _ = acc.node(i, s)
        T, alpha = acc.var(L.T_index, s), _alpha(L, acc, s)
        c = ca.DM(B2[i]) / T**2 + 2 * e * ca.DM(B1[i]) / T + e**2 * ca.DM(B0[i])
        out.append((s, qdd + 2 * e * qd + e**2 * q - alpha @ c, np.arange(i * nq, (i + 1) * nq)))
    s0, M, row = acc.stage_of(0), L.bezier.degree, L.n_nodes * nq
    q0, qd0 = acc.node(0, s0)[:2]
    T, alpha = acc.var(L.T_index, s0), _alpha(L, acc, s0)
    out.append((s0, q0 - alpha[:, 0], np.arange(row, row + nq)))
    out.append((s0, qd0 - M * (alpha[:, 1] - alpha[:, 0]) / T, np.arange(row + nq, row + 2 * nq)))
    return out


def _fixed(b: FixedValues, acc) -> Rows:
    L, out = b.layout, []
    for r, idx in enumerate(b.indices):
        s = acc.stage_of(int(idx) // L.node_size) if idx < L.alpha_start else 0
        out.append((s, acc.var(int(idx), s), np.array([r])))
    return out


def _kinematic(b: KinematicBlock, acc) -> Rows:
    k, out = b.quantity.size, []
    point = getattr(b.quantity, "point", None)
    for r, i in enumerate(b.nodes):
        s = acc.stage_of(i)
        value = quantity(b.quantity, acc.kinematics(i, s, point), b.ctx)
        out.append((s, value, np.arange(r * k, (r + 1) * k)))
    return out


def _braking(b: BrakingMargin, acc) -> Rows:
    s = acc.stage_of(b.node)
    q, qd = acc.node(b.node, s)[:2]
    return [(s, q + qd * ca.fabs(qd) / ca.DM(2.0 * b.qdd_max), np.arange(b.m))]


_FORMS = ((Dynamics, _dynamics), (HermiteSimpson, _hermite_simpson), (BezierOutput, _bezier),
          (FixedValues, _fixed), (KinematicBlock, _kinematic), (BrakingMargin, _braking),
          (InterpolantLimits, _interpolant))


def symbolic_rows(block: Block, acc) -> Rows:
    """The rows of ``block`` as SX, grouped by stage (see the module docstring).

    Raises:
        NoSymbolicFormError: The block (e.g. ``arm_clearance``) has no symbolic form.
    """
    for cls, form in _FORMS:
        if type(block) is cls:
            rows = form(block, acc)
            covered = np.sort(np.concatenate([r for _, _, r in rows])) if rows else np.zeros(0)
            if not np.array_equal(covered, np.arange(block.m)):
                raise NoSymbolicFormError(f"block {block.name!r}: symbolic rows do not cover it")
            return rows
    raise NoSymbolicFormError(
        f"constraint block {block.name!r} ({type(block).__name__}) has no symbolic form; build "
        "the segment without it (SegmentOptions(arm_clearance=False) for arm_clearance)")
