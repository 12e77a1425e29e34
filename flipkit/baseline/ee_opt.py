"""End-effector-space trajectory optimisation of one subbehaviour (the baseline of the paper's
reference [8], Tsuji et al.), a convex QP in cvxpy.

The spatula orientation o(t) (rpy, rad) is a fixed smooth profile from the start to the end
orientation (quintic smoothstep φ(s), s = t/T, so the angular velocity is zero at both ends);
the blade-centre position p(t) is a Bezier polynomial (degree 7 by default) in s whose
control points are the decision variables. With R(t) fixed, every constraint is linear in the
control points: the specific contact force f = R(t)ᵀ(a(t) − g) and so the physical friction
cone (eq. 5), the blade-edge heights p_z + (R r)_z, the scoop tip height (eq. 24). The cost is
∫ |jerk|² + λ |a|² dt. On the scoop the pitch follows o_y = asin σ(s) with σ a quintic, so the
tip equality p_z = h + (l/2) σ(s) has a polynomial solution and holds exactly.

A QP is stated once per (subbehaviour, samples, duration, degree) with the location-dependent
data as cvxpy Parameters; given a :class:`~flipkit.baseline.problems.CompiledProblems`, a sweep
over burger locations compiles each QP once.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from flipkit.baseline.problems import CompiledProblems
from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors import targets as tg
from flipkit.model.bezier import Bezier
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, InvalidChoiceError, NoSolutionFound
from flipkit.model.orientation import rpy_matrix

DEGREE = 7
FLIP_END_RPY = (-2.7, 0.1, 0.0)  # rad; normal (-0.09, 0.43, -0.90) lies inside FLIP_NORMAL_BOUNDS
ACC_WEIGHT = 100.0  # λ (s⁻²): weight of ∫|a|² against ∫|jerk|²
COST_SCALE = 1e-4  # numerical scaling of the objective only


@dataclass(frozen=True)
class EEState:
    """Spatula state at a segment boundary: position p (m), velocity v (m/s), rpy o (rad),
    rpy rate w (rad/s)."""

    p: tuple
    v: tuple
    o: tuple
    w: tuple = (0.0, 0.0, 0.0)


@dataclass
class EETrajectory:
    """A sampled end-effector trajectory of one subbehaviour (world frame).

    Attributes:
        name: Subbehaviour. T: Duration (s). t: Sample times (s), evenly spaced, t[0] = 0.
        p, v, a: Blade-centre position (m), velocity (m/s), acceleration (m/s²), (n, 3).
        o: rpy (rad), (n, 3). R: Rotations spatula → world, (n, 3, 3).
        cone: Samples where the friction cone is enforced (bool, n).
        coeffs: Bezier control points of p, (degree + 1, 3) (m).
        solve_time_s: Wall time of the QP (s): building and compiling it on the first call
            for its shape, parameter update, solve.
        objective: Optimal cost. status: Solver status.
        od: rpy rates (rad/s), (n, 3), or None (the fixed profile: zero at both ends).
        o_coeffs: Bezier control points of o (rad), or None (the fixed profile).
        iterations: SCP iterations at the chosen duration (0: a single QP).
        max_violation: Scaled violation of the linearised constraints at the solution.
        durations_tried: Durations the search evaluated (1: fixed duration).
    """

    name: str
    T: float
    t: np.ndarray
    p: np.ndarray
    v: np.ndarray
    a: np.ndarray
    o: np.ndarray
    R: np.ndarray
    cone: np.ndarray
    coeffs: np.ndarray
    solve_time_s: float
    objective: float
    status: str
    od: np.ndarray | None = None
    o_coeffs: np.ndarray | None = None
    iterations: int = 0
    max_violation: float = 0.0
    durations_tried: int = 1

    def end_state(self) -> EEState:
        """The state the next subbehaviour starts from."""
        w = (0.0, 0.0, 0.0) if self.od is None else tuple(self.od[-1])
        return EEState(tuple(self.p[-1]), tuple(self.v[-1]), tuple(self.o[-1]), w)


def smoothstep(s) -> np.ndarray:
    """Quintic φ(s) = 10s³ − 15s⁴ + 6s⁵: φ(0) = 0, φ(1) = 1, zero rate and curvature at both."""
    s = np.asarray(s, dtype=float)
    return s**3 * (10 - 15 * s + 6 * s**2)


def orientation_profile(o0, o1, s, sine_pitch: bool = False) -> np.ndarray:
    """rpy o(s) (rad), (len(s), 3): o0 + (o1 − o0) φ(s); with ``sine_pitch`` the pitch is
    asin of sin o0_y + (sin o1_y − sin o0_y) φ(s) (the scoop: tip height polynomial)."""
    o0, o1, w = np.asarray(o0, float), np.asarray(o1, float), smoothstep(s)[:, None]
    o = o0 + (o1 - o0) * w
    if sine_pitch:
        o[:, 1] = np.arcsin(np.sin(o0[1]) + (np.sin(o1[1]) - np.sin(o0[1])) * w[:, 0])
    return o


class _SegmentQP:
    """The parameterised QP of one subbehaviour with a fixed sample grid."""

    def __init__(self, name: str, t: np.ndarray, T: float, degree: int, cone_idx: np.ndarray):
        n, bez = len(t), Bezier(degree)
        B = [bez.basis(t / T, k) / T**k for k in range(4)]
        C = cp.Variable((degree + 1, 3), name="control_points")
        pos, vel, acc = B[0] @ C, B[1] @ C, B[2] @ C
        P = self.par = {k: cp.Parameter(m, name=k) for k, m in (
            ("p0", 3), ("v0", 3), ("p_end", 3), ("p_min", 3), ("p_max", 3), ("v_max", 3),
            ("a_max", 3), ("z_clear", n), ("z_tip", n), ("band", 2))}
        cons = [pos[0] == P["p0"], vel[0] == P["v0"], pos >= np.ones((n, 1)) @ P["p_min"][None],
                pos <= np.ones((n, 1)) @ P["p_max"][None], pos[:, 2] >= P["z_clear"],
                cp.abs(vel) <= np.ones((n, 1)) @ P["v_max"][None],
                cp.abs(acc) <= np.ones((n, 1)) @ P["a_max"][None]]
        if name in ("go_to_burger", "scoop", "pickup", "turn_back"):
            cons.append(pos[-1] == P["p_end"])
        if name in ("go_to_burger", "turn_back"):
            cons.append(vel[-1] == 0)
        if name == "scoop":
            cons.append(pos[:, 2] == P["z_tip"])
        if name == "flip":
            cons += [pos[-1, 2] >= P["band"][0], pos[-1, 2] <= P["band"][1]]
        if len(cone_idx):  # Σ_j M[r, j, k] a_kj ≥ (M g)_rk, M_k = S R_kᵀ
            m = len(cone_idx)
            self.cone_M = [[cp.Parameter(m, name=f"M{r}{j}") for j in range(3)] for r in range(5)]
            self.cone_b = [cp.Parameter(m, name=f"b{r}") for r in range(5)]
            ac = acc[cone_idx]
            cons += [sum(cp.multiply(self.cone_M[r][j], ac[:, j]) for j in range(3))
                     >= self.cone_b[r] for r in range(5)]
        dt = T / (n - 1)
        cost = dt * (cp.sum_squares(B[3] @ C) + ACC_WEIGHT * cp.sum_squares(acc))
        self.C, self.B, self.cone_idx = C, B, cone_idx
        self.problem = cp.Problem(cp.Minimize(COST_SCALE * cost), cons)

    def solve(self, values: dict, cone_M: np.ndarray | None, cone_b: np.ndarray | None):
        for key, value in values.items():
            self.par[key].value = np.asarray(value, dtype=float)
        if len(self.cone_idx):
            for r in range(5):
                self.cone_b[r].value = cone_b[:, r]
                for j in range(3):
                    self.cone_M[r][j].value = cone_M[:, r, j]
        self.problem.solve(solver=cp.CLARABEL)
        return self.problem.status, self.C.value, self.problem.value


def sample_times(T: float, rate: float) -> np.ndarray:
    """Evenly spaced times on [0, T] (s), spacing ≤ 1/rate, both ends included."""
    n = max(int(np.ceil(T * rate - 1e-9)), 1)
    return np.linspace(0.0, T, n + 1)


def plan_segment(name: str, cell: CellConfig, location, start: EEState, T: float,
                 home: tg.Pose | None = None, rate: float = 200.0,
                 degree: int = DEGREE, problems: CompiledProblems | None = None
                 ) -> EETrajectory:
    """Optimise the spatula trajectory of subbehaviour ``name``.

    Args:
        name: One of :data:`flipkit.behaviors.library.FLIP_NAMES`.
        cell: Cell configuration (spatula, burger μ, grill, task limits, gravity).
        location: Burger location p^b (m).
        start: Start state (the previous subbehaviour's end, or the pose at q_start at rest).
        T: Duration (s).
        home: Home spatula pose (``turn_back`` only).
        rate: Sample rate of the output and of the constraints (Hz).
        degree: Bezier degree of p(t) (≥ 5).
        problems: The compiled QPs to solve in and add to (default: new ones, for this
            call alone).

    Raises:
        NoSolutionFound: The QP is infeasible.
    """
    if name not in FLIP_NAMES:
        raise InvalidChoiceError("subbehaviour", name, FLIP_NAMES)
    if not (np.isfinite(T) and T > 0 and np.isfinite(rate) and rate > 0):
        raise ConfigError(f"duration and rate must be positive, got T={T!r}, rate={rate!r}")
    if int(degree) != degree or degree < 5:
        raise ConfigError(f"Bezier degree must be an integer >= 5, got {degree!r}")
    if name == "turn_back" and home is None:
        raise ConfigError("turn_back needs the home pose")
    for field_name in ("p", "v", "o"):
        value = np.asarray(getattr(start, field_name), dtype=float)
        if value.shape != (3,) or not np.all(np.isfinite(value)):
            raise ConfigError(f"start.{field_name} must be 3 finite numbers, got {value.tolist()}")
    pb = tg.check_location(cell, location)
    # the paper's scoop (eq. 24): tip on the grill's surface, not pressed into it as
    # collocation's is (behaviors.SCOOP_PRESS, for the simulated grill contact)
    ends = {"go_to_burger": tg.scoop_ready(cell, pb, 0.0), "scoop": tg.scoop_end(cell, pb, 0.0),
            "pickup": tg.pickup_end(cell, pb), "flip": tg.Pose((np.nan,) * 3, FLIP_END_RPY),
            "turn_back": home}
    goal = ends[name]
    t = sample_times(T, rate)
    o = orientation_profile(start.o, goal.o, t / T, sine_pitch=name == "scoop")
    R = np.array([rpy_matrix(ok) for ok in o])
    frac = {"pickup": 1.0, "flip": tg.FLIP_CONE_FRACTION}.get(name, 0.0)
    cone = t <= frac * T + 1e-12 if frac else np.zeros(len(t), bool)
    tic = time.perf_counter()
    key = ("fixed", name, len(t), round(float(T), 12), int(degree), int(cone.sum()))
    problems = CompiledProblems() if problems is None else problems
    qp = problems.get(key, lambda: _SegmentQP(name, t, T, int(degree), np.flatnonzero(cone)))

    sp, lim, hg = cell.spatula, cell.limits, cell.grill.height
    edges = np.array([[sp.length / 2, 0, 0], [-sp.length / 2, 0, 0],
                      [0, sp.width / 2, 0], [0, -sp.width / 2, 0]]).T
    h_clear = min(hg, pb[2])
    z_tip = hg + sp.length / 2 * np.sin(o[:, 1])  # tip on the grill (targets use h_g too)
    values = {"p0": start.p, "v0": start.v, "p_end": goal.p if name != "flip" else np.zeros(3),
              "p_min": lim.p_min, "p_max": lim.p_max, "v_max": np.full(3, lim.v_max),
              "a_max": np.full(3, lim.a_max), "z_clear": h_clear - np.min(R[:, 2] @ edges, axis=1),
              "z_tip": z_tip, "band": hg + np.asarray(tg.FLIP_HEIGHT_BAND)}
    mu = cell.burger.mu  # physical cone S f ≥ 0: f_z, μ f_z ∓ f_x, μ f_z ∓ f_y (eq. 5)
    S = np.array([[0, 0, 1], [-1, 0, mu], [1, 0, mu], [0, -1, mu], [0, 1, mu]], dtype=float)
    M = np.einsum("rc,kjc->krj", S, R[cone]) if cone.any() else None  # S R_kᵀ
    b = M @ np.asarray(cell.gravity) if cone.any() else None
    status, coeffs, objective = qp.solve(values, M, b)
    elapsed = time.perf_counter() - tic
    if status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or coeffs is None:
        raise NoSolutionFound(name, status, None, float("nan"))
    p, v, a = (Bk @ coeffs for Bk in qp.B[:3])
    return EETrajectory(name, float(T), t, p, v, a, o, R, cone, coeffs, elapsed,
                        float(objective), status)
