"""Joint limits between the nodes: the velocity and acceleration of the trajectory the arm is
given, not only of its nodes.

The controller (:mod:`flipkit.simulation.execute`) and the judge of :mod:`flipkit.baseline.
classify` follow a plan between its nodes by the cubic Hermite interpolant of (q, q̇), knot
at every node. Node bounds alone let that interpolant exceed the limits between nodes. On an
interval of length h = T/N with ends (q_0, q̇_0), (q_1, q̇_1) and Δ = q_1 − q_0:

* q̈ is linear in time, so its bounds hold on the whole interval when they hold at its two
  ends: a_0 = 6Δ/h² − (4q̇_0 + 2q̇_1)/h and a_1 = −6Δ/h² + (2q̇_0 + 4q̇_1)/h (exact);
* q̇ is a quadratic with Bernstein coefficients q̇_0, c = 3Δ/h − q̇_0 − q̇_1, q̇_1, and lies in
  their convex hull, so |c| ≤ q̇_max (q̇_0, q̇_1 are bounded as variables) suffices.

Rows per interval: a_0 (nq), a_1 (nq), c (nq). Their coefficients are large (6/h² ≈ 7e3 per
rad at T = 0.6 s), so the rows are scaled by :data:`ACC_SCALE` and :data:`VEL_SCALE`, well
below the node rows' scale, which would multiply the restoration QPs' ADMM iterations.
:func:`flipkit.planning.plans.verify.verify_plan` checks them in the same scaled units.
"""

from __future__ import annotations

import numpy as np

from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.registry import Check

ACC_SCALE = 1e-3  # row scale of a_0, a_1 (s²/rad): the solver's tolerance 1e-6 is 1e-3 rad/s²
VEL_SCALE = 1e-2  # row scale of c (s/rad): 1e-4 rad/s


def interval_terms(q0, qd0, q1, qd1, h):
    """(a_0, a_1, c) of the cubic Hermite interval (see the module docstring); any array
    shapes that broadcast, h in s."""
    d = q1 - q0
    return (6 * d / h**2 - (4 * qd0 + 2 * qd1) / h, -6 * d / h**2 + (2 * qd0 + 4 * qd1) / h,
            3 * d / h - qd0 - qd1)


class InterpolantLimits(Block):
    """|q̈| ≤ q̈_max and |q̇| ≤ q̇_max on the cubic Hermite interpolant between every two nodes.

    Args:
        layout: Variable layout. qd_max: Joint speed limits (rad/s). qdd_max: Joint
            acceleration limits (rad/s²).
    """

    def __init__(self, layout, qd_max, qdd_max):
        super().__init__("interpolant_limits", layout)
        nq, N = layout.nq, layout.N
        # row (i, kind, j) of interval i, kind a_0 / a_1 / c, joint j: columns q_i[j], q_{i+1}[j],
        # q̇_i[j], q̇_{i+1}[j] and T (one dense 1 × 5 sub-block per row, built at once)
        iq = np.array([layout.iq(i) for i in range(N + 1)])  # (N+1, nq)
        iqd = np.array([layout.iqd(i) for i in range(N + 1)])
        cols = np.stack([iq[:-1], iq[1:], iqd[:-1], iqd[1:], np.full((N, nq), layout.T_index)],
                        axis=-1)  # (N, nq, 5)
        cols = np.broadcast_to(cols[:, None], (N, 3, nq, 5))
        self.m = 3 * N * nq
        self._rows.append(np.repeat(np.arange(self.m), 5))
        self._cols.append(cols.reshape(-1))
        qd_max, qdd_max = np.asarray(qd_max, float), np.asarray(qdd_max, float)
        bound = np.tile(np.concatenate([qdd_max, qdd_max, qd_max]), N)
        scale = np.tile(np.concatenate([np.full(2 * nq, ACC_SCALE), np.full(nq, VEL_SCALE)]), N)
        self._finish(-bound, bound, scale)

    def evaluate(self, ev):
        L = self.layout
        N = L.N
        nodes = L.nodes(ev.x)
        q, qd = nodes[:, 0], nodes[:, 1]
        h = ev.T / N
        q0, q1, v0, v1 = q[:-1], q[1:], qd[:-1], qd[1:]  # (N, nq)
        a0, a1, c = interval_terms(q0, v0, q1, v1, h)
        d = q1 - q0
        one = np.ones_like(d)
        # ∂/∂(q_0, q_1, q̇_0, q̇_1, T) per row; dh/dT = 1/N
        jac_a0 = np.stack([-6 / h**2 * one, 6 / h**2 * one, -4 / h * one, -2 / h * one,
                           (-12 * d / h**3 + (4 * v0 + 2 * v1) / h**2) / N], axis=-1)
        jac_a1 = np.stack([6 / h**2 * one, -6 / h**2 * one, 2 / h * one, 4 / h * one,
                           (12 * d / h**3 - (2 * v0 + 4 * v1) / h**2) / N], axis=-1)
        jac_c = np.stack([-3 / h * one, 3 / h * one, -one, -one, -3 * d / h**2 / N], axis=-1)
        vals = np.stack([a0, a1, c], axis=1)  # (N, 3, nq)
        jac = np.stack([jac_a0, jac_a1, jac_c], axis=1)  # (N, 3, nq, 5)
        return vals.ravel(), jac.ravel()

    check = Check(("interpolant",))

    def symbolic(self, acc):
        L, nq, out = self.layout, self.layout.nq, []
        for i in range(L.N):
            s = acc.stage_of(i)  # holds node i and node i + 1 (itself or the copy of the next)
            (q0, qd0), (q1, qd1) = acc.node(i, s)[:2], acc.node(i + 1, s)[:2]
            terms = interval_terms(q0, qd0, q1, qd1, acc.var(L.T_index, s) / L.N)
            for r, value in enumerate(terms):
                row = (3 * i + r) * nq
                out.append((s, value, np.arange(row, row + nq)))
        return out


__all__ = ["ACC_SCALE", "InterpolantLimits", "VEL_SCALE", "interval_terms"]
