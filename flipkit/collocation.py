"""Decision-variable layout and node evaluation for one collocation segment.

Per segment (paper Sec. III–IV): 21 nodes (N = 20) evenly spaced on [0, T], at each node
(q_i, q̇_i, q̈_i, u_i) — 504 values for a 6-DOF arm —, Bezier coefficients α ∈ R^42 (one row of
7 per joint) and the duration T: 547 decision variables.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .bezier import Bezier
from .errors import ConfigError
from .robot import Robot, SpatulaState

N_DEFAULT = 20


class Layout:
    """Index bookkeeping of the 547-vector Z = (q_0, q̇_0, q̈_0, u_0, …, q_N, …, α, T).

    Args:
        nq: Number of joints.
        N: Number of intervals (N + 1 nodes); must be even for Hermite–Simpson.
        degree: Bezier degree.
    """

    def __init__(self, nq: int = 6, N: int = N_DEFAULT, degree: int = 6):
        if N < 2 or N % 2:
            raise ConfigError(f"N must be an even number >= 2 (odd nodes are midpoints), got {N}")
        self.nq, self.N, self.bezier = nq, N, Bezier(degree)
        self.n_nodes = N + 1
        self.node_size = 4 * nq
        self.alpha_start = self.n_nodes * self.node_size
        self.n_alpha = nq * self.bezier.n_coeffs
        self.T_index = self.alpha_start + self.n_alpha
        self.n = self.T_index + 1
        self.s = np.linspace(0.0, 1.0, self.n_nodes)  # node times t_i = s_i T

    def _field(self, i: int, k: int) -> np.ndarray:
        start = i * self.node_size + k * self.nq
        return np.arange(start, start + self.nq)

    def iq(self, i: int) -> np.ndarray:
        """Indices of q_i."""
        return self._field(i, 0)

    def iqd(self, i: int) -> np.ndarray:
        """Indices of q̇_i."""
        return self._field(i, 1)

    def iqdd(self, i: int) -> np.ndarray:
        """Indices of q̈_i."""
        return self._field(i, 2)

    def iu(self, i: int) -> np.ndarray:
        """Indices of u_i."""
        return self._field(i, 3)

    def ialpha(self, j: int) -> np.ndarray:
        """Indices of the Bezier coefficients α_j0..α_jM of joint j."""
        start = self.alpha_start + j * self.bezier.n_coeffs
        return np.arange(start, start + self.bezier.n_coeffs)

    def nodes(self, x: np.ndarray) -> np.ndarray:
        """View of x as (N+1, 4, nq): [:, 0] q, [:, 1] q̇, [:, 2] q̈, [:, 3] u."""
        return x[: self.alpha_start].reshape(self.n_nodes, 4, self.nq)

    def alpha(self, x: np.ndarray) -> np.ndarray:
        """Bezier coefficients as (nq, M+1)."""
        return x[self.alpha_start: self.T_index].reshape(self.nq, self.bezier.n_coeffs)

    def pack(self, q, qd, qdd, u, alpha, T) -> np.ndarray:
        """Assemble Z from per-node arrays (N+1, nq), α (nq, M+1) and T (s)."""
        x = np.empty(self.n)
        self.nodes(x)[:] = np.stack([q, qd, qdd, u], axis=1)
        x[self.alpha_start: self.T_index] = np.asarray(alpha).ravel()
        x[self.T_index] = T
        return x


@dataclass
class Evaluation:
    """One point Z with per-node kinematics and dynamics computed once, on demand.

    Blocks of constraints share it so that each node's pinocchio work is done once.
    """

    layout: Layout
    robot: Robot
    x: np.ndarray
    _states: dict = field(default_factory=dict)
    _rnea: dict = field(default_factory=dict)

    @property
    def T(self) -> float:
        return float(self.x[self.layout.T_index])

    def node(self, i: int):
        """(q_i, q̇_i, q̈_i, u_i)."""
        return self.layout.nodes(self.x)[i]

    def state(self, i: int) -> SpatulaState:
        """Spatula kinematics with Jacobians at node i."""
        if i not in self._states:
            q, qd, qdd, _ = self.node(i)
            self._states[i] = self.robot.state(q, qd, qdd)
        return self._states[i]

    def point_state(self, i: int, point) -> SpatulaState:
        """Kinematics at node i of a blade point (spatula frame, m), e.g. under the burger."""
        key = (i, *(float(v) for v in point))
        if key not in self._states:
            q, qd, qdd, _ = self.node(i)
            self._states[key] = self.robot.state(q, qd, qdd, point)
        return self._states[key]

    def rnea(self, i: int):
        """RNEA torque and its Jacobians at node i."""
        if i not in self._rnea:
            q, qd, qdd, _ = self.node(i)
            self._rnea[i] = self.robot.dynamics_residual_jacobians(q, qd, qdd)
        return self._rnea[i]


def bezier_guess(layout: Layout, robot: Robot, q_start, q_end, T: float, qd_start=None) -> np.ndarray:
    """A dynamically consistent initial guess: a Bezier path from q_start to q_end.

    α_0 = q_start, α_1 = q_start + q̇_start T/M (matching the start velocity), α_{M−2..M} =
    q_end (arriving at rest), α_2..α_{M−3} blended linearly; q, q̇, q̈ at the nodes follow
    the polynomial exactly and u = RNEA(q, q̇, q̈), so only the Hermite–Simpson defects and
    path inequalities are off.
    """
    b, M = layout.bezier, layout.bezier.degree
    q0, q1 = np.asarray(q_start, float), np.asarray(q_end, float)
    v0 = np.zeros_like(q0) if qd_start is None else np.asarray(qd_start, float)
    alpha = np.empty((layout.nq, M + 1))
    alpha[:, 0] = q0
    alpha[:, 1] = q0 + v0 * T / M
    for k in range(2, M - 2):
        w = (k - 1) / (M - 2)
        alpha[:, k] = (1 - w) * alpha[:, 1] + w * q1
    alpha[:, M - 2:] = q1[:, None]
    t = layout.s * T
    q, qd, qdd = (b.evaluate(alpha, t, T, r) for r in range(3))
    u = np.array([robot.inverse_dynamics(*z) for z in zip(q, qd, qdd)])
    return layout.pack(q, qd, qdd, u, alpha, T)


def fit_guess(layout: Layout, robot: Robot, q_nodes, T: float, qd_start=None,
              rest_at_end: bool = False) -> np.ndarray:
    """An initial guess whose Bezier polynomial fits joint waypoints at the nodes.

    α_0 = q_0 and α_1 = q_0 + q̇_start T/M keep the start state exact (and α_{M−1} = α_M a
    rest at the end when asked); the other coefficients are least-squares fits to the
    waypoints (e.g. IK along a task-space path). q, q̇, q̈ then follow the polynomial and
    u = RNEA(q, q̇, q̈).
    """
    b, M = layout.bezier, layout.bezier.degree
    qn = np.asarray(q_nodes, float)
    v0 = np.zeros(layout.nq) if qd_start is None else np.asarray(qd_start, float)
    B = b.basis(layout.s)
    alpha = np.zeros((layout.nq, M + 1))
    alpha[:, 0], alpha[:, 1] = qn[0], qn[0] + v0 * T / M
    free = list(range(2, M + 1))
    Bf = B[:, free].copy()
    if rest_at_end:  # α_{M-1} = α_M: merge the two columns
        Bf[:, -2] += Bf[:, -1]
        Bf = Bf[:, :-1]
    rhs = qn - B[:, :2] @ alpha[:, :2].T
    sol = np.linalg.lstsq(Bf, rhs, rcond=None)[0].T
    if rest_at_end:
        sol = np.column_stack([sol, sol[:, -1]])
    alpha[:, 2:] = sol
    t = layout.s * T
    q, qd, qdd = (b.evaluate(alpha, t, T, r) for r in range(3))
    u = np.array([robot.inverse_dynamics(*z) for z in zip(q, qd, qdd)])
    return layout.pack(q, qd, qdd, u, alpha, T)
