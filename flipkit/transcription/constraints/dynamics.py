"""Dynamics (eq. 7), Hermite–Simpson collocation (eqs. 8–9) and Bezier outputs (eq. 18)."""

from __future__ import annotations

import casadi as ca
import numpy as np

from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.registry import Check


class Dynamics(Block):
    """Implicit dynamics D(q_i)q̈_i + C q̇_i + G − u_i = 0 at every node (eq. 7).

    Args:
        layout: Variable layout. robot: Model (its RNEA, payload included).
        torque_scale: Per-joint torque scale (N·m); rows are divided by it.
    """

    def __init__(self, layout, torque_scale):
        super().__init__("dynamics", layout)
        nq = layout.nq

        def fill():
            for i in range(layout.n_nodes):
                cols = np.concatenate([layout.iq(i), layout.iqd(i), layout.iqdd(i), layout.iu(i)])
                self._add(i * nq, nq, cols)

        self._pattern(layout.key, fill)
        self.m = nq * layout.n_nodes
        self._finish(0.0, 0.0, np.tile(1.0 / np.asarray(torque_scale), layout.n_nodes))

    def project(self, x: np.ndarray, robot) -> np.ndarray:
        """x with u_i = RNEA(q_i, q̇_i, q̈_i) at every node: these rows hold exactly.

        u enters eq. (7) alone and linearly, so this is the exact nonlinear correction of
        the dynamics rows (the SQP applies it to every trial point).
        """
        x = np.array(x, float)
        nodes = self.layout.nodes(x)
        for i in range(self.layout.n_nodes):
            nodes[i, 3] = robot.inverse_dynamics(nodes[i, 0], nodes[i, 1], nodes[i, 2])
        return x

    def evaluate(self, ev):
        n, nq = self.layout.n_nodes, self.layout.nq
        vals, jac = np.empty((n, nq)), np.empty((n, nq, 4 * nq))
        for i in range(n):  # row-major per node: ∂/∂q, ∂/∂q̇, ∂/∂q̈, ∂/∂u side by side
            tau, *parts = ev.rnea(i)
            vals[i] = tau - ev.node(i)[3]
            for f, block in enumerate(parts):
                jac[i, :, f * nq:(f + 1) * nq] = block
        return vals.ravel(), jac.ravel()

    check = Check(("dynamics",))

    def symbolic(self, acc):
        nq = self.layout.nq
        out = []
        for i in range(self.layout.n_nodes):
            s = acc.stage_of(i)
            out.append((s, acc.rnea(i, s) - acc.node(i, s)[3], np.arange(i * nq, (i + 1) * nq)))
        return out


class HermiteSimpson(Block):
    """Hermite–Simpson collocation with defects at the odd (midpoint) nodes i (eqs. 8–9).

    For x ∈ {q, q̇} with ẋ ∈ {q̇, q̈} and Δt_i = t_{i+1} − t_{i−1} = 2T/N:

    * interpolation defect δ_i = x_i − (x_{i−1} + x_{i+1})/2 − Δt_i (ẋ_{i−1} − ẋ_{i+1})/8,
    * Simpson defect σ_i = x_{i+1} − x_{i−1} − Δt_i (ẋ_{i−1} + 4ẋ_i + ẋ_{i+1})/6.

    σ_i = 0 is the paper's ξ_i = ẋ_i − ẋ̄_i = 0 multiplied by −2Δt_i/3 (the Hermite
    interpolant's midpoint slope is ẋ̄_i = 3(x_{i+1} − x_{i−1})/(2Δt_i) − (ẋ_{i−1} + ẋ_{i+1})/4),
    so imposing both would repeat one equation; σ keeps the constraint polynomial in T.
    """

    def __init__(self, layout, qd_scale: float = 1.0):
        super().__init__("hermite_simpson", layout)
        nq = layout.nq

        def fill():
            row = 0
            for i in range(1, layout.N, 2):
                for xf, dxf in ((layout.iq, layout.iqd), (layout.iqd, layout.iqdd)):
                    a, b = i - 1, i + 1
                    for cols in ((xf(i), xf(a), xf(b), dxf(a), dxf(b)),  # δ
                                 (xf(b), xf(a), dxf(a), dxf(i), dxf(b))):  # σ
                        for c in cols:
                            self._rows.append(np.arange(row, row + nq))
                            self._cols.append(c)
                        self._add(row, nq, [layout.T_index])
                        row += nq

        self._pattern(layout.key, fill)
        self.m = 4 * nq * (layout.N // 2)
        group = np.concatenate([np.ones(2 * nq), np.full(2 * nq, qd_scale)])
        self._finish(0.0, 0.0, np.tile(group, layout.N // 2))

    def evaluate(self, ev):
        # All intervals at once, in the pattern's order: interval, x = q then q̇, δ then σ,
        # then the six column groups (x_i / x_b, x_a, ẋ_a, ẋ_i / ẋ_b, ẋ_b, T) of nq entries.
        L, nodes, T = self.layout, self.layout.nodes(ev.x), ev.T
        dt, ddt = 2 * T / L.N, 2 / L.N
        x = nodes[:, :3]  # (N+1, 3, nq): q, q̇, q̈
        xa, xi, xb = x[0:-1:2, :2], x[1::2, :2], x[2::2, :2]  # (N/2, 2, nq): x = q, q̇
        da, di, db = x[0:-1:2, 1:], x[1::2, 1:], x[2::2, 1:]  # their derivatives
        s = da + 4 * di + db
        vals = np.stack([xi - (xa + xb) / 2 - dt * (da - db) / 8, xb - xa - dt * s / 6], axis=2)
        one = np.ones_like(xa)
        jac = np.stack([
            np.stack([one, -one / 2, -one / 2, -one * dt / 8, one * dt / 8, -ddt * (da - db) / 8], 2),
            np.stack([one, -one, -one * dt / 6, -one * 4 * dt / 6, -one * dt / 6, -ddt * s / 6], 2),
        ], axis=2)  # (N/2, 2, 2, 6, nq)
        return vals.ravel(), jac.ravel()

    check = Check(("defects",))

    def symbolic(self, acc):
        L, nq, out, row = self.layout, self.layout.nq, [], 0
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


class BezierOutput(Block):
    """Output dynamics ÿ + 2εẏ + ε²y = 0 at every node with y(0) = ẏ(0) = 0 (eqs. 17–18).

    y = q − P(t), P the degree-M Bezier polynomial with coefficients α and duration T.

    Args:
        layout: Variable layout. epsilon: Convergence rate ε (1/s).
    """

    def __init__(self, layout, epsilon: float):
        super().__init__("bezier_output", layout)
        self.eps = float(epsilon)
        nq, b = layout.nq, layout.bezier
        self.B = [b.basis(layout.s, r) for r in range(3)]  # (N+1, M+1) each
        row = nq * layout.n_nodes

        def fill():
            for i in range(layout.n_nodes):
                for f in (layout.iq, layout.iqd, layout.iqdd):
                    self._rows.append(np.arange(i * nq, (i + 1) * nq))
                    self._cols.append(f(i))
                for j in range(nq):
                    self._add(i * nq + j, 1, np.append(layout.ialpha(j), layout.T_index))
            for j in range(nq):  # y(0) = q_0 − α_j0
                self._add(row + j, 1, [layout.iq(0)[j], layout.ialpha(j)[0]])
            for j in range(nq):  # ẏ(0) = q̇_0 − M(α_j1 − α_j0)/T
                self._add(row + nq + j, 1, [layout.iqd(0)[j], *layout.ialpha(j)[:2],
                                            layout.T_index])

        self._pattern(layout.key, fill)
        self.m = row + 2 * nq
        scale = np.concatenate([np.full(row, 1 / self.eps**2), np.ones(nq), np.full(nq, 0.1)])
        self._finish(0.0, 0.0, scale)

    def evaluate(self, ev):
        # All nodes at once, in the pattern's order: per node the q, q̇, q̈ entries (nq each),
        # then per joint the M+1 α entries and T; then the two start rows per joint.
        L, e, T = self.layout, self.eps, ev.T
        nodes, alpha = L.nodes(ev.x), L.alpha(ev.x)
        B0, B1, B2 = self.B
        nq, n, M = L.nq, L.n_nodes, L.bezier.degree
        C = B2 / T**2 + 2 * e * B1 / T + e**2 * B0  # (N+1, M+1)
        dC = -2 * B2 / T**3 - 2 * e * B1 / T**2
        q, qd, qdd = nodes[:, 0], nodes[:, 1], nodes[:, 2]
        vals = qdd + 2 * e * qd + e**2 * q - C @ alpha.T  # (N+1, nq)
        per_joint = np.empty((n, nq, M + 2))
        per_joint[:, :, : M + 1] = -C[:, None, :]
        per_joint[:, :, M + 1] = -(dC @ alpha.T)
        states = np.repeat(np.array([e**2, 2 * e, 1.0]), nq)
        jac_nodes = np.concatenate([np.broadcast_to(states, (n, 3 * nq)), per_joint.reshape(n, -1)], 1)
        a0, a1 = alpha[:, 0], alpha[:, 1]
        start = np.column_stack([np.ones(nq), np.full(nq, M / T), np.full(nq, -M / T),
                                 M * (a1 - a0) / T**2])
        return (np.concatenate([vals.ravel(), q[0] - a0, qd[0] - M * (a1 - a0) / T]),
                np.concatenate([jac_nodes.ravel(), np.tile([1.0, -1.0], nq), start.ravel()]))

    check = Check(none="the outputs y = q − P(t) shape the motion the solver looks for; a "
                       "plan records no α, and what the arm must meet (dynamics, limits, "
                       "poses) is checked by the other groups")

    def _alpha(self, acc, s) -> ca.SX:
        """α as an (nq, M+1) SX matrix, held by stage s."""
        L = self.layout
        flat = ca.vertcat(*[acc.var(int(j), s) for j in np.arange(L.alpha_start, L.T_index)])
        return ca.reshape(flat, L.bezier.n_coeffs, L.nq).T  # row-major (nq, M+1)

    def symbolic(self, acc):
        L, nq, e, out = self.layout, self.layout.nq, self.eps, []
        B0, B1, B2 = self.B
        for i in range(L.n_nodes):
            s = acc.stage_of(i)
            q, qd, qdd, _ = acc.node(i, s)
            T, alpha = acc.var(L.T_index, s), self._alpha(acc, s)
            c = ca.DM(B2[i]) / T**2 + 2 * e * ca.DM(B1[i]) / T + e**2 * ca.DM(B0[i])
            out.append((s, qdd + 2 * e * qd + e**2 * q - alpha @ c,
                        np.arange(i * nq, (i + 1) * nq)))
        s0, M, row = acc.stage_of(0), L.bezier.degree, L.n_nodes * nq
        q0, qd0 = acc.node(0, s0)[:2]
        T, alpha = acc.var(L.T_index, s0), self._alpha(acc, s0)
        out.append((s0, q0 - alpha[:, 0], np.arange(row, row + nq)))
        out.append((s0, qd0 - M * (alpha[:, 1] - alpha[:, 0]) / T,
                    np.arange(row + nq, row + 2 * nq)))
        return out
