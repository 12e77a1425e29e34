"""Position commands that a joint position servo tracks as the plan intends.

A UR10 driven by position commands (``servoj``: desired q, with q̇ from their differences)
closes its own joint loop. flipkit models that loop (:class:`~flipkit.config.PhysicsConfig`)
as

    u = g_c(q) + Kp (q_c − q) + Kd (q̇_c − q̇),

with g_c the controller's gravity model (the arm and the payload it was told: the spatula,
not the burger), and the command (q_c, q̇_c) sampled at ``servo_rate_hz`` (zero-order hold)
and arriving ``latency_s`` late. Sent the plan's (q, q̇) as it is, the servo produces no
inertial torque until an error builds up: it lags, by centimetres at the blade in a flip.

The compensated command makes the servo's torque equal the plan's at the plan's own state.
With (q_d, q̇_d, u_d) the plan at the time the sample will act,

    q_c = q_d + Kp⁻¹ (u_d − g_c(q_d)),   q̇_c = q̇_d,

so on the plan u = u_d: the plan's torques (inverse dynamics of the arm with its payload,
burger included while carried), delivered through the position interface. The time the
sample will act is the send time plus the transport latency plus half a servo period (the
middle of its hold). The compensation uses the nominal servo model; its gains, rate and
latency are uncertain and swept by the sensitivity study.

A servo that smooths its commands (``servo_lookahead_s`` > 0, UR's ``servoj`` lookahead;
default 0.1 s, servoj's own) passes them through a first-order low-pass (:func:`smoothed`)
before its PD; the commands are then made for it by the filter's inverse
(:func:`lookahead_command`), within each segment of the plan.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from scipy.signal import lfilter

from flipkit.errors import ConfigError, InvalidChoiceError

COMMANDS = ("raw", "compensated")
"""``raw``: the plan's (q, q̇) as they are; ``compensated``: q_c as in the module docstring."""

DEFAULT_COMMAND = "raw"
"""The command a controller is sent unless told otherwise: the plan's (q, q̇), as the paper
sends them (its footnote 2). The compensated stream asks a UR10 for more than its published
joint speeds where the plan's torque steps (segment joins; docs/arm-profile.md), and the
stream check refuses it there."""


def paused(t: np.ndarray, t_pause: float, pause: float) -> np.ndarray:
    """Plan times of run times ``t`` (s) when the plan stops at ``t_pause`` for ``pause`` s."""
    return np.where(t < t_pause, t, np.maximum(t - pause, t_pause))


def hold_torque(plan) -> np.ndarray:
    """The torque (N·m) that holds the plan's final configuration at rest: gravity of the
    model of its last segment (with the payload that segment carries).

    A plan ends at rest (q̇ = 0), but its last node's torque includes M q̈ of an acceleration
    that ends there; held after the plan, that torque would move the arm on, towards a rest
    Kp⁻¹ M q̈ away in position mode."""
    last = plan.segments[-1]
    return np.asarray(plan.robot_for(last).inverse_dynamics(
        last.q[-1], np.zeros_like(last.q[-1]), np.zeros_like(last.q[-1])), float)




def lookahead_command(q_c, qd_c, qdd, t, physics, pieces=None) -> tuple[np.ndarray, np.ndarray]:
    """Commands made for the servo's smoothing (``physics.servo_lookahead_s`` = τ, a
    first-order low-pass y' = (x − y)/τ between the commands and the PD): its inverse,
    x = q_c + τ q̇_c and ẋ = q̇ + τ q̈, so that the smoothed command is (q_c, q̇) where the
    plan is smooth. q̇_c is the rate of the command itself (finite differences over the
    samples of one piece: it includes the rate of the torque compensation), q̈ the plan's.
    τ = 0: the commands as they are.

    Where a plan's segments meet, its torque, and so the compensation, steps by Δ.
    Inverting a step takes an impulse τ Δ: a command τ/Δt times the step for one sample
    (12 Δ at 125 Hz and τ 0.1 s, 50 Δ at 500 Hz), which no arm should be sent. So the rate is
    taken within each piece (``pieces``: the samples' segment labels), and each step's
    impulse is spread over the samples within τ/2 of it: about Δ more command for τ. The
    smoothed command then crosses the step centred on it and is back on the plan's within
    τ after it (passed as it is, it would still lag by Δ/e there).

    Args:
        q_c, qd_c: Commands (rad, rad/s), n×nq (:func:`position_command`).
        qdd: The plan's accelerations (rad/s²) at the samples, n×nq.
        t: The samples' times (s), increasing, n.
        physics: The cell's model of its servo (:class:`~flipkit.config.PhysicsConfig`).
        pieces: Integer labels (n,), equal along each smooth piece (a plan's segment);
            default one piece.
    """
    tau = float(physics.servo_lookahead_s)
    q_c, qd_c = np.asarray(q_c, float), np.asarray(qd_c, float)
    if tau == 0.0 or len(q_c) == 0:
        return q_c, qd_c
    t = np.asarray(t, float)
    labels = np.zeros(len(q_c), int) if pieces is None else np.asarray(pieces)
    cuts = np.flatnonzero(np.diff(labels)) + 1
    rate = np.zeros_like(q_c)
    for a, b in zip(np.r_[0, cuts], np.r_[cuts, len(q_c)]):
        if b - a >= 2:
            rate[a:b] = np.gradient(q_c[a:b], t[a:b], axis=0)
    x = q_c + tau * rate
    for c in cuts:  # each step's impulse τ Δ, spread over τ centred on it: about Δ high
        dt = t[c] - t[c - 1]
        step = q_c[c] - q_c[c - 1] - 0.5 * dt * (rate[c - 1] + rate[c])
        m = max(1, int(round(tau / dt)))
        lo, hi = max(0, c - m // 2), min(len(x), c - m // 2 + m)
        x[lo:hi] += tau * step / (m * dt)
    return x, qd_c + tau * np.asarray(qdd, float)


def segment_labels(plan, t) -> np.ndarray:
    """The segment index of each plan time ``t`` (s, from the plan's start): k on
    [start_k, end_k) (0 before the start), ``len(plan.segments)`` from the end on."""
    ends = np.cumsum([float(s.t[-1] - s.t[0]) for s in plan.segments])
    return np.searchsorted(ends - 1e-12, np.asarray(t, float), side="left")


def smoothed(x: np.ndarray, dt: float, tau: float, start=None) -> np.ndarray:
    """The servo's smoothing of a command stream ``x`` (n×nq) sampled every ``dt`` s: the
    first-order low-pass of time constant ``tau`` (s), exact for a stream held between
    samples (y_k = y_{k−1} + a (x_{k−1} − y_{k−1}), a = 1 − e^{−dt/τ}); ``tau`` = 0: ``x``.

    Args:
        start: The filter's output at sample 0 (nq,): what the servo held before the stream
            began (the arm's state at rest before a plan). Default ``x[0]``.
    """
    x = np.asarray(x, float)
    if tau == 0.0 or len(x) == 0:
        return x
    a = -np.expm1(-dt / tau)
    y0 = x[:1] if start is None else np.asarray(start, float).reshape(1, -1)
    # y_k − (1 − a) y_{k−1} = a x_{k−1}, the state set so that y_0 = start
    return lfilter([0.0, a], [1.0, a - 1.0], x, axis=0, zi=y0)[0]


def command_lead(physics) -> float:
    """Time (s) between sending a sample and the middle of its hold at the servo."""
    return float(physics.latency_s + 0.5 / physics.servo_rate_hz)


def position_command(q_d, qd_d, u_d, controller_model, physics,
                     kind: str = "compensated") -> tuple[np.ndarray, np.ndarray]:
    """Commands (q_c, q̇_c) (rad, rad/s) for desired samples (n×nq) of a plan.

    Args:
        q_d, qd_d, u_d: The plan's positions, velocities and torques (N m) at the times the
            samples will act (n×nq each).
        controller_model: The servo's pinocchio model (its gravity compensation g_c).
        physics: :class:`~flipkit.config.PhysicsConfig`: ``kp`` of the servo as modelled.
        kind: One of :data:`COMMANDS`.

    Raises:
        InvalidChoiceError: Unknown ``kind``. ConfigError: Arrays of different shapes.
    """
    if kind not in COMMANDS:
        raise InvalidChoiceError("position command", kind, COMMANDS)
    q_d, qd_d, u_d = (np.asarray(a, float) for a in (q_d, qd_d, u_d))
    if not (q_d.shape == qd_d.shape == u_d.shape) or q_d.ndim != 2:
        raise ConfigError(f"position command needs n×nq arrays of one shape, got {q_d.shape}, "
                          f"{qd_d.shape}, {u_d.shape}")
    if kind == "raw":
        return q_d.copy(), qd_d.copy()
    kp = np.asarray(physics.kp, float)
    data = controller_model.createData()
    gravity = np.array([pin.computeGeneralizedGravity(controller_model, data, x) for x in q_d])
    return q_d + (u_d - gravity) / kp, qd_d.copy()


def smooths(physics, kind: str) -> bool:
    """Whether ``kind`` commands are made for a smoothing servo (``compensated`` ones, and
    ``physics.servo_lookahead_s`` > 0): they then need the plan's q̈ (:func:`servo_commands`)."""
    return kind == "compensated" and physics.servo_lookahead_s > 0


def servo_commands(plan, t, at, q_d, qd_d, u_d, qdd, controller_model, physics,
                   kind: str = "compensated") -> tuple[np.ndarray, np.ndarray]:
    """The commands (q_c, q̇_c) (rad, rad/s) a servo receives for ``plan``'s samples sent at
    ``t`` (s, n, increasing) and acting at plan times ``at`` (s, n; constant while the plan
    pauses): :func:`position_command`, then, where the servo smooths (:func:`smooths`),
    :func:`lookahead_command` within the plan's segments. The simulation's position mode and
    the URScript export both send these.

    Args:
        plan: The plan (its segments' durations). q_d, qd_d, u_d, qdd: The plan at ``at``
            (n×nq; ``qdd`` only read where the servo smooths). controller_model, physics,
            kind: As :func:`position_command`; ``physics`` is the servo model, its
            ``servo_lookahead_s`` the smoothing the commands are made for.
    """
    q_c, qd_c = position_command(q_d, qd_d, u_d, controller_model, physics, kind)
    if smooths(physics, kind):
        q_c, qd_c = lookahead_command(q_c, qd_c, qdd, t, physics, segment_labels(plan, at))
    return q_c, qd_c


__all__ = ["COMMANDS", "DEFAULT_COMMAND", "command_lead", "hold_torque", "paused", "lookahead_command", "position_command",
           "segment_labels", "servo_commands", "smoothed", "smooths"]
