"""One segment's collocation NLP as an optimal control problem in FATROP's form (CasADi SX).

FATROP's problem class (its documentation, ``docs/problem_class.tex``, and the CasADi
cookbook) is a sequence of stages k = 0..K with states x_k, controls u_k, explicit dynamics
x_{k+1} = F_k(x_k, u_k) and path constraints on (x_k, u_k) alone; the variables are ordered
x_0, u_0, x_1, …, u_K and the rows dynamics_0, path_0, dynamics_1, …, path_K. With
K = N/2 Hermite–Simpson intervals this graph is the :class:`~flipkit.transcription.nlp.NLP`
in that form:

* stage k holds the knot x_k = (q_2k, q̇_2k, q̈_2k) of its interval, and T and the Bezier
  coefficients α. FATROP's problem class has no free variable shared by all stages (its
  parameters are fixed numbers), so the stage-invariant T and α ride in every state with
  the dynamics T_{k+1} = T_k, α_{k+1} = α_k;
* its controls (k < K) are the knot's torque u_2k, the midpoint (q, q̇, q̈, u)_2k+1 and the
  next knot's q̈_2k+2; the last stage's control is u_N (or, for HPIPM, u_N is a state of the
  last stage and its copy a control of the one before);
* the dynamics are the interval's Simpson rules solved for the next knot:
  q̇_2k+2 = q̇_2k + Δt (q̈_2k + 4 q̈_2k+1 + q̈_2k+2)/6 and
  q_2k+2 = q_2k + Δt (q̇_2k + 4 q̇_2k+1 + q̇_2k+2)/6 (Δt = 2T/N), q̈_2k+2 from the control.

The NLP's Simpson rows σ are the dynamics rows (at a point of the NLP, x_{k+1} − F_k is σ_q̇
and σ_q + Δt σ_q̇/6, divided by the knot's scale: the same equations). Every other NLP row reads one
stage and is a path row of that stage, equal to the NLP's scaled row ``row_source`` (a test
checks both). The objective is the NLP's scaled obj_scale · Σ u_i², or that Σ u_i² with
another scale (``obj_scale``): the optimum is the same.
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
    """The NLP's variables as each stage reads them (unscaled SX): its own variables, and the
    next knot's q and q̇ as the Simpson rules give them; per-node caches of the kinematics."""

    def __init__(self, graph: "OcpGraph", w: ca.SX):
        self.graph, self.arm, self.w = graph, graph.arm, w
        self.derived: list[dict] = [{} for _ in graph.position]
        self._kin, self._rnea = {}, {}

    def stage_of(self, i: int) -> int:
        return i // 2

    def var(self, index: int, stage: int) -> ca.SX:
        pos = self.graph.position[stage].get(int(index))
        if pos is not None:
            return self.w[pos] * self.graph.scale[pos]
        if int(index) in self.derived[stage]:
            return self.derived[stage][int(index)]
        raise ConfigError(f"stage {stage} does not read variable {index}")

    def _vec(self, idx, stage) -> ca.SX:
        return ca.vertcat(*[self.var(int(j), stage) for j in idx])

    def node(self, i: int, stage: int):
        L = self.graph.layout
        u = self._vec(L.iu(i), stage) if L.iu(i)[0] in self.graph.position[stage] else None
        return (self._vec(L.iq(i), stage), self._vec(L.iqd(i), stage),
                self._vec(L.iqdd(i), stage), u)

    def kinematics(self, i: int, stage: int, point=None):
        key = (i, stage, None if point is None else tuple(float(v) for v in point))
        if key not in self._kin:
            self._kin[key] = self.arm.frame(*self.node(i, stage)[:3], point)
        return self._kin[key]

    def rnea(self, i: int, stage: int) -> ca.SX:
        if (i, stage) not in self._rnea:
            self._rnea[(i, stage)] = self.arm.rnea_function(*self.node(i, stage)[:3])
        return self._rnea[(i, stage)]

    def simpson(self, k: int) -> None:
        """Store the next knot's (q, q̇) as stage k's Simpson rules give them."""
        L, a, m, b = self.graph.layout, 2 * k, 2 * k + 1, 2 * k + 2
        dt = 2 * self.var(L.T_index, k) / L.N
        (q_a, qd_a, qdd_a, _), (_, qd_m, qdd_m, _) = self.node(a, k), self.node(m, k)
        qdd_b = self._vec(L.iqdd(b), k)
        qd_b = qd_a + dt * (qdd_a + 4 * qdd_m + qdd_b) / 6
        q_b = q_a + dt * (qd_a + 4 * qd_m + qd_b) / 6
        for idx, value in ((L.iq(b), q_b), (L.iqd(b), qd_b)):
            self.derived[k].update({int(j): value[r] for r, j in enumerate(idx)})


def _is_simpson_row(block, local: np.ndarray) -> bool:
    """Whether ``local`` rows of a Hermite–Simpson block are σ rows (δ, σ alternate by nq)."""
    return block.name == "hermite_simpson" and (int(local[0]) // block.layout.nq) % 2 == 1


class OcpGraph:
    """The segment NLP as FATROP's stage-wise OCP, in scaled units (z = x / x_scale).

    Args:
        nlp: The collocation NLP (every block must have a symbolic form).
        arm: Symbolic model of ``nlp.robot`` (built when not given).
        obj_scale: Scale of Σ u_i² in the objective (default the NLP's ``obj_scale``).
        final_control: The last stage has the control u_N (FATROP). Without it (HPIPM's OCP
            QP has no last control) u_N is a state of the last stage, its copy a control of
            the stage before.

    Attributes:
        n: Number of graph variables. index: The NLP variable each graph variable is (a copy
            of). scale: Its scale. K: Number of stages − 1 (FATROP's horizon N).
        nx, nu, ng: Per stage (K + 1 entries): states, controls, path rows.
        obj_scale, final_control: As given (``obj_scale`` resolved).
        problem: ``{"x", "f", "g"}`` for :func:`casadi.nlpsol`. lbx, ubx, lbg, ubg: Bounds
            (scaled). row_source: For each row of g, the NLP row it is (scaled), −1 for a
            dynamics row. primary: For each NLP variable, the graph variable holding it.

    Raises:
        NoSymbolicFormError: A block of ``nlp`` without a symbolic form.
        ConfigError: N is not even.
    """

    def __init__(self, nlp: NLP, arm: CasadiArm | None = None, obj_scale: float | None = None,
                 final_control: bool = True):
        L = self.layout = nlp.layout
        if L.N % 2:
            raise ConfigError(f"the stage-wise graph needs an even N, got {L.N}")
        self.nlp, self.arm = nlp, arm or CasadiArm(nlp.robot)
        self.obj_scale = nlp.obj_scale if obj_scale is None else float(obj_scale)
        self.final_control = bool(final_control)
        K = self.K = L.N // 2
        shared = np.concatenate([[L.T_index], np.arange(L.alpha_start, L.T_index)])
        xs = [np.concatenate([L.iq(2 * k), L.iqd(2 * k), L.iqdd(2 * k), shared])
              for k in range(K + 1)]
        us = [np.concatenate([L.iu(2 * k), L.iq(2 * k + 1), L.iqd(2 * k + 1), L.iqdd(2 * k + 1),
                              L.iu(2 * k + 1), L.iqdd(2 * k + 2)]) for k in range(K)]
        us.append(L.iu(L.N))
        if not final_control:
            xs[K], us[K - 1] = np.concatenate([xs[K], us[K]]), np.concatenate([us[K - 1], us[K]])
            us[K] = us[K][:0]
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
        for k in range(K):
            acc.simpson(k)
        path = [[] for _ in range(K + 1)]  # (SX rows, NLP row indices)
        for block, rows in zip(nlp.blocks, nlp.block_slices.values()):
            for stage, values, local in symbolic_rows(block, acc):
                if not _is_simpson_row(block, local):
                    path[stage].append((values, np.arange(rows.start, rows.stop)[local]))
        g, source = [], []
        for k in range(K + 1):
            if k < K:  # x_{k+1} − F_k(x_k, u_k), scaled by the state's scale
                nxt = xs[k + 1]
                g.append(ca.vertcat(*[w[self.position[k + 1][int(j)]]
                                      - acc.var(int(j), k) / nlp.x_scale[j] for j in nxt]))
                source.append(np.full(len(nxt), -1))
            for values, rows in path[k]:
                g.append(ca.DM(nlp.c_scale[rows]) * values)
                source.append(rows)
        self.ng = [sum(len(r) for _, r in path[k]) for k in range(K + 1)]
        self.row_source = np.concatenate(source)
        u = ca.vertcat(*[acc.var(int(j), acc.stage_of(i)) for i in range(L.n_nodes)
                         for j in L.iu(i)])
        self.problem = {"x": w, "f": self.obj_scale * ca.sumsqr(u), "g": ca.vertcat(*g)}
        self.lbx, self.ubx = nlp.x_lb[self.index] / self.scale, nlp.x_ub[self.index] / self.scale
        dyn = self.row_source < 0
        src = np.where(dyn, 0, self.row_source)
        self.lbg = np.where(dyn, 0.0, nlp.c_scale[src] * nlp.c_lo[src])
        self.ubg = np.where(dyn, 0.0, nlp.c_scale[src] * nlp.c_hi[src])
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
        holder (a knot's state, a midpoint's control; α and T from stage 0)."""
        z = np.asarray(z, float).ravel()
        return z[self.primary] * self.scale[self.primary]
