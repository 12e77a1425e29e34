"""Simulated execution of a joint trajectory: a digital joint PD controller on the rigid arm.

The paper's robot tracks the planned joint positions and velocities with its own PD position
controller (footnote 2). Here the controller runs at ``rate_hz`` with zero-order hold,

    u = u_ff(t) + Kp (q_d − q) + Kd (q̇_d − q̇),   clipped to ±robot.u_max,

and the plant is integrated by semi-implicit (symplectic) Euler at the same rate:
q̈ = ABA(q, q̇, u), q̇ ← q̇ + Δt q̈, q ← q + Δt q̇. At 1 kHz this is stable for the default
gains (checked in tests by the spectral radius of the discretised closed loop) and its
truncation error is far below the tracking error. The desired q_d, q̇_d, q̈_d come from a cubic
Hermite spline through the samples (q, q̇).

The controller's model (feed-forward) is ``robot``; the plant is ``mismatch`` when given, e.g.
a :class:`~flipkit.model.robot.Robot` built with the burger payload that the controller ignores.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.interpolate import CubicHermiteSpline, interp1d

from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.model.robot import Robot

# UR10 joint PD gains. Kp (N·m/rad) gives closed-loop bandwidths of ~25–35 rad/s on the
# shoulder and elbow and ~100–240 rad/s on the wrist; Kd (N·m·s/rad) ≈ 2√(Kp·D_ii), with D_ii
# the diagonal of the joint-space inertia at q_home (1.6, 3.5, 2.0, 0.026, 0.033, 0.0009 kg·m²):
# about critical damping. Joint 6 turns only the blade about its long axis, hence its low gains.
DEFAULT_KP = (2000.0, 2000.0, 1000.0, 300.0, 300.0, 50.0)
DEFAULT_KD = (120.0, 160.0, 90.0, 6.0, 6.0, 0.4)
FEEDFORWARDS = ("inverse_dynamics", "gravity", "none")


@dataclass(frozen=True)
class SegmentError:
    """Spatula position tracking error over [t_start, t_end] (s): max and RMS (m)."""

    t_start: float
    t_end: float
    max: float
    rms: float


@dataclass
class TrackingResult:
    """Time series of a tracking simulation (N samples at the controller rate).

    Attributes:
        t: Times (s). q, qd: Actual joint positions (rad) and velocities (rad/s), N×nq.
        u: Applied (saturated) torques (N·m), N×nq. q_des, qd_des: Desired, N×nq.
        p, p_des: Actual / desired spatula-frame origin (m), N×3.
        R, R_des: Actual / desired spatula rotation (spatula→world), N×3×3.
        saturated: Whether any joint torque hit its limit at each sample (N bools).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    u: np.ndarray
    q_des: np.ndarray
    qd_des: np.ndarray
    p: np.ndarray
    p_des: np.ndarray
    R: np.ndarray
    R_des: np.ndarray
    saturated: np.ndarray

    @property
    def position_error(self) -> np.ndarray:
        """|p − p_des| at each sample (m)."""
        return np.linalg.norm(self.p - self.p_des, axis=1)

    def errors(self, segment_bounds=None) -> list[SegmentError]:
        """Per-segment max and RMS spatula position error (m).

        Args:
            segment_bounds: Increasing boundary times t_0 < t_1 < … < t_K (s) of K segments;
                ``None`` means one segment spanning the run.
        """
        b = np.asarray([self.t[0], self.t[-1]] if segment_bounds is None else segment_bounds,
                       dtype=float)
        if b.ndim != 1 or len(b) < 2 or np.any(np.diff(b) <= 0):
            raise ConfigError("segment_bounds must be at least two increasing times (s)")
        e, out = self.position_error, []
        for t0, t1 in zip(b[:-1], b[1:]):
            sel = (self.t >= t0 - 1e-9) & (self.t <= t1 + 1e-9)
            if not np.any(sel):
                raise ConfigError(f"segment [{t0}, {t1}] s holds no sample of the run")
            out.append(SegmentError(float(t0), float(t1), float(e[sel].max()),
                                    float(np.sqrt(np.mean(e[sel] ** 2)))))
        return out


def _gain(name: str, value, nq: int, positive: bool) -> np.ndarray:
    """A gain vector of nq finite values from a scalar or a sequence, or ConfigError."""
    try:
        g = np.broadcast_to(np.asarray(value, dtype=float), (nq,)).copy()
    except (ValueError, TypeError):
        g = None
    if g is None or not np.all(np.isfinite(g)) or np.any(g <= 0 if positive else g < 0):
        kind = "positive" if positive else "non-negative"
        raise ConfigError(f"{name} must be {kind} and finite, a scalar or {nq} values, "
                          f"got {value!r}")
    return g


def track(robot: Robot, t_des, q_des, qd_des, *, kp=None, kd=None, u_ff=None, rate_hz=1000.0,
          mismatch: Robot | None = None, q0=None) -> TrackingResult:
    """Simulate the arm following desired joint trajectories under joint PD control.

    Args:
        robot: The controller's model (feed-forward torques, spatula kinematics).
        t_des: Strictly increasing sample times (s), length n ≥ 2.
        q_des, qd_des: Desired positions (rad) and velocities (rad/s) at t_des, n×nq.
        kp, kd: PD gains (N·m/rad, N·m·s/rad), scalar or nq values; defaults
            :data:`DEFAULT_KP`, :data:`DEFAULT_KD` (UR10).
        u_ff: Feed-forward torque: ``None`` or ``"inverse_dynamics"`` (RNEA of the controller
            model along q_d, q̇_d, q̈_d), ``"gravity"`` (G(q_d)), ``"none"``, or an n×nq
            array sampled at t_des (N·m), linearly interpolated (e.g. a plan's u).
        rate_hz: Control and integration rate (Hz).
        mismatch: Plant model if it differs from ``robot`` (same joints).
        q0: Initial positions (rad); default q_des[0]. The initial velocity is qd_des[0].

    Returns:
        The :class:`TrackingResult` on [t_des[0], t_des[-1]].
    """
    nq = robot.nq
    t_des = np.asarray(t_des, dtype=float)
    n = t_des.size
    if t_des.ndim != 1 or n < 2 or not np.all(np.isfinite(t_des)) or np.any(np.diff(t_des) <= 0):
        raise ConfigError("t_des must be a strictly increasing 1-D array of at least 2 times (s)")
    Q, QD = np.asarray(q_des, dtype=float), np.asarray(qd_des, dtype=float)
    for name, arr in (("q_des", Q), ("qd_des", QD)):
        if arr.shape != (n, nq) or not np.all(np.isfinite(arr)):
            raise ConfigError(f"{name} must be a finite {n}x{nq} array, got shape {arr.shape}")
    kp = _gain("kp", DEFAULT_KP if kp is None else kp, nq, True)
    kd = _gain("kd", DEFAULT_KD if kd is None else kd, nq, False)
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise ConfigError(f"rate_hz must be positive, got {rate_hz!r}")
    plant = mismatch if mismatch is not None else robot
    if plant.nq != nq or plant.model.nv != nq or robot.model.nv != nq:
        raise ConfigError(f"plant and controller need the same {nq} joints with nq = nv")
    q = Q[0].copy() if q0 is None else np.asarray(q0, dtype=float).copy()
    if q.shape != (nq,) or not np.all(np.isfinite(q)):
        raise ConfigError(f"q0 must be {nq} finite values, got {q0!r}")

    dt = 1.0 / rate_hz
    t = t_des[0] + dt * np.arange(int(np.floor((t_des[-1] - t_des[0]) * rate_hz + 1e-9)) + 1)
    t = np.minimum(t, t_des[-1])  # the 1e-9 slack may put the last sample a hair past the end
    spline = CubicHermiteSpline(t_des, Q, QD, axis=0)
    qs, qds, qdds = spline(t), spline(t, 1), spline(t, 2)
    if isinstance(u_ff, str) or u_ff is None:
        mode = u_ff or "inverse_dynamics"
        if mode not in FEEDFORWARDS:
            raise InvalidChoiceError("feed-forward", mode, FEEDFORWARDS)
        m, d, z = robot.model, robot.data, np.zeros(nq)
        ff = np.array([pin.rnea(m, d, qs[k], qds[k], qdds[k]) if mode == "inverse_dynamics"
                       else pin.computeGeneralizedGravity(m, d, qs[k]) if mode == "gravity"
                       else z for k in range(len(t))])
    else:
        U = np.asarray(u_ff, dtype=float)
        if U.shape != (n, nq) or not np.all(np.isfinite(U)):
            raise ConfigError(f"u_ff array must be finite {n}x{nq}, got shape {U.shape}")
        ff = interp1d(t_des, U, axis=0)(t)

    N = len(t)
    qa, qda, ua = np.zeros((N, nq)), np.zeros((N, nq)), np.zeros((N, nq))
    qd = QD[0].copy()
    umax, pm, pd_ = robot.u_max, plant.model, plant.data
    for k in range(N):
        u = np.clip(ff[k] + kp * (qs[k] - q) + kd * (qds[k] - qd), -umax, umax)
        qa[k], qda[k], ua[k] = q, qd, u
        qd = qd + dt * pin.aba(pm, pd_, q, qd, u)
        q = pin.integrate(pm, q, dt * qd)

    def poses(qq):
        M = [robot.placement(x) for x in qq]
        return np.array([m.translation for m in M]), np.array([m.rotation for m in M])

    p, R = poses(qa)
    p_des, R_des = poses(qs)
    return TrackingResult(t=t, q=qa, qd=qda, u=ua, q_des=qs, qd_des=qds, p=p, p_des=p_des, R=R,
                          R_des=R_des, saturated=np.any(np.abs(ua) >= umax - 1e-12, axis=1))
