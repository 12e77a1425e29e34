"""The strong end-effector-space optimisation of one subbehaviour: position, orientation and
duration free, by sequential convex programming.

What it keeps of the paper's reference [8] (Tsuji et al., dynamic object manipulation with a
tool, planned in task space): the motion is planned for the tool alone — blade-centre
position p(t) and orientation R(t) as smooth polynomials in time — under the contact
condition of the carried object (the friction cone of the specific contact force,
f = Rᵀ(a − g), eq. 5, with collocation's friction safety factor μ × 0.8) and the task's
endpoint conditions; the joints enter only afterwards, through inverse kinematics. What it
adds so that the comparison with joint-space collocation is fair: the task-space constraints
of collocation's segments (:func:`flipkit.behaviors.transcribe.transcribe`) — endpoint
poses and rest, the position/velocity/acceleration box and pitch range (eq. 4), the blade's
edges above the grill (the scoop's press included), the scoop's tip band, lateral band and
attitude band, the flip's end-normal box, x-axis box at every sample, end-height band, cone
up to the release at 0.7 T and the ballistic landing within r_land of the pickup spot, top
face ≥ TILT_MIN_DEG (175°) from up — and a duration free within the same bounds
(the specs' ``duration``). Not kept: the flip's flight clearance and the
arm's space limits (joint-space quantities the task-space method cannot see).

Method. p(s) and the rpy angles o(s) are Bezier polynomials of degree 7 in s = t/T; their
control points C, D (m, rad) are the decision variables. The constraints are imposed at
:data:`SAMPLES` evenly spaced s (the velocity, acceleration and pitch bounds on the control
points instead, so they hold along the whole curve). Those linear in (C, D) — endpoints, boxes,
pitch, bands — are exact; the others (cone, edge heights, tip, axes, landing) are linearised
about the previous iterate (R(o) ≈ R(oᵏ) + Σ_j ∂R/∂o_j (o_j − o_jᵏ); the landing by central
differences of :data:`flipkit.model.flight.LANDING`, 25 points in one call) and relaxed by one
elastic slack σ ≥ 0 with an exact ℓ∞ penalty. Each convex subproblem is one cvxpy problem per
(subbehaviour, samples), written once with Parameters (DPP) and kept in a
:class:`~flipkit.baseline.problems.CompiledProblems`; the duration enters only through
Parameters (bounds scaled by T, T²; cost weights), so a duration search recompiles nothing, and
nor does a sweep over burger locations that passes the same ``problems``. A step is taken when
the merit — cost plus penalty × the exact violation — falls by at least a tenth of what the
subproblem predicts; the box trust region (Δ rad on D, 0.3 Δ m on C) halves when it falls by
less than a quarter and doubles when by more than three quarters at its edge. The cost is ∫
|p⃛|² + λ|p̈|² + w_o (|o⃛|² + λ|ö|²) dt with w_o = :data:`ORIENTATION_WEIGHT` (m²/rad²): a
radian of blade rotation weighs as much as a translation by the arm's reach, ≈ 1 m, both being
about a radian of joint motion. (A weight as small as (l/2)², a blade-tip displacement, makes
rotations so cheap that the go to burger pitches back and forward again to keep the tip off the
grill, driving wrist 1 past its speed limit; docs/history.md.) The duration is chosen by a
search of the converged cost over the bounds (infeasible durations cost +∞), each solve
warm-started from the best so far: the upper bound and a probe just below it, and a
golden-section search only when the probe costs less (:data:`PROBE_FRACTION`). At each duration
the SCP returns the best feasible point it met, and stops once that has not improved by OBJ_TOL
for :data:`STALE_ITERATIONS` iterations.
"""

from __future__ import annotations

import math
import time

import cvxpy as cp
import numpy as np

from flipkit.behaviors.library import FLIP_NAMES, SUBBEHAVIORS
from flipkit.behaviors.options import MU_SAFETY, RELEASE_FRACTION, R_LAND, SCOOP_PRESS, SCOOP_TIP_BAND
from flipkit.behaviors.transcribe import blade_floor
from flipkit.baseline.ee_opt import EEState, EETrajectory, sample_times
from flipkit.baseline.problems import CompiledProblems
from flipkit.baseline.scp_problem import (ACC_WEIGHT, COST_SCALE, ORIENTATION_WEIGHT, REST,
                                          SCPProblem)
from flipkit.behaviors import targets as tg
from flipkit.behaviors.guesses import flip_guess_pose
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, InvalidChoiceError, NoSolutionFound
from flipkit.model.bezier import Bezier
from flipkit.model.flight import LANDING, TILT_MIN_DEG, landing_parameters
from flipkit.model.orientation import rpy_matrix, rpy_rate_matrix

DEGREE = 7
SAMPLES = 31  # constraint samples on s ∈ [0, 1] (collocation: 21 nodes)
ITERATIONS = 30  # SCP iterations per duration, at most
TRUST0 = 0.3  # rad: initial trust region on the rpy control points
TRUST_WARM = 0.05  # rad: the initial region of a solve warm-started at another duration
TRUST_MAX = 1.0  # rad: the trust region doubles after an accepted step that reached it
STEP_TOL = 1e-4  # rad: the search at a duration stops when the trust region is below this
# converged: the exact scaled violation below FEAS_TOL ...
FEAS_TOL = 1e-4  # ... and the exact scaled violation below this
OBJ_TOL = 0.02  # ... and the merit decreases by less than this, relative
RHO_ACCEPT = 0.1  # a step is taken when the merit falls by this share of the model's decrease
STALE_ITERATIONS = 3  # stop when the best feasible objective has not fallen by OBJ_TOL in these
GOLDEN_STEPS = 3  # golden-section reductions of the duration interval
# The duration search first solves at the upper bound and just below it (PROBE_FRACTION of the
# range): when the cost is no lower there, the minimum of a unimodal cost lies within that
# tenth of the range, finer than the golden section's final bracket (0.618⁴ = 0.15), and the
# search stops. The cost usually falls with T, and the golden section would spend most of its
# time on shorter durations.
PROBE_FRACTION = 0.1
EDGES = np.array([[0.5, 0, 0], [-0.5, 0, 0], [0, 0.5, 0], [0, -0.5, 0]])  # × (l, w, ·)


def _guess_coeffs(bez: Bezier, s: np.ndarray, start: EEState, goal: tg.Pose) -> tuple:
    """Control points of the smoothstep interpolation from ``start`` to ``goal``."""
    w = (s**3 * (10 - 15 * s + 6 * s**2))[:, None]
    P = np.asarray(start.p) + (np.asarray(goal.p) - np.asarray(start.p)) * w
    O = np.asarray(start.o) + (np.asarray(goal.o) - np.asarray(start.o)) * w
    pinv = np.linalg.pinv(bez.basis(s))
    return pinv @ P, pinv @ O


class ScpSegment:
    """One subbehaviour at one location as the SCP states it: its goal pose, the blade's
    floors and edges, the cone's nodes and friction, gravity (all SI)."""

    def __init__(self, name: str, cell: CellConfig, pb: np.ndarray, start: EEState,
                 home: tg.Pose | None):
        self.name, self.cell, self.pb, self.start = name, cell, pb, start
        sp, hg = cell.spatula, cell.grill.height
        self.edges = (EDGES * np.array([sp.length, sp.width, 0.0])).T  # (3, 4) blade frame
        self.goal = {"go_to_burger": tg.scoop_ready(cell, pb), "scoop": tg.scoop_end(cell, pb),
                     "pickup": tg.pickup_end(cell, pb), "turn_back": home}.get(name)
        self.guess_goal = self.goal or flip_guess_pose(cell, pb)
        n = SAMPLES
        c = blade_floor(name, cell, n - 1)  # per corner: tip left, tip right, back left, right
        # the floors of the edges' midpoints (EDGES: tip, heel, left, right), (n, 4)
        self.floor = np.column_stack([c[:, :2].mean(1), c[:, 2:].mean(1), c[:, ::2].mean(1),
                                      c[:, 1::2].mean(1)])
        self.p_lo = np.array(cell.limits.p_min, float)
        if name in ("go_to_burger", "scoop", "pickup"):
            self.p_lo[2] -= SCOOP_PRESS + SCOOP_TIP_BAND
        self.tip = hg - SCOOP_PRESS
        self.cone_frac = {"pickup": 1.0, "flip": max(RELEASE_FRACTION, tg.FLIP_CONE_FRACTION)}
        self.release = int(np.ceil(RELEASE_FRACTION * (n - 1) - 1e-9))
        # The nominal μ × MU_SAFETY, not collocation's narrower MU_PLAN: the baseline keeps
        # the cone it was compared with, within which the SCP finds feasible chains.
        self.mu = cell.burger.mu * MU_SAFETY
        self.g = np.asarray(cell.gravity, float)
        self._mapped: dict = {}  # k -> LANDING mapped over k release states

    def _landing_map(self, k: int):
        """:data:`~flipkit.model.flight.LANDING` mapped over ``k`` release states, built on
        first use by this segment (its solves ask for a few sizes, many times each)."""
        if k not in self._mapped:
            self._mapped[k] = LANDING.map(k)
        return self._mapped[k]

    def cone_idx(self, n: int) -> np.ndarray:
        frac = self.cone_frac.get(self.name, 0.0)
        return np.flatnonzero(np.linspace(0, 1, n) <= frac + 1e-12) if frac else np.array([], int)

    def landing(self, z: np.ndarray) -> np.ndarray:
        """(x, y, cos tilt) of the landing from the release state z = (p, v, o, ȯ)."""
        return self._landings(np.asarray(z, float)[None])[:, 0]

    def _landings(self, Z: np.ndarray) -> np.ndarray:
        """:meth:`landing` of each row of Z (k, 12), in one call of the mapped CasADi
        function (:meth:`_landing_map`); (3, k)."""
        x = np.zeros((12, len(Z)))
        Rs = np.empty((3, 3 * len(Z)))
        for k, z in enumerate(Z):
            o = z[6:9]
            x[:6, k], x[9:, k] = z[:6], rpy_rate_matrix(o) @ z[9:]
            Rs[:, 3 * k: 3 * k + 3] = rpy_matrix(o)
        bg = self.cell.burger
        par = landing_parameters(bg.thickness, self.cell.grill.height, self.g,
                                 diameter=bg.diameter)
        y = np.asarray(self._landing_map(len(Z))(x, Rs, par)[0])  # (5, k)
        return np.vstack([y[3], y[4], np.clip(y[1], -1.0, 1.0)])

    def landing_jacobian(self, z: np.ndarray, h: float = 1e-6) -> tuple:
        """Landing (3,) and its central-difference Jacobian (3, 12) at z (one batched call)."""
        E = h * np.eye(12)
        Y = self._landings(np.vstack([z, z + E, z - E]))
        return Y[:, 0], (Y[:, 1:13] - Y[:, 13:]) / (2 * h)


def violations(task: ScpSegment, B: list, C: np.ndarray, D: np.ndarray, T: float) -> dict:
    """Largest scaled violation of each linearised (nonconvex) constraint group at the
    samples (≤ 0: satisfied): edge heights, tip band and landing in cm, cone rows in g, axes
    and cos tilt unitless."""
    P, A, O = B[0] @ C, B[2] @ C / T**2, B[0] @ D
    R = np.array([rpy_matrix(o) for o in O])
    h = P[:, 2:3] + R[:, 2] @ task.edges  # (n, 4)
    out = {"grill_clearance": float(np.max(task.floor - h)) / 0.01}
    if task.name == "scoop":
        out["scoop_tip"] = (np.max(np.abs(h[1:-1, 0] - task.tip)) - SCOOP_TIP_BAND) / 0.01
    idx = task.cone_idx(len(P))
    if len(idx):
        S = SCPProblem.cone_rows(task.mu)
        f = np.einsum("kji,kj->ki", R[idx], A[idx] - task.g)
        out["cone"] = float(np.max(-(f @ S.T))) / np.linalg.norm(task.g)
    if task.name == "flip":
        lo_n, hi_n = (np.array(b) for b in tg.FLIP_NORMAL_BOUNDS)
        n_end = R[-1][:, 2]
        out["flip_normal"] = float(max(np.max(lo_n - n_end), np.max(n_end - hi_n)))
        out["flip_xaxis"] = float(np.max(tg.FLIP_XAXIS_BOUNDS[0][0] - R[1:, 0, 0]))
        land = task.landing(_release_state(B, C, D, T, task.release))
        out["landing"] = (np.linalg.norm(land[:2] - task.pb[:2]) - R_LAND) / 0.01
        out["landing_tilt"] = land[2] - math.cos(math.radians(TILT_MIN_DEG))
    return out


def violation(task: ScpSegment, B: list, C: np.ndarray, D: np.ndarray, T: float) -> float:
    """The largest of :func:`violations`, or 0 when all hold."""
    return float(max(0.0, *violations(task, B, C, D, T).values()))


def _release_state(B, C, D, T, r) -> np.ndarray:
    return np.concatenate([B[0][r] @ C, B[1][r] @ C / T, B[0][r] @ D, B[1][r] @ D / T])


def _objective(B, C, D, T, w_o) -> float:
    ds = 1.0 / (len(B[0]) - 1)
    acc = lambda X: ds / T**3 * np.sum((B[2] @ X) ** 2)  # noqa: E731
    jerk = lambda X: ds / T**5 * np.sum((B[3] @ X) ** 2)  # noqa: E731
    return COST_SCALE * (jerk(C) + ACC_WEIGHT * acc(C) + w_o * (jerk(D) + ACC_WEIGHT * acc(D)))


def scp_subproblem(task: ScpSegment, n: int = SAMPLES,
                problems: CompiledProblems | None = None) -> SCPProblem:
    """The SCP subproblem of ``task`` on ``n`` samples, from ``problems`` (built there on
    first use; default: a new one)."""
    key = ("scp", task.name, n, len(task.cone_idx(n)))
    problems = CompiledProblems() if problems is None else problems
    return problems.get(key, lambda: SCPProblem(task.name, n, DEGREE, task.cone_idx(n),
                                                task.release))


def compile_subproblems(cell: CellConfig, location, problems: CompiledProblems) -> float:
    """Compile every subbehaviour's SCP subproblem at ``location`` into ``problems`` (cvxpy's
    one-off canonicalisation, on placeholder Parameter values that every solve sets anew),
    so that what a run with ``problems`` then times is the SCP, not the compile. Returns the
    time spent (s)."""
    t0, pb = time.perf_counter(), tg.check_location(cell, location)
    rest = EEState((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    for name in FLIP_NAMES:
        task = ScpSegment(name, cell, pb, rest, tg.Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
        problem = scp_subproblem(task, SAMPLES, problems).problem
        for par in problem.parameters():
            par.value = np.zeros(par.shape)
        problem.get_problem_data(cp.CLARABEL)
    return time.perf_counter() - t0


def _meet_ends(task: ScpSegment, C0: np.ndarray, D0: np.ndarray, T: float) -> tuple:
    """Copies of (C0, D0) whose end control points meet the start state at duration T and
    the end pose (and rest), so that a trust region about them admits the end rows."""
    C, D, st, d = C0.copy(), D0.copy(), task.start, len(C0) - 1
    C[0], D[0] = st.p, st.o
    C[1], D[1] = np.asarray(st.p) + np.asarray(st.v) * T / d, np.asarray(st.o) + np.asarray(st.w) * T / d
    if task.goal is not None:
        C[-1], D[-1] = task.goal.p, task.goal.o
        if task.name in REST:
            C[-2], D[-2] = C[-1], D[-1]
    return C, D


def scp_at_duration(task: ScpSegment, T: float, C0: np.ndarray, D0: np.ndarray,
                    trust: float = TRUST0, *, problem: SCPProblem | None = None) -> dict:
    """The SCP at a fixed duration T (s) from the iterate (C0, D0), trust region ``trust`` (rad),
    its subproblems solved in ``problem`` (default :func:`scp_subproblem` of ``task``).

    Returns:
        ``{"C", "D", "objective", "violation", "iterations", "qp_solves"}``; ``objective`` is
        +∞ when the final violation exceeds :data:`FEAS_TOL`.
    """
    qp = scp_subproblem(task) if problem is None else problem
    B, w_o, W = qp.B, ORIENTATION_WEIGHT, qp.PENALTY
    C, D = _meet_ends(task, C0, D0, T)
    viol = violation(task, B, C, D, T)
    merit = _objective(B, C, D, T, w_o) + W * max(viol, 0.0)
    solves, it = 0, 0
    feasible_linear = False  # (C, D) meets the linear rows (a subproblem's solution)
    best = None  # the feasible point of least objective seen, taken or not: (objective, C, D,
    stale = 0  # violation); iterations since it last improved by OBJ_TOL
    qp.set_task(task, T)  # the task and duration Parameters hold for the whole loop
    for it in range(1, ITERATIONS + 1):
        stale += best is not None
        if stale > STALE_ITERATIONS:  # feasible, and the objective no longer falls
            break
        # until a subproblem solution is taken, the position is free: the start and end
        # rows (the start velocity × T) cannot be met near a guess or a warm start
        qp.linearise(task, C, D, T, trust, free_position=not feasible_linear)
        status = qp.solve()
        solves += 1
        if status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or qp.C.value is None:
            trust /= 2
            continue
        Cn, Dn = qp.C.value.copy(), qp.D.value.copy()
        vn = violation(task, B, Cn, Dn, T)
        on = _objective(B, Cn, Dn, T, w_o)
        mn = on + W * max(vn, 0.0)
        if vn <= FEAS_TOL and (best is None or on < best[0]):  # feasible: the linear rows
            stale = 0 if best is None or on < (1 - OBJ_TOL) * best[0] else stale  # hold too
            best = (on, Cn, Dn, vn)
        predicted = merit - float(qp.problem.value)  # the subproblem's model of the merit
        actual = merit - mn
        if feasible_linear and predicted <= OBJ_TOL * max(abs(merit), 1e-9):  # no decrease left
            if viol <= FEAS_TOL:
                break
            trust /= 2
            continue
        rho = actual / predicted
        if rho >= RHO_ACCEPT or not feasible_linear:
            C, D, viol, merit, feasible_linear = Cn, Dn, vn, mn, True
            if viol <= FEAS_TOL and actual <= OBJ_TOL * max(abs(merit), 1e-9):
                break
        if rho < 0.25:
            trust /= 2
        elif rho > 0.75 and float(np.max(np.abs(Dn - qp.par["Dk"].value))) >= 0.99 * trust:
            trust = min(2 * trust, TRUST_MAX)
        if trust < STEP_TOL:
            break
    obj = _objective(B, C, D, T, w_o)
    ok = feasible_linear and viol <= FEAS_TOL
    if best is not None and (not ok or best[0] < obj):
        # the ℓ∞ merit may trade a violation above FEAS_TOL for objective, and rejects
        # feasible trial points: keep the best feasible point seen (an SCP can pass feasible
        # trials and end just outside)
        obj, C, D, viol = best
        ok = True
    return {"C": C, "D": D, "objective": obj if ok else math.inf,
            "merit": merit if feasible_linear else math.inf,
            "violation": viol, "iterations": it, "qp_solves": solves}


def search_duration(f, lo: float, hi: float) -> None:
    """Minimise the cost f(T) (+∞ where infeasible) over T ∈ [lo, hi] (s): f(hi) and the probe
    f(hi − PROBE_FRACTION (hi − lo)); when the probe costs no less, stop (for a unimodal cost
    the minimum lies between them), else a golden-section search of GOLDEN_STEPS reductions on
    [lo, hi] in which ties and infeasible pairs keep the longer part. The caller records the
    values f returns and takes the least."""
    f_hi = f(hi)
    if hi <= lo or (math.isfinite(f_hi) and f(hi - PROBE_FRACTION * (hi - lo)) >= f_hi):
        return
    g = (math.sqrt(5) - 1) / 2
    a, b = lo, hi
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(GOLDEN_STEPS):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(d)


def plan_segment_scp(name: str, cell: CellConfig, location, start: EEState,
                     home: tg.Pose | None = None, rate: float = 500.0,
                     T_bounds: tuple | None = None,
                     problems: CompiledProblems | None = None) -> EETrajectory:
    """Optimise position, orientation and duration of subbehaviour ``name`` in task space.

    Args:
        name: One of :data:`flipkit.behaviors.library.FLIP_NAMES`.
        cell: Cell configuration.
        location: Burger location p^b (m).
        start: Start state (position, velocity, rpy and rpy rate; the previous subbehaviour's
            end, or the pose at q_start at rest).
        home: Home spatula pose (``turn_back`` only).
        rate: Sample rate of the output (Hz).
        T_bounds: Duration bounds (s); default collocation's (the specs' ``duration``).
        problems: The compiled subproblems to solve in and add to (default: new ones, for
            this call alone).

    Returns:
        The trajectory; ``solve_time_s`` is the whole duration search (all QP solves, and
        the subproblem's compilation when ``problems`` did not hold it yet).

    Raises:
        NoSolutionFound: No duration within the bounds gives a feasible SCP solution.
        ConfigError: Bad start state, rate or bounds, or ``turn_back`` without ``home``.
    """
    if name not in FLIP_NAMES:
        raise InvalidChoiceError("subbehaviour", name, FLIP_NAMES)
    if name == "turn_back" and home is None:
        raise ConfigError("turn_back needs the home pose")
    if not (np.isfinite(rate) and rate > 0):
        raise ConfigError(f"rate must be a positive number of Hz, got {rate!r}")
    lo, hi = SUBBEHAVIORS[name].duration if T_bounds is None else (float(T_bounds[0]), float(T_bounds[1]))
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi):
        raise ConfigError(f"duration bounds must satisfy 0 < lo <= hi, got {(lo, hi)}")
    for field_name in ("p", "v", "o", "w"):
        value = np.asarray(getattr(start, field_name), dtype=float)
        if value.shape != (3,) or not np.all(np.isfinite(value)):
            raise ConfigError(f"start.{field_name} must be 3 finite numbers, got {value.tolist()}")
    tic = time.perf_counter()
    task = ScpSegment(name, cell, tg.check_location(cell, location), start, home)
    qp = scp_subproblem(task, SAMPLES, problems)
    C, D = _guess_coeffs(qp.bez, np.linspace(0, 1, SAMPLES), start, task.guess_goal)
    evals: dict = {}

    def f(T: float) -> float:  # warm start: the best solution so far, a smaller region
        best = min(evals.values(), key=lambda r: (r["objective"], r["merit"]), default=None)
        if best is None:
            evals[T] = scp_at_duration(task, T, C, D, problem=qp)
        else:
            evals[T] = scp_at_duration(task, T, best["C"], best["D"], TRUST_WARM, problem=qp)
        return evals[T]["objective"]

    search_duration(f, lo, hi)
    T = min(evals, key=lambda k: (evals[k]["objective"], -k))
    best = evals[T]
    elapsed = time.perf_counter() - tic
    if not math.isfinite(best["objective"]):
        worst = min(r["violation"] for r in evals.values())
        raise NoSolutionFound(name, "infeasible", "scp_violation", worst)
    return _sampled(task, qp.bez, best, T, rate, elapsed, len(evals))


def _sampled(task: ScpSegment, bez: Bezier, sol: dict, T: float, rate: float, elapsed: float,
             n_durations: int) -> EETrajectory:
    t = sample_times(T, rate)
    s = t / T
    Bk = [bez.basis(s, k) / T**k for k in range(3)]
    p, v, a = (B @ sol["C"] for B in Bk)
    o, od = Bk[0] @ sol["D"], Bk[1] @ sol["D"]
    R = np.array([rpy_matrix(ok) for ok in o])
    frac = task.cone_frac.get(task.name, 0.0)
    cone = s <= frac + 1e-12 if frac else np.zeros(len(t), bool)
    return EETrajectory(task.name, float(T), t, p, v, a, o, R, cone, sol["C"], elapsed,
                        float(sol["objective"]), "optimal", od=od, o_coeffs=sol["D"],
                        iterations=sol["iterations"], max_violation=sol["violation"],
                        durations_tried=n_durations)


__all__ = ["DEGREE", "SAMPLES", "ScpSegment", "compile_subproblems", "plan_segment_scp",
           "scp_at_duration", "scp_subproblem", "search_duration", "violation"]
