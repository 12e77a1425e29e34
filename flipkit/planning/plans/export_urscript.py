"""Write a verified plan as a URScript program that streams it with ``servoj``.

The program (``def flipkit_<behavior>(): ... end``) first checks that the arm is at the plan's
first configuration — every joint of ``get_actual_joint_positions()`` within
``start_tol`` of it — and otherwise shows a ``popup`` and stops (``halt``) before any motion.
Then it sends one ``servoj(q, 0, 0, t, lookahead_time, gain)`` per sample of
:func:`flipkit.planning.plans.export.resample`, t = 1 / rate (``servoj`` blocks for t, so the
samples play at the rate), and ends with ``stopj``. URScript manual (servoj): ``a`` and ``v``
are not used, ``lookahead_time`` in [0.03, 0.2] s (default 0.1), ``gain`` in [100, 2000]
(default 300); t = 0.008 s on a CB3 (125 Hz), 0.002 s on an e-Series (500 Hz).

The positions streamed are, as in the simulation's position mode
(:mod:`flipkit.simulation.execute`), the compensated command of
:mod:`flipkit.planning.plans.servo_command` (default): the plan a transport latency plus half
a servo period ahead, offset by Kp⁻¹ (u − g_c(q)) of flipkit's *modelled* servo (its Kp and
latency, :class:`flipkit.config.PhysicsConfig`, are not identified on a real arm), and made
for the smoothing of the ``lookahead_time`` sent (the inverse of the servo model's low-pass,
:func:`~flipkit.planning.plans.servo_command.lookahead_command`); or, with
``command="raw"``, the resampled q as it is. Either way every command lies within the
model's joint limits, or nothing is written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from flipkit.config.physics import SERVOJ_LOOKAHEAD, SERVOJ_LOOKAHEAD_DEFAULT
from flipkit.errors import ConfigError, ExportError, InvalidChoiceError
from flipkit.fileio import write_text
from flipkit.model.robot import Robot
from flipkit.planning.plans.export import evaluate, resample
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.servo_command import COMMANDS, command_lead, servo_commands
from flipkit.planning.plans.verify import TOL, require_verified

LOOKAHEAD_RANGE = SERVOJ_LOOKAHEAD  # s, servoj lookahead_time (URScript manual)
GAIN_RANGE = (100.0, 2000.0)  # servoj gain, proportional (URScript manual)
START_TOL_RANGE = (1e-4, 0.1)  # rad, the start guard's tolerance per joint
CYCLE_HZ = 500.0  # Hz: an e-Series controller cycle (2 ms); t must be whole cycles
DECIMALS = 8  # joint angles printed to 1e-8 rad
STOP_ACCEL = 2.0  # rad/s², stopj after the stream (the plan ends at rest)


@dataclass(frozen=True)
class ServoOptions:
    """How the program streams the plan.

    Attributes:
        lookahead: ``servoj`` lookahead_time (s), in :data:`LOOKAHEAD_RANGE`; default 0.1.
        gain: ``servoj`` gain, in :data:`GAIN_RANGE`; default 300.
        command: One of :data:`~flipkit.planning.plans.servo_command.COMMANDS`; default
            ``"compensated"`` (the simulation's position mode).
        start_tol: The start guard's tolerance per joint (rad), in :data:`START_TOL_RANGE`.
    """

    lookahead: float = SERVOJ_LOOKAHEAD_DEFAULT
    gain: float = 300.0
    command: str = "compensated"
    start_tol: float = 0.01

    def __post_init__(self):
        for name, (lo, hi), unit in (("lookahead", LOOKAHEAD_RANGE, " s"),
                                     ("gain", GAIN_RANGE, ""),
                                     ("start_tol", START_TOL_RANGE, " rad")):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise ConfigError(f"servoj {name} must be a number in [{lo:g}, {hi:g}]{unit}, "
                                  f"got {value!r}")
        if self.command not in COMMANDS:
            raise InvalidChoiceError("position command", self.command, COMMANDS)


def check_servo_rate(rate: float) -> float:
    """``rate`` (Hz) if t = 1/rate is a whole number of 2 ms controller cycles (500, 250,
    125, ... Hz), else ConfigError."""
    k = CYCLE_HZ / rate if rate > 0 else math.inf
    if not (math.isfinite(k) and k >= 1 - 1e-9 and abs(k - round(k)) < 1e-9):
        raise ConfigError(f"urscript rate must be 500/k Hz (servoj t a whole number of 2 ms "
                          f"cycles: 500, 250, 125, ...), got {rate!r}")
    return float(rate)


def servo_stream(plan: Plan, rate: float, command: str = "compensated", *,
                 lookahead: float = SERVOJ_LOOKAHEAD_DEFAULT, force=False):
    """The samples' times t (n,) (s, t_j = j / rate) and position commands (n, 6) (rad).

    ``compensated`` commands are made as the simulation's position mode makes them
    (:func:`flipkit.simulation.control.plan_references`): for the servo model at this rate
    and, with ``lookahead`` (s) > 0, for servoj's smoothing with that lookahead
    (:func:`~flipkit.planning.plans.servo_command.lookahead_command`)."""
    if command not in COMMANDS:
        raise InvalidChoiceError("position command", command, COMMANDS)
    t, q, _ = resample(plan, check_servo_rate(rate), force=force)
    if command == "raw":
        return t, q
    cell = plan.cell()
    nominal = replace(cell.physics, servo_rate_hz=rate,  # the servo model, at this rate
                      servo_lookahead_s=float(lookahead))
    at = t + command_lead(nominal)  # plan times the samples act at
    q_d, qd_d, u_d, qdd_d = evaluate(plan, at, accelerations=True)
    model = Robot(cell, with_burger=False).model  # the controller's: arm and spatula
    return t, servo_commands(plan, t, at, q_d, qd_d, u_d, qdd_d, model, nominal, command)[0]


def check_limits(plan: Plan, t, q) -> None:
    """ExportError naming the first command (time, joint, value) outside the joint limits."""
    robot = Robot(plan.cell(), with_burger=False)
    bad = np.argwhere((q < robot.q_min) | (q > robot.q_max))
    if bad.size:
        i, j = bad[0]
        raise ExportError(f"servoj command at t = {t[i]:.3f} s puts q{j + 1} at {q[i, j]:.4f} "
                          f"rad, outside [{robot.q_min[j]:.4f}, {robot.q_max[j]:.4f}]")


def _vector(q) -> str:
    return "[" + ", ".join(f"{x:.{DECIMALS}f}" for x in q) + "]"


def urscript_text(plan: Plan, t, q_cmd, rate: float, options: ServoOptions, where: str) -> str:
    """The program streaming ``q_cmd`` (n, 6) (rad) every 1/rate s."""
    period = f"{1.0 / rate:.6g}"
    q0 = plan.segments[0].q[0]
    made = plan.created_by
    tail = f"{options.lookahead:g}, {options.gain:g})"
    lines = [
        f"# flipkit export --format urscript: {where}, a {plan.behavior} plan of "
        f"{len(plan.segments)} segments, {plan.duration:.3f} s",
        f"# planned by flipkit {made['flipkit']} (git {made['git']}); passed flipkit verify "
        "before this was written",
        f"# {t.size} servoj samples at {rate:g} Hz (t = {period} s), lookahead_time "
        f"{options.lookahead:g} s, gain {options.gain:g}, command {options.command}",
        "# joint angles in rad, base to wrist 3; not run on a robot by flipkit",
        f"def flipkit_{plan.behavior}():",
        f"  q_start = {_vector(q0)}",
        "  q_now = get_actual_joint_positions()",
        "  j = 0",
        "  while j < 6:",
        f"    if norm(q_now[j] - q_start[j]) > {options.start_tol:g}:",
        f"      popup(\"flipkit: the arm is not at the plan's first configuration (tolerance "
        f"{options.start_tol:g} rad per joint); nothing was moved\", title=\"flipkit\", "
        "error=True)",
        "      halt",
        "    end",
        "    j = j + 1",
        "  end",
        f"  textmsg(\"flipkit: streaming {t.size} servoj samples at {rate:g} Hz\")",
    ]
    lines += [f"  servoj({_vector(q)}, 0, 0, {period}, {tail}" for q in q_cmd]
    lines += [f"  stopj({STOP_ACCEL:g})", "end", ""]
    return "\n".join(lines)


def write_urscript(plan: Plan, path, rate: float, options: ServoOptions = ServoOptions(), *,
                   force: bool = False, tol: float = TOL, where=None) -> int:
    """Verify ``plan``, then write its URScript program to ``path``; return the sample count.

    Args:
        plan: The plan. path: Output file. rate: Controller rate (Hz), 500/k.
        options: :class:`ServoOptions`.
        force: Export even a plan whose status is not ``solved`` (it must still verify).
        tol: Verification tolerance (:data:`flipkit.planning.plans.verify.TOL`).
        where: How messages and the program's header name the plan; default ``"plan"``.

    Raises:
        VerificationError: The plan fails verification; nothing is written.
        ExportError: A command outside the joint limits; nothing is written.
        FlipkitError: A bad rate or option, or the file cannot be written.
    """
    where = "plan" if where is None else str(where)
    t, q_cmd = servo_stream(plan, rate, options.command, lookahead=options.lookahead,
                            force=force)
    require_verified(plan, where, force=force, tol=tol)
    check_limits(plan, t, q_cmd)
    write_text(Path(path), urscript_text(plan, t, q_cmd, rate, options, Path(where).name))
    return t.size
