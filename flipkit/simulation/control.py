"""The arm's joint controller and the stepping of a plan on a compiled cell.

A plan becomes :class:`References` on the controller's clock (:func:`plan_references`): the
desired state (per-segment cubic Hermite q, q̇; linear u) and, in position mode, the delayed,
servo-rate commands the robot's PD receives (smoothed first where the servo smooths them,
``physics.servo_lookahead_s``). :class:`ArmController` turns the measured state
into joint torques (the two controllers of :mod:`flipkit.simulation.execute`), and
:func:`step_references` runs one plan on a scene as it is, whatever else the scene holds:
:func:`~flipkit.simulation.execute.execute_plan` on a one-burger cell, the cook simulation
(:mod:`flipkit.simulation.cook`) on a cell with every burger of the cook.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import mujoco
import numpy as np
import pinocchio as pin
from scipy.interpolate import CubicHermiteSpline

from flipkit.model.robot import Robot
from flipkit.planning.plans.export_urscript import servo_stream
from flipkit.planning.plans.servo_command import hold_torque, paused, smoothed
from flipkit.simulation.modes import FEEDFORWARD, POSITION
from flipkit.simulation.scene import ARM_JOINTS, Scene


def pause_steps(wall_s: float, dt: float, lead_s: float = 0.0) -> float:
    """The arm's pause (s) for a re-plan of ``wall_s`` s that had ``lead_s`` s of motion still
    to run when it started: whole control steps of ``dt`` covering the part beyond the lead,
    0 if none."""
    excess = wall_s - lead_s
    return dt * np.ceil(excess / dt - 1e-9) if excess > 0 else 0.0


def desired(plan, t: np.ndarray, accelerations: bool = False, hold_u=None):
    """Plan's desired q, q̇ (per-segment cubic Hermite) and u (per-segment linear) at times t
    (s, from 0); after the last segment the final q with q̇ = 0 and ``hold_u`` (default the
    final u; :func:`hold_torque` holds it at rest). With ``accelerations``, also q̈ (the
    splines' second derivative; 0 after the plan), last."""
    n, start = len(t), 0.0
    q, qd, u = np.zeros((n, ARM_JOINTS)), np.zeros((n, ARM_JOINTS)), np.zeros((n, ARM_JOINTS))
    qdd = np.zeros((n, ARM_JOINTS)) if accelerations else None
    bounds = {}
    for seg in plan.segments:
        ts = start + seg.t - seg.t[0]
        sel = (t >= ts[0] - 1e-12) & (t <= ts[-1] + 1e-12)
        spl = CubicHermiteSpline(ts, seg.q, seg.qd, axis=0)
        tt = np.clip(t[sel], ts[0], ts[-1])
        q[sel], qd[sel] = spl(tt), spl(tt, 1)
        if accelerations:
            qdd[sel] = spl(tt, 2)
        u[sel] = np.column_stack([np.interp(tt, ts, seg.u[:, j]) for j in range(ARM_JOINTS)])
        bounds[seg.name] = (float(ts[0]), float(ts[-1]))
        start = float(ts[-1])
    after = t > start + 1e-12
    last = plan.segments[-1]
    q[after], qd[after] = last.q[-1], 0.0
    u[after] = last.u[-1] if hold_u is None else hold_u
    if accelerations:
        qdd[after] = 0.0
        return q, qd, u, bounds, qdd
    return q, qd, u, bounds


@dataclass(frozen=True)
class References:
    """A plan's references on the controller's clock, N samples from the plan's start.

    Attributes:
        t: Sample times (s). q_des, qd_des: Desired (undelayed) joint positions (rad) and
            velocities (rad/s), N×6. u_ff: The plan's torques (N·m), N×6. bounds:
            ``{segment: (t_start, t_end)}`` (s). q_cmd, qd_cmd: What the joint PD receives:
            the desired state (feed-forward mode) or position mode's delayed, servo-rate
            commands (N×6). qdd_cmd: Position mode's commanded acceleration (rad/s², N×6),
            the smoothed commands' own, which a ``model_based`` servo feeds forward; ``None``
            in feed-forward mode.
    """

    t: np.ndarray
    q_des: np.ndarray
    qd_des: np.ndarray
    u_ff: np.ndarray
    bounds: dict
    q_cmd: np.ndarray
    qd_cmd: np.ndarray
    qdd_cmd: np.ndarray | None = None


def plan_references(plan, robot: Robot, physics, mode: str, command: str, dt: float,
                    hold: float, t_pause: float = np.inf, pause: float = 0.0,
                    servo=None) -> References:
    """The references of ``plan`` every ``dt`` s until ``hold`` s after its end (module
    docstring: the two controllers), the plan paused ``pause`` s at ``t_pause`` (a replan).

    Args:
        plan: A solved plan. robot: The arm (position mode's controller model).
        physics: The plant's :class:`~flipkit.config.PhysicsConfig` (servo rate, latency).
        mode, command: As :func:`execute_plan`. dt: Controller period (s).
        hold: Time (s) the last desired state is held after the plan.
        servo: The cell's model of its servo, which the commands use (a
            :class:`~flipkit.config.PhysicsConfig`); default the plan's nominal one
            (``plan.cell().physics``). Its smoothing is taken from ``physics``
            (``servo_lookahead_s``): the cell sets it.
    """
    nominal = plan.cell().physics if servo is None else servo
    # the servo's smoothing is the cell's own setting (servoj's lookahead): always known
    nominal = replace(nominal, servo_lookahead_s=physics.servo_lookahead_s)
    T = sum(float(s.t[-1] - s.t[0]) for s in plan.segments) + pause
    t = dt * np.arange(int(np.floor((T + hold) / dt + 1e-9)) + 1)
    rest = hold_torque(plan)  # after the plan: its final configuration held at rest
    q_des, qd_des, u_ff, bounds = desired(plan, paused(t, t_pause, pause), hold_u=rest)
    bounds = {k: (a + pause if a >= t_pause - 1e-9 else a,
                  b + pause if b > t_pause + 1e-9 else b) for k, (a, b) in bounds.items()}
    if mode == POSITION:  # the servoj stream as export writes it, arriving latency_s late
        rate = physics.servo_rate_hz
        _, q_c, qd_c = servo_stream(plan, rate, command, lookahead=physics.servo_lookahead_s,
                                    servo=nominal, t_pause=t_pause, pause=pause)
        held = np.floor(np.maximum(t - physics.latency_s, 0.0) * rate + 1e-9).astype(int)
        held = np.minimum(held, len(q_c) - 1)  # after the stream: its last sample, at rest
        # The servo smooths the held stream (if it does), from what it held before the
        # plan: the plan's first state (at rest), not the first command, whose torque
        # compensation and lead the smoothing has yet to reach.
        tau = physics.servo_lookahead_s
        q_cmd = smoothed(q_c[held], dt, tau, start=q_des[0])
        qd_cmd = smoothed(qd_c[held], dt, tau, start=qd_des[0])
        # the smoothed velocity's rate: the low-pass's own derivative (x − y)/τ, exact
        qdd_cmd = ((qd_c[held] - qd_cmd) / tau if tau > 0
                   else np.gradient(qd_cmd, dt, axis=0))
    else:
        q_cmd, qd_cmd, qdd_cmd = q_des, qd_des, None
    return References(t, q_des, qd_des, u_ff, bounds, q_cmd, qd_cmd, qdd_cmd)


@dataclass(frozen=True)
class ArmController:
    """The joint controller of ``mode`` (module docstring) at ``substeps`` MuJoCo steps per
    control step.

    Attributes:
        robot: The arm; position mode's gravity compensation (or inverse dynamics) uses its
            model.
        mode: ``"feedforward"`` or ``"position"``. kp, kd: Joint gains (N·m/rad, N·m s/rad),
            scaled by ``physics.servo_gain_scale``. u_max: Torque limits (N·m).
        substeps: MuJoCo steps per control step. form: ``physics.servo_form``.
        bandwidth: The ``model_based`` servo's natural frequency (rad/s), scaled by
            √``servo_gain_scale`` (its stiffness by the scale).
    """

    robot: Robot
    mode: str
    kp: np.ndarray
    kd: np.ndarray
    u_max: np.ndarray
    substeps: int
    form: str = "pd_gravity"
    bandwidth: float = 30.0

    @classmethod
    def of(cls, robot: Robot, physics, mode: str, rate_hz: float, timestep: float
           ) -> "ArmController":
        """The controller at ``rate_hz`` (Hz) over a MuJoCo ``timestep`` (s)."""
        kp, kd = (np.asarray(g) * physics.servo_gain_scale for g in (physics.kp, physics.kd))
        return cls(robot, mode, kp, kd, robot.u_max,
                   max(1, int(round(1.0 / (rate_hz * timestep)))), physics.servo_form,
                   physics.servo_bandwidth * physics.servo_gain_scale ** 0.5)

    def torque(self, refs: References, k: int, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Joint torques (N·m) at sample k of ``refs`` from the measured q (rad), q̇ (rad/s):
        feed-forward mode's plan torque plus the PD; position mode's servo
        (``physics.servo_form``): the PD plus gravity, or the model's inverse dynamics at
        the commanded acceleration plus a critically damped correction at ``bandwidth``."""
        if self.mode != FEEDFORWARD and self.form == "model_based":
            w = self.bandwidth
            a = refs.qdd_cmd[k] + w * w * (refs.q_cmd[k] - q) + 2 * w * (refs.qd_cmd[k] - qd)
            u = pin.rnea(self.robot.model, self.robot.data, q, qd, a).copy()
            return np.minimum(np.maximum(u, -self.u_max, out=u), self.u_max, out=u)
        ff = refs.u_ff[k] if self.mode == FEEDFORWARD else pin.computeGeneralizedGravity(
            self.robot.model, self.robot.data, q)
        u = ff + self.kp * (refs.q_cmd[k] - q) + self.kd * (refs.qd_cmd[k] - qd)
        return np.minimum(np.maximum(u, -self.u_max, out=u), self.u_max, out=u)  # np.clip


def step_references(scene: Scene, control: ArmController, refs: References,
                    record: Callable, hook: Callable | None = None,
                    stop: Callable | None = None) -> tuple[References, int]:
    """Run the arm through ``refs`` on the scene as it is, one control step per sample.

    Each step k: ``hook(k, refs)`` may return new references (a replan) or change the scene;
    ``stop(k, refs)`` True ends the run before the step; then the torque from the current
    state, ``record(k, q, u)`` (the state before the step: q a view of the arm's qpos), the
    torque held over ``control.substeps`` MuJoCo steps.

    Returns:
        The references finally run and the number of control steps taken.
    """
    m, d = scene.model, scene.data
    k = -1
    while k + 1 < len(refs.t):
        k += 1
        if hook is not None:
            refs = hook(k, refs) or refs
        if stop is not None and stop(k, refs):
            return refs, k
        q, qd = d.qpos[:ARM_JOINTS], d.qvel[:ARM_JOINTS]
        u = control.torque(refs, k, q, qd)
        record(k, q, u)
        d.qfrc_applied[:ARM_JOINTS] = u
        mujoco.mj_step(m, d, nstep=control.substeps)
    return refs, len(refs.t)


__all__ = ["ArmController", "References", "desired", "pause_steps", "paused", "plan_references",
           "step_references"]
