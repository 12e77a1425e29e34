"""The convex subproblem of the end-effector SCP (:mod:`flipkit.baseline.ee_scp`): one cvxpy
problem per (subbehaviour, samples), stated once with Parameters (DPP).

Decision variables: the Bezier control points C (m) of the blade-centre position and D (rad)
of the rpy angles, in s = t/T, and one elastic slack σ ≥ 0 (scaled units: cm for heights and
the landing, g for the cone, 1 for axes). The duration T appears only in Parameters: velocity
bounds v_max T, acceleration bounds a_max T², start rates × T, cost weights ∝ T^(−5/2) and
T^(−3/2), and the cone's and landing's coefficients. Constraints nonlinear in the orientation
are linear in (C, D) about the iterate (Cᵏ, Dᵏ), whose coefficients
:meth:`SCPProblem.linearise` sets, with a box trust region about it (Δ rad on D, 0.3 Δ m on
C: the cone's neglected term (R − Rᵏ)ᵀ(a − aᵏ) is then second order in Δ).
"""

from __future__ import annotations

import math

import cvxpy as cp
import numpy as np

from flipkit.behaviors.options import R_LAND, SCOOP_ANGLE_BAND, SCOOP_LATERAL_BAND, SCOOP_TIP_BAND
from flipkit.behaviors import targets as tg
from flipkit.model.bezier import Bezier
from flipkit.model.flight import TILT_MIN_DEG
from flipkit.model.orientation import rpy_matrix, rpy_matrix_derivatives

ACC_WEIGHT = 100.0  # λ (s⁻²): weight of ∫|a|² against ∫|jerk|², as the fixed-orientation QP
ORIENTATION_WEIGHT = 1.0  # w_o (m²/rad²), see flipkit.baseline.ee_scp
COST_SCALE = 1e-4  # numerical scaling of the objective only
PENALTY = 100.0  # weight of the elastic slack σ in the merit (exact penalty: above the
# multipliers; the objective is ~0.01–0.5 and a violation of 1 mm or 0.01 g costs 10)
CLARABEL_OPTIONS = {"tol_gap_abs": 1e-7, "tol_gap_rel": 1e-7, "tol_feas": 1e-7}
FREE = 100.0  # m: a trust region on C that never binds
POSITION_TRUST = 0.3  # m per rad: the trust region on C for a region of Δ rad on D
REST = ("go_to_burger", "scoop", "turn_back")
POSED = ("go_to_burger", "scoop", "pickup", "turn_back")


class SCPProblem:
    """The parameterised convex subproblem of one subbehaviour.

    Args:
        name: Subbehaviour. n: Constraint samples on s ∈ [0, 1]. degree: Bezier degree.
        cone_idx: Samples with the friction cone. release: The flip's release sample.
    """

    PENALTY = PENALTY

    def __init__(self, name: str, n: int, degree: int, cone_idx: np.ndarray, release: int):
        self.name, self.n, self.cone_idx, self.release = name, n, np.asarray(cone_idx), release
        self.bez = Bezier(degree)
        s = np.linspace(0.0, 1.0, n)
        self.B = B = [self.bez.basis(s, k) for k in range(4)]
        nc = degree + 1
        C = self.C = cp.Variable((nc, 3), name="C")
        D = self.D = cp.Variable((nc, 3), name="D")
        sig = self.sigma = cp.Variable(nonneg=True, name="sigma")
        par = self.par = {}

        def P(key, shape=(), **kw):
            par[key] = cp.Parameter(shape, name=key, **kw)
            return par[key]

        pos, vel, acc, O, Od = B[0] @ C, B[1] @ C, B[2] @ C, B[0] @ D, B[1] @ D
        dC = C[1:] - C[:-1]
        cons = [pos[0] == P("p0", 3), vel[0] == P("v0T", 3), O[0] == P("o0", 3),
                Od[0] == P("w0T", 3),
                # the position box at the samples; boxes on the control points of ṗ, p̈ and
                # o_y (Bezier convex hull: they then hold along the whole curve)
                pos >= np.ones((n, 1)) @ P("p_lo", 3)[None],
                pos <= np.ones((n, 1)) @ P("p_hi", 3)[None],
                cp.abs(dC) <= P("vT", nonneg=True) / degree,
                cp.abs(dC[1:] - dC[:-1]) <= P("aT2", nonneg=True) / (degree * (degree - 1)),
                D[:, 1] >= P("pitch_lo"), D[:, 1] <= P("pitch_hi"),
                cp.abs(D - P("Dk", (nc, 3))) <= P("trust", nonneg=True),
                cp.abs(C - P("Ck", (nc, 3))) <= P("trust_c", nonneg=True)]
        # Linearisation coefficients stacked in few Parameters: setting a Parameter costs
        # cvxpy a validation of its value, a large share of an iteration with one Parameter
        # per coefficient vector
        edge, floor = [], P("floor", (4, n))  # each edge's floor (EDGES' order)
        He, Ce = P("He", (12, n)), P("Ce", (4, n))
        for e in range(4):  # blade edge heights p_z + R[2, :] r_e, linearised in o
            h = pos[:, 2] + Ce[e] + sum(cp.multiply(He[3 * e + j], O[:, j]) for j in range(3))
            edge.append(h)
            cons.append(h >= floor[e] - 0.01 * sig)
        if name in POSED:
            cons += [pos[-1] == P("p_end", 3), O[-1] == P("o_end", 3)]
        if name in REST:
            cons += [vel[-1] == 0, Od[-1] == 0]
        if name == "scoop":
            mid = slice(1, n - 1)
            cons += [cp.abs(edge[0][mid] - P("tip")) <= SCOOP_TIP_BAND + 0.01 * sig,
                     cp.abs(pos[mid, 1] - P("pb_y")) <= SCOOP_LATERAL_BAND,
                     cp.abs(O[mid, 0]) <= SCOOP_ANGLE_BAND, cp.abs(O[mid, 2]) <= SCOOP_ANGLE_BAND]
        if name == "flip":
            lo_n, hi_n = (np.array(b) for b in tg.FLIP_NORMAL_BOUNDS)
            normal = P("Nm", (3, 3)) @ O[-1] + P("cN", 3)
            X = P("X", (3, n - 1))
            xaxis = P("cX", n - 1) + sum(cp.multiply(X[j], O[1:, j]) for j in range(3))
            r = release
            z = cp.hstack([pos[r], vel[r], O[r], Od[r]])
            land = P("Jl", (3, 12)) @ z + P("cl", 3)
            cons += [pos[-1, 2] >= P("z_lo"), pos[-1, 2] <= P("z_hi"),
                     normal >= lo_n - sig, normal <= hi_n + sig,
                     xaxis >= tg.FLIP_XAXIS_BOUNDS[0][0] - sig,
                     cp.norm(land[:2] - P("spot", 2)) <= R_LAND + 0.01 * sig,
                     land[2] <= math.cos(math.radians(TILT_MIN_DEG)) + sig]
        if len(self.cone_idx):  # Σ_i A_ri a_i + Σ_j G_rj o_j ≥ b_r − |g| σ, row r of S Rᵀ(a−g)
            ac, Oc = acc[self.cone_idx], O[self.cone_idx]
            m, g_norm = len(self.cone_idx), P("g_norm", nonneg=True)
            A, G, b = P("A", (15, m)), P("G", (15, m)), P("b", (5, m))
            for rr in range(5):
                lhs = (sum(cp.multiply(A[3 * rr + i], ac[:, i]) for i in range(3))
                       + sum(cp.multiply(G[3 * rr + j], Oc[:, j]) for j in range(3)))
                cons.append(lhs >= b[rr] - g_norm * sig)
        cost = (cp.sum_squares(P("c3", nonneg=True) * (B[3] @ C))
                + cp.sum_squares(P("c2", nonneg=True) * acc)
                + cp.sum_squares(P("c3w", nonneg=True) * (B[3] @ D))
                + cp.sum_squares(P("c2w", nonneg=True) * (B[2] @ D)) + PENALTY * sig)
        self.problem = cp.Problem(cp.Minimize(cost), cons)

    @staticmethod
    def cone_rows(mu: float) -> np.ndarray:
        """S (5×3) with S f ≥ 0 the physical cone (eq. 5): f_z, μ f_z ∓ f_x, μ f_z ∓ f_y."""
        return np.array([[0, 0, 1], [-1, 0, mu], [1, 0, mu], [0, -1, mu], [0, 1, mu]], float)

    def _set(self, key: str, value) -> None:
        if key in self.par:
            self.par[key].value = np.asarray(value, dtype=float).reshape(self.par[key].shape)

    def set_task(self, task, T: float) -> None:
        """Task and duration Parameters (``task``: :class:`flipkit.baseline.ee_scp.ScpSegment`)."""
        cell, st = task.cell, task.start
        lim, ds = cell.limits, 1.0 / (self.n - 1)
        w_o = ORIENTATION_WEIGHT
        c3, c2 = math.sqrt(COST_SCALE * ds / T**5), math.sqrt(COST_SCALE * ACC_WEIGHT * ds / T**3)
        values = {"p0": st.p, "v0T": np.asarray(st.v) * T, "o0": st.o, "w0T": np.asarray(st.w) * T,
                  "p_lo": task.p_lo, "p_hi": lim.p_max, "vT": lim.v_max * T,
                  "aT2": lim.a_max * T**2, "pitch_lo": lim.pitch_range[0],
                  "pitch_hi": lim.pitch_range[1], "floor": task.floor.T, "tip": task.tip,
                  "pb_y": task.pb[1], "spot": tg.landing_spot(cell, task.pb),
                  "z_lo": cell.grill.height + tg.FLIP_HEIGHT_BAND[0],
                  "z_hi": cell.grill.height + tg.FLIP_HEIGHT_BAND[1],
                  "g_norm": np.linalg.norm(task.g), "c3": c3, "c2": c2,
                  "c3w": c3 * math.sqrt(w_o), "c2w": c2 * math.sqrt(w_o)}
        if task.goal is not None:
            values.update(p_end=task.goal.p, o_end=task.goal.o)
        for key, value in values.items():
            self._set(key, value)

    def linearise(self, task, C: np.ndarray, D: np.ndarray, T: float, trust: float,
                  free_position: bool = False) -> None:
        """Set the linearisation about the iterate (C, D) and the trust region (rad; with
        ``free_position`` none on C)."""
        B = self.B
        Ok, Ak = B[0] @ D, B[2] @ C / T**2
        R = np.array([rpy_matrix(o) for o in Ok])
        dR = np.array([rpy_matrix_derivatives(o) for o in Ok])  # (n, j, 3, 3)
        self._set("Dk", D)
        self._set("Ck", C)
        self._set("trust", trust)
        self._set("trust_c", FREE if free_position else trust * POSITION_TRUST)
        He = np.einsum("kjc,ce->ejk", dR[:, :, 2, :], task.edges)  # (4, 3, n)
        self._set("He", He.reshape(12, -1))
        self._set("Ce", (R[:, 2, :] @ task.edges).T - np.einsum("ejk,kj->ek", He, Ok))
        if self.name == "flip":
            X = dR[1:, :, 0, 0]
            self._set("X", X.T)
            self._set("cX", R[1:, 0, 0] - np.sum(X * Ok[1:], axis=1))
            Nm = dR[-1, :, :, 2].T  # column j: ∂(R e_z)/∂o_j
            self._set("Nm", Nm)
            self._set("cN", R[-1][:, 2] - Nm @ Ok[-1])
            r = self.release
            z = np.concatenate([B[0][r] @ C, B[1][r] @ C / T, Ok[r], B[1][r] @ D / T])
            L, J = task.landing_jacobian(z)
            Js = J.copy()
            Js[:, 3:6] /= T
            Js[:, 9:12] /= T
            self._set("Jl", Js)
            self._set("cl", L - J @ z)
        if len(self.cone_idx):
            idx, S = self.cone_idx, self.cone_rows(task.mu)
            M = np.einsum("rc,kjc->krj", S, R[idx])  # S R_kᵀ, (m, 5, 3)
            G = np.einsum("rc,kqjc,kj->krq", S, dR[idx], Ak[idx] - task.g)  # (m, 5, j)
            b = M @ task.g + np.sum(G * Ok[idx][:, None, :], axis=2)
            self._set("A", M.reshape(len(idx), 15).T / T**2)  # row 3 rr + i
            self._set("G", G.reshape(len(idx), 15).T)
            self._set("b", b.T)

    def solve(self) -> str:
        """Solve with Clarabel; the status string."""
        try:
            self.problem.solve(solver=cp.CLARABEL, **CLARABEL_OPTIONS)
        except cp.error.SolverError:
            return "solver_error"
        return self.problem.status


__all__ = ["SCPProblem", "ORIENTATION_WEIGHT", "ACC_WEIGHT", "COST_SCALE", "PENALTY"]
