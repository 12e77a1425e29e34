"""Decision-variable layout and node evaluation for one collocation segment.

Per segment (paper Sec. III–IV): 21 nodes (N = 20) evenly spaced on [0, T], at each node
(q_i, q̇_i, q̈_i, u_i) — 504 values for a 6-DOF arm —, Bezier coefficients α ∈ R^42 (one row of
7 per joint) and the duration T: 547 decision variables.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from flipkit.model.bezier import Bezier
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot, SpatulaState

N_DEFAULT = 20


class Layout:
    """Index bookkeeping of the 547-vector Z = (q_0, q̇_0, q̈_0, u_0, …, q_N, …, α, T).

    Args:
        nq: Number of joints.
        N: Number of intervals (N + 1 nodes); must be even for Hermite–Simpson.
        degree: Bezier degree.
        patterns: Where the constraint blocks on this layout find and keep their sparsity
            patterns (:class:`~flipkit.transcription.constraints.base.Patterns`, shared by
            the layouts of many segments); default none: each block fills its own.
    """

    def __init__(self, nq: int = 6, N: int = N_DEFAULT, degree: int = 6, patterns=None):
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
        self.key = (nq, N, degree)  # what every index of the layout depends on
        self.patterns = patterns

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

    Blocks of constraints share it so that each node's pinocchio work is done once: the first
    request for kinematics computes the blade centre's and every point of ``points`` at every
    node in one pass (:meth:`~flipkit.model.robot.Robot.states`).

    Attributes:
        points: Blade points (spatula frame, m) the blocks will ask for, as tuples.
    """

    layout: Layout
    robot: Robot
    x: np.ndarray
    points: tuple = ()
    _states: dict = field(default_factory=dict)
    _batches: dict = field(default_factory=dict)
    _rnea: dict = field(default_factory=dict)

    @property
    def T(self) -> float:
        return float(self.x[self.layout.T_index])

    def node(self, i: int):
        """(q_i, q̇_i, q̈_i, u_i)."""
        return self.layout.nodes(self.x)[i]

    def states(self, nodes=slice(None), point=None) -> SpatulaState:
        """Spatula kinematics with Jacobians at ``nodes`` (an index array or a slice of the
        node axis; an int: that node's state alone), of the blade centre or of a blade
        ``point`` (spatula frame, m)."""
        key = None if point is None else tuple(float(c) for c in point)
        if key not in self._batches:  # the first request: the centre and every expected point
            wanted = [key] if self._batches else [*self.points, key]
            pts = list(dict.fromkeys(k for k in wanted if k is not None))
            X = self.layout.nodes(self.x)
            centre, at_points = self.robot.states(X[:, 0], X[:, 1], X[:, 2], pts)
            self._batches.setdefault(None, centre)
            self._batches.update(zip(pts, at_points))
        return self._batches[key].take(nodes)

    def state(self, i: int) -> SpatulaState:
        """Spatula kinematics with Jacobians at node i."""
        return self.states(i)

    def point_state(self, i: int, point) -> SpatulaState:
        """Kinematics at node i of a blade point (spatula frame, m), e.g. under the burger."""
        return self.states(i, point)

    def rnea(self, i: int):
        """RNEA torque and its Jacobians at node i."""
        if i not in self._rnea:
            q, qd, qdd, _ = self.node(i)
            self._rnea[i] = self.robot.dynamics_residual_jacobians(q, qd, qdd)
        return self._rnea[i]
