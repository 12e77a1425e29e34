"""Failure classification of a joint path, per subbehaviour: one judge for the EE + IK baseline
and for collocation plans (:func:`classify_plan`, resampled at the same rate).

Every measurement uses flipkit's pinocchio model (:class:`flipkit.model.robot.Robot`), not placo.
The checks run in this order and the first one that fails is the verdict:

0. ``unreachable`` — closed-form IK only: a sample whose pose has no branch within the
   joint limits (the configuration is held there).
1. ``tracking_error`` — spatula pose error, max over samples: position > 1 mm or rotation
   angle |log(R_refᵀ R)| > 0.01 rad. Then ``singularity`` — the spatula Jacobian's smallest
   singular value below :attr:`Thresholds.sigma_min`.
2. ``joint_limit`` — a joint within 1e-3 rad of q_min or q_max.
3. ``configuration_jump`` — |Δq| between consecutive samples > 0.2 rad (a branch switch).
   It runs before the rate checks: a jump of 0.2 rad in one 5 ms sample is a 40 rad/s
   finite difference, so it would otherwise always be reported as an over-speed.
4. ``joint_velocity`` / ``joint_acceleration`` — finite differences of q (second order,
   ``np.gradient``) above qd_max / the segment's acceleration bound (``Robot.qdd_bound``:
   none for the free motions, go to burger and turn back).
5. ``torque`` — RNEA along (q, q̇, q̈) with the segment's payload above u_max.
6. ``below_grill`` — a blade edge (tip, heel, sides) lower than h_g − 1 mm (in go-to-burger,
   scoop and pickup, which end, run or start with the blade pressed into the grill,
   h_g − 1 mm − the commanded press and its band).

``ee_infeasible`` marks a subbehaviour whose end-effector QP had no solution.

Each reason has a class (:data:`CLASSES`): ``kinematic`` (no joint path realises the poses:
unreachable, singular, a branch switch or jump, a joint limit, a tracking error, the blade
below the grill), ``dynamic`` (a path exists but breaks a velocity, acceleration or torque
limit) and ``ee`` (the end-effector QP itself). A dynamic failure that passes when the same
path is slowed down uniformly by a factor s ≤ :data:`MAX_TIME_SCALING` (q̇/s, q̈/s², RNEA
at those) is classed ``time_scalable`` instead, with s recorded in ``time_scaling``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from scipy.interpolate import CubicHermiteSpline

from flipkit.baseline.ee_opt import sample_times
from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.behaviors.options import SCOOP_PRESS, SCOOP_TIP_BAND
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot

REASONS = ("ee_infeasible", "unreachable", "singularity", "tracking_error", "joint_limit",
           "configuration_jump", "joint_velocity", "joint_acceleration", "torque", "below_grill")
CLASSES = {"ee_infeasible": "ee", "unreachable": "kinematic", "singularity": "kinematic",
           "tracking_error": "kinematic", "joint_limit": "kinematic",
           "configuration_jump": "kinematic", "below_grill": "kinematic",
           "joint_velocity": "dynamic", "joint_acceleration": "dynamic", "torque": "dynamic"}
FAILURE_CLASSES = ("ee", "kinematic", "dynamic", "time_scalable")
MAX_TIME_SCALING = 2.0  # time-scalable: slowing the EE trajectory by at most 2x makes it pass
UNITS = {"ee_infeasible": "", "unreachable": "s", "singularity": "1",
         "tracking_error": "m or rad", "joint_limit": "rad",
         "configuration_jump": "rad", "joint_velocity": "rad/s",
         "joint_acceleration": "rad/s^2", "torque": "N m", "below_grill": "m"}
EDGES = ("tip", "heel", "left", "right")
PRESSED = ("go_to_burger", "scoop", "pickup")  # subbehaviours where the blade is pressed


@dataclass(frozen=True)
class Thresholds:
    """Failure thresholds.

    Attributes:
        position: Spatula position tracking error (m). rotation: Rotation error (rad).
        limit_margin: Distance to a joint limit that counts as reaching it (rad).
        jump: Joint change between consecutive samples that counts as a jump (rad).
        grill_margin: Depth below the grill surface a blade edge may reach (m).
        rate_tolerance: Relative tolerance on the velocity, acceleration and torque limits,
            for the error of their finite differences: at h = 2 ms (500 Hz) the one-sided
            difference at a segment's end is off by up to h²|q⃛|/3, 4e-4 rad/s for a jerk of
            300 rad/s³ (a turn back that starts exactly at q̇_max reads about 1e-4 rad/s
            above it there). The IK holds a saturated joint at qd_max; its
            finite difference is qd_max to rounding.
        sigma_min: Smallest singular value of the 6×6 spatula Jacobian (linear part in m/rad,
            angular in rad/rad) below which a sample counts as singular. Our choice: 0.01, a
            hundredth of the arm's typical values (0.1–1), where the IK's joint rates are
            about a hundred times the spatula's.
    """

    position: float = 1e-3
    rotation: float = 0.01
    limit_margin: float = 1e-3
    jump: float = 0.2
    grill_margin: float = 1e-3
    rate_tolerance: float = 1e-3
    sigma_min: float = 0.01

    def __post_init__(self):
        for name in ("position", "rotation", "limit_margin", "jump", "grill_margin",
                     "rate_tolerance", "sigma_min"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ConfigError(f"threshold {name} must be positive, got {value!r}")


@dataclass
class SegmentVerdict:
    """Outcome of one subbehaviour.

    Attributes:
        subbehavior: Name. status: ``solved`` or ``failed``.
        reason: One of :data:`REASONS`, or ``None`` when solved.
        amount: The measured value that failed (units in :data:`UNITS`; NaN when solved).
        limit: The bound it broke. detail: Which joint/edge, when, one line.
        ee_time_s: End-effector QP wall time (s). ik_time_s: IK wall time (s).
        measures: Every check's worst value (tracking_position_m, tracking_rotation_rad,
            limit_margin_rad, max_jump_rad, velocity_ratio, acceleration_ratio,
            torque_ratio, min_edge_height_m).
    """

    subbehavior: str
    status: str
    reason: str | None = None
    amount: float = float("nan")
    limit: float = float("nan")
    detail: str = ""
    ee_time_s: float = 0.0
    ik_time_s: float = 0.0
    measures: dict = field(default_factory=dict)
    time_scaling: float = float("nan")

    @property
    def failure_class(self) -> str | None:
        """One of :data:`FAILURE_CLASSES` (None when solved)."""
        if self.reason is None:
            return None
        if CLASSES[self.reason] == "dynamic" and self.time_scaling <= MAX_TIME_SCALING:
            return "time_scalable"
        return CLASSES[self.reason]


def _worst_ratio(values: np.ndarray, bound: np.ndarray):
    """(ratio, k, j) of the largest |values[k, j]| / bound[j]."""
    ratio = np.abs(values) / bound[None]
    k, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    return float(ratio[k, j]), k, j


def classify_segment(name: str, robot: Robot, t, q, p_ref, R_ref, *,
                     thresholds: Thresholds = Thresholds(), ee_time_s: float = 0.0,
                     ik_time_s: float = 0.0, branch=None) -> SegmentVerdict:
    """Classify the joint trajectory q(t) that should realise the spatula poses (p_ref, R_ref).

    Args:
        name: Subbehaviour name (recorded).
        robot: Model with the segment's payload (burger on the blade or not).
        t: Sample times (s), ≥ 3, increasing. q: Joint angles (rad), (n, nq).
        p_ref: Reference positions (m), (n, 3). R_ref: Reference rotations, (n, 3, 3).
        thresholds: Failure thresholds. ee_time_s, ik_time_s: Recorded wall times (s).
        branch: Closed-form IK branch per sample (−1: none exists), or None.
    """
    t, q = np.asarray(t, float), np.asarray(q, float)
    p_ref, R_ref = np.asarray(p_ref, float), np.asarray(R_ref, float)
    n = len(t)
    if n < 3 or q.shape != (n, robot.nq) or p_ref.shape != (n, 3) or R_ref.shape != (n, 3, 3):
        raise ConfigError(f"classify: need >= 3 samples with q (n, {robot.nq}), p (n, 3), "
                          f"R (n, 3, 3); got t {t.shape}, q {q.shape}, p {p_ref.shape}")
    if np.any(np.diff(t) <= 0):
        raise ConfigError("classify: sample times must increase")
    cell, th = robot.cell, thresholds
    sp = cell.spatula
    edges = np.array([[sp.length / 2, 0, 0], [-sp.length / 2, 0, 0],
                      [0, sp.width / 2, 0], [0, -sp.width / 2, 0]]).T
    e_pos, e_rot, heights, sigma = np.empty(n), np.empty(n), np.empty((n, 4)), np.empty(n)
    for k in range(n):
        _, _, Jp, Jw = robot.pose_jacobians(q[k])
        sigma[k] = np.linalg.svd(np.vstack([Jp, Jw]), compute_uv=False)[-1]
        M = robot.placement(q[k])
        e_pos[k] = np.linalg.norm(M.translation - p_ref[k])
        e_rot[k] = np.linalg.norm(pin.log3(R_ref[k].T @ M.rotation))
        heights[k] = M.translation[2] + (M.rotation @ edges)[2]
    margin = np.minimum(q - robot.q_min, robot.q_max - q)
    dq = np.abs(np.diff(q, axis=0))
    qd = np.gradient(q, t, axis=0, edge_order=2)
    qdd = np.gradient(qd, t, axis=0, edge_order=2)
    u = np.array([robot.inverse_dynamics(q[k], qd[k], qdd[k]) for k in range(n)])
    v_ratio, vk, vj = _worst_ratio(qd, robot.qd_max)
    qdd_max = robot.qdd_bound(name in SUBBEHAVIORS and SUBBEHAVIORS[name].free_motion)
    a_ratio, ak, aj = _worst_ratio(qdd, qdd_max)
    u_ratio, uk, uj = _worst_ratio(u, robot.u_max)
    # the scoop commands the tip SCOOP_PRESS into the grill (±SCOOP_TIP_BAND), for both methods'
    # plans alike: the blade may go that deep where it is pressed (behaviors.transcribe.blade_floor:
    # the go-to-burger's end, the scoop, the pickup's start)
    depth = th.grill_margin + (SCOOP_PRESS + SCOOP_TIP_BAND if name in PRESSED else 0.0)
    floor = cell.grill.height - depth
    measures = {"tracking_position_m": float(e_pos.max()),
                "tracking_rotation_rad": float(e_rot.max()),
                "limit_margin_rad": float(margin.min()), "max_jump_rad": float(dq.max()),
                "velocity_ratio": v_ratio, "acceleration_ratio": a_ratio,
                "torque_ratio": u_ratio, "min_edge_height_m": float(heights.min()),
                "sigma_min": float(sigma.min())}

    def fail(reason, amount, limit, detail):
        scale = (time_scaling(robot, t, q, th.rate_tolerance, qdd_max=qdd_max)
                 if CLASSES[reason] == "dynamic" else float("nan"))
        return SegmentVerdict(name, "failed", reason, float(amount), float(limit), detail,
                              ee_time_s, ik_time_s, measures, scale)

    if branch is not None and np.any(np.asarray(branch) < 0):
        missing = np.flatnonzero(np.asarray(branch) < 0)
        return fail("unreachable", len(missing) * (t[1] - t[0]), 0.0,
                    f"{len(missing)} samples without an IK branch in the joint limits, first at "
                    f"t={t[missing[0]]:.3f} s")

    rp, rr = e_pos.max() / th.position, e_rot.max() / th.rotation
    if max(rp, rr) > 1:
        k = int(np.argmax(e_pos if rp >= rr else e_rot))
        amount, limit = (e_pos[k], th.position) if rp >= rr else (e_rot[k], th.rotation)
        return fail("tracking_error", amount, limit,
                    f"t={t[k]:.3f} s: position {e_pos[k] * 1e3:.2f} mm, rotation "
                    f"{e_rot[k]:.4f} rad (limits {th.position * 1e3:g} mm, {th.rotation:g} rad)")
    if sigma.min() < th.sigma_min:
        k = int(np.argmin(sigma))
        return fail("singularity", sigma[k], th.sigma_min,
                    f"t={t[k]:.3f} s: smallest singular value {sigma[k]:.3g} of the spatula "
                    f"Jacobian (q5 = {q[k, 4]:.3f} rad)")
    if margin.min() < th.limit_margin:
        k, j = np.unravel_index(int(np.argmin(margin)), margin.shape)
        return fail("joint_limit", margin[k, j], th.limit_margin,
                    f"joint {j + 1} = {q[k, j]:.4f} rad at t={t[k]:.3f} s, limits "
                    f"[{robot.q_min[j]:.4f}, {robot.q_max[j]:.4f}] rad")
    if dq.max() > th.jump:
        k, j = np.unravel_index(int(np.argmax(dq)), dq.shape)
        return fail("configuration_jump", dq[k, j], th.jump,
                    f"joint {j + 1} between t={t[k]:.3f} s and t={t[k + 1]:.3f} s")
    for reason, ratio, k, j, values, bound in (
            ("joint_velocity", v_ratio, vk, vj, qd, robot.qd_max),
            ("joint_acceleration", a_ratio, ak, aj, qdd, qdd_max),
            ("torque", u_ratio, uk, uj, u, robot.u_max)):
        if ratio > 1 + th.rate_tolerance:
            return fail(reason, abs(values[k, j]), bound[j],
                        f"joint {j + 1} at t={t[k]:.3f} s: {abs(values[k, j]):.3g} > "
                        f"{bound[j]:.3g} {UNITS[reason]}")
    if heights.min() < floor:
        k, e = np.unravel_index(int(np.argmin(heights)), heights.shape)
        return fail("below_grill", heights[k, e], floor,
                    f"blade {EDGES[e]} at z={heights[k, e]:.4f} m, t={t[k]:.3f} s "
                    f"(grill {cell.grill.height:g} m)")
    return SegmentVerdict(name, "solved", ee_time_s=ee_time_s, ik_time_s=ik_time_s,
                          measures=measures)


def _rate_ratio(robot: Robot, t, q, s: float, qdd_max) -> float:
    """Largest velocity, acceleration (bound ``qdd_max``) or torque ratio of the path q(t) run
    s times slower."""
    qd = np.gradient(q, t, axis=0, edge_order=2) / s
    qdd = np.gradient(np.gradient(q, t, axis=0, edge_order=2), t, axis=0, edge_order=2) / s**2
    u = np.array([robot.inverse_dynamics(q[k], qd[k], qdd[k]) for k in range(len(t))])
    return max(_worst_ratio(qd, robot.qd_max)[0], _worst_ratio(qdd, qdd_max)[0],
               _worst_ratio(u, robot.u_max)[0])


def time_scaling(robot: Robot, t, q, tolerance: float = 1e-6, steps: int = 20, *,
                 qdd_max=None) -> float:
    """The smallest uniform slow-down factor s ∈ [1, :data:`MAX_TIME_SCALING`] with which the
    path passes the velocity, acceleration (``qdd_max``, default ``robot.qdd_max``) and torque
    limits (bisection, ``steps`` halvings); ``inf`` if even s = MAX_TIME_SCALING does not."""
    qdd_max = robot.qdd_max if qdd_max is None else qdd_max
    if _rate_ratio(robot, t, q, MAX_TIME_SCALING, qdd_max) > 1 + tolerance:
        return float("inf")
    lo, hi = 1.0, MAX_TIME_SCALING
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        lo, hi = ((lo, mid) if _rate_ratio(robot, t, q, mid, qdd_max) <= 1 + tolerance
                  else (mid, hi))
    return hi


@dataclass
class BaselineResult:
    """End-effector-space + IK baseline at one burger location.

    Attributes:
        location: Burger location p^b (m). segments: One verdict per subbehaviour run, in
            order (fewer than five when an end-effector QP was infeasible).
        trajectories: The end-effector trajectories. tracks: The IK joint trajectories.
    """

    location: tuple
    segments: list
    trajectories: list = field(default_factory=list)
    tracks: list = field(default_factory=list)

    @property
    def failure(self) -> SegmentVerdict | None:
        """The first failed subbehaviour, or ``None``."""
        return next((s for s in self.segments if s.status == "failed"), None)

    @property
    def status(self) -> str:
        """``solved`` when all five subbehaviours ran and passed, else ``failed``."""
        return "solved" if self.failure is None and len(self.segments) == 5 else "failed"

    @property
    def reason(self) -> str | None:
        return self.failure.reason if self.failure else None

    @property
    def subbehavior(self) -> str | None:
        return self.failure.subbehavior if self.failure else None

    @property
    def amount(self) -> float:
        return self.failure.amount if self.failure else float("nan")

    @property
    def time_s(self) -> dict:
        """{subbehaviour: {"ee": s, "ik": s}} wall times."""
        return {s.subbehavior: {"ee": s.ee_time_s, "ik": s.ik_time_s} for s in self.segments}


def resample_segment(seg, rate: float = 500.0):
    """A plan segment at ``rate`` Hz as the controller follows it: (t (s), q (rad)), the cubic
    Hermite interpolant of the nodes' (q, q̇) (:mod:`flipkit.simulation.execute`)."""
    t = sample_times(seg.T, rate)
    return t, CubicHermiteSpline(seg.t, seg.q, seg.qd, axis=0)(t)


def classify_plan(plan, rate: float = 500.0, thresholds: Thresholds = Thresholds()) -> list:
    """The same judge on a collocation plan: each segment resampled at ``rate``
    (:func:`resample_segment`), its own spatula poses as the reference (a joint-space plan has
    no tracking error), with the segment's payload.

    Args:
        plan: A :class:`~flipkit.planning.plans.plan_file.Plan`. rate: Sample rate (Hz).

    Returns:
        One :class:`SegmentVerdict` per segment.
    """
    cell, out = plan.cell(), []
    for seg in plan.segments:
        robot = plan.robot_for(seg, cell)
        t, q = resample_segment(seg, rate)
        M = [robot.placement(qk) for qk in q]
        out.append(classify_segment(seg.name, robot, t, q, np.array([m.translation for m in M]),
                                    np.array([m.rotation for m in M]), thresholds=thresholds))
    return out
