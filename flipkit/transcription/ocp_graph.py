"""One segment's collocation NLP as a single stage-wise CasADi SX graph (exact derivatives).

The same problem as the :class:`~flipkit.transcription.nlp.NLP` — the same constraint rows
(:mod:`flipkit.transcription.symbolic_blocks`), bounds, row and variable scales and scaled
objective obj_scale · Σ u_i² — with its variables ordered by stage, as an optimal-control
solver (FATROP) needs them. With K = N/2 Hermite–Simpson intervals:

* stage k < K holds the state x_k = (q_2k, q̇_2k, q̈_2k, α, T) and the controls
  u_k = (u_2k, q_2k+1, q̇_2k+1, q̈_2k+1, u_2k+1, q'_2k+2, q̇'_2k+2, q̈'_2k+2): the midpoint node
  and a copy of the interval's end node (the next stage's), on which the interval's defects
  are stated;
* the gap rows x_{k+1} − (q'_2k+2, q̇'_2k+2, q̈'_2k+2, α, T) = 0 carry the copies, the Bezier
  coefficients and the duration to the next stage;
* the last stage K holds x_K = (q_N, q̇_N, q̈_N, α, T) and u_K = u_N.

Every row of the NLP reads the variables of one stage (a node's rows that of the node; an
interval's defects that of its first node; α and T are in every stage), so the constraint
vector is [gap_0, path_0, gap_1, path_1, …, path_K] and the Lagrangian's Hessian is block
diagonal by stage. The graph's variables are the NLP's, plus the copies: at a point whose
copies equal their originals (:meth:`OcpGraph.from_nlp_point`) the gap rows vanish and each
path row equals the NLP's scaled row ``row_source`` (a test checks it); so both problems have
the same solutions.

Tried and not kept: solving each interval's Simpson rows σ for (q, q̇) at its end and making
them the gap rows (controls 36 instead of 48 per stage); FATROP then failed on the three
translates tried (it solves 4 of the 6 with the copies).
"""

from __future__ import annotations

import hashlib

import casadi as ca
import numpy as np

from flipkit.errors import ConfigError
from flipkit.model.casadi_dynamics import CasadiArm
from flipkit.transcription.nlp import NLP
from flipkit.transcription.symbolic_blocks import symbolic_rows


class _Access:
    """Variables of the graph as each stage holds them (unscaled SX), with per-node caches."""

    def __init__(self, graph: "OcpGraph", w: ca.SX):
        self.graph, self.arm = graph, graph.arm
        self.w = w
        self._kin, self._rnea = {}, {}

    def stage_of(self, i: int) -> int:
        return i // 2

    def var(self, index: int, stage: int) -> ca.SX:
        pos = self.graph.position[stage].get(int(index))
        if pos is None:
            raise ConfigError(f"stage {stage} holds no copy of variable {index}")
        return self.w[pos] * self.graph.scale[pos]

    def _vec(self, idx, stage) -> ca.SX:
        return ca.vertcat(*[self.var(int(j), stage) for j in idx])

    def node(self, i: int, stage: int):
        L = self.graph.layout
        u = (self._vec(L.iu(i), stage) if L.iu(i)[0] in self.graph.position[stage] else None)
        return (self._vec(L.iq(i), stage), self._vec(L.iqd(i), stage),
                self._vec(L.iqdd(i), stage), u)

    def kinematics(self, i: int, stage: int, point=None):
        key = (i, stage, None if point is None else tuple(float(v) for v in point))
        if key not in self._kin:
            q, qd, qdd, _ = self.node(i, stage)
            self._kin[key] = self.arm.frame(q, qd, qdd, point)
        return self._kin[key]

    def rnea(self, i: int, stage: int) -> ca.SX:
        if (i, stage) not in self._rnea:
            self._rnea[(i, stage)] = self.arm.rnea_function(*self.node(i, stage)[:3])
        return self._rnea[(i, stage)]


class OcpGraph:
    """The stage-wise SX graph of ``nlp`` in scaled units (z = x / x_scale).

    Args:
        nlp: The collocation NLP (every block must have a symbolic form).
        arm: Symbolic model of ``nlp.robot`` (built when not given).

    Attributes:
        n: Number of graph variables. index: The NLP variable each graph variable is (a copy
            of). scale: Its scale. K: Number of stages − 1 (FATROP's horizon N).
        nx, nu, ng: Per stage (K + 1 entries): states, controls, path rows.
        problem: ``{"x", "f", "g"}`` for :func:`casadi.nlpsol`. lbx, ubx, lbg, ubg: Bounds
            (scaled). row_source: For each row of g, the NLP row it is (scaled), −1 for a
            gap row. primary: For each NLP variable, the graph variable that gives its value.

    Raises:
        NoSymbolicFormError: A block of ``nlp`` without a symbolic form.
        ConfigError: N is not even.
    """

    def __init__(self, nlp: NLP, arm: CasadiArm | None = None):
        L = self.layout = nlp.layout
        if L.N % 2:
            raise ConfigError(f"the stage-wise graph needs an even N, got {L.N}")
        self.nlp, self.arm = nlp, arm or CasadiArm(nlp.robot)
        K = self.K = L.N // 2
        shared = np.arange(L.alpha_start, L.n)  # α and T
        xs, us = [], []
        for k in range(K + 1):
            a = 2 * k
            xs.append(np.concatenate([L.iq(a), L.iqd(a), L.iqdd(a), shared]))
            if k < K:
                us.append(np.concatenate([L.iu(a), L.iq(a + 1), L.iqd(a + 1), L.iqdd(a + 1),
                                          L.iu(a + 1), L.iq(a + 2), L.iqd(a + 2), L.iqdd(a + 2)]))
            else:
                us.append(L.iu(a))
        self.nx, self.nu = [len(x) for x in xs], [len(u) for u in us]
        self.index = np.concatenate([np.concatenate([x, u]) for x, u in zip(xs, us)])
        self.n = len(self.index)
        starts = np.cumsum([0] + [nx + nu for nx, nu in zip(self.nx, self.nu)])
        self.position = [{int(j): int(starts[k] + p) for p, j in enumerate(np.concatenate([x, u]))}
                         for k, (x, u) in enumerate(zip(xs, us))]
        self.scale = nlp.x_scale[self.index]
        self.primary = np.array([self.position[k // L.node_size // 2 if k < L.alpha_start else 0][k]
                                 for k in range(L.n)])
        w = ca.SX.sym("z", self.n)
        acc = _Access(self, w)
        path = [[] for _ in range(K + 1)]  # (SX rows, NLP row indices)
        for block, rows in zip(nlp.blocks, nlp.block_slices.values()):
            for stage, values, local in symbolic_rows(block, acc):
                path[stage].append((values, np.arange(rows.start, rows.stop)[local]))
        g, source = [], []
        for k in range(K + 1):
            if k < K:  # x_{k+1} − its copy in stage k (scaled: the same scale on both sides)
                nxt = xs[k + 1]
                g.append(ca.vertcat(*[w[self.position[k + 1][int(j)]] - w[self.position[k][int(j)]]
                                      for j in nxt]))
                source.append(np.full(len(nxt), -1))
            for values, rows in path[k]:
                g.append(ca.DM(nlp.c_scale[rows]) * values)
                source.append(rows)
        self.ng = [sum(len(r) for _, r in path[k]) for k in range(K + 1)]
        self.row_source = np.concatenate(source)
        u_pos = [self.position[i // 2][int(j)] for i in range(L.n_nodes) for j in L.iu(i)]
        u = w[u_pos] * ca.DM(self.scale[u_pos])
        self.problem = {"x": w, "f": nlp.obj_scale * ca.sumsqr(u), "g": ca.vertcat(*g)}
        self.lbx, self.ubx = nlp.x_lb[self.index] / self.scale, nlp.x_ub[self.index] / self.scale
        gap = self.row_source < 0
        src = np.where(gap, 0, self.row_source)
        self.lbg = np.where(gap, 0.0, nlp.c_scale[src] * nlp.c_lo[src])
        self.ubg = np.where(gap, 0.0, nlp.c_scale[src] * nlp.c_hi[src])
        self.constraints = ca.Function("g", [w], [self.problem["g"]])

    @property
    def key(self) -> str:
        """Hash of the graph's functions (objective, rows), structure and scales: graphs with
        equal keys differ only in their bounds (start state, targets, limits) and can share
        one built solver."""
        if not hasattr(self, "_key"):
            fg = ca.Function("fg", [self.problem["x"]], [self.problem["f"], self.problem["g"]])
            h = hashlib.sha1(fg.serialize().encode())
            for arr in (self.index, self.row_source, np.array(self.nx + self.nu + self.ng)):
                h.update(np.ascontiguousarray(arr).tobytes())
            self._key = h.hexdigest()
        return self._key

    @property
    def structure(self) -> dict:
        """FATROP's manual structure options: ``N``, ``nx``, ``nu``, ``ng``."""
        return {"N": self.K, "nx": list(self.nx), "nu": list(self.nu), "ng": list(self.ng)}

    def from_nlp_point(self, x) -> np.ndarray:
        """Graph variables (scaled) of the NLP point x (unscaled): copies equal originals."""
        return np.asarray(x, float)[self.index] / self.scale

    def to_nlp_point(self, z) -> np.ndarray:
        """The NLP point (unscaled) of graph variables z, each variable read from its primary
        holder (a node's own stage; α and T from stage 0)."""
        z = np.asarray(z, float).ravel()
        return z[self.primary] * self.scale[self.primary]

