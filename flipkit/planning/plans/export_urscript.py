"""Write a verified plan as a URScript program that streams it with ``servoj``.

The program (``def flipkit_<behavior>(): ... end``) first checks that the arm is at the plan's
first configuration — every joint of ``get_actual_joint_positions()`` within
``start_tol`` of it — and otherwise shows a ``popup`` and stops (``halt``) before any motion.
Then it sends one ``servoj(q, 0, 0, t, lookahead_time, gain)`` per sample of
:func:`servo_stream`, t = 1 / rate (``servoj`` blocks for t, so the samples play at the
rate), and ends with ``stopj``. URScript manual (servoj): ``a`` and ``v`` are not used,
``lookahead_time`` in [0.03, 0.2] s (default 0.1), ``gain`` in [100, 2000] (default 300);
t = 0.008 s on a CB3 (125 Hz), 0.002 s on an e-Series (500 Hz).

The positions streamed are, by default, the plan's own q at t_j = j / rate (``raw``, the
paper's footnote 2), ending with the plan's final configuration held for two samples (at
rest). ``command="compensated"`` streams the command of
:mod:`flipkit.planning.plans.servo_command` instead, for flipkit's *modelled* servo (its Kp
and latency are not identified on a real arm). Either way the program is read back from its
text and its stream checked against the arm's published limits before it is written
(:mod:`flipkit.planning.plans.stream_check`): the compensated stream's torque steps at the
segments' joins ask a UR10 for more than its joint speeds, and it is refused there.
The simulation's position mode sends the same stream (:func:`servo_stream`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from flipkit.config.physics import SERVOJ_LOOKAHEAD, SERVOJ_LOOKAHEAD_DEFAULT
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.fileio import write_text
from flipkit.model.robot import Robot
from flipkit.planning.plans.export import check_written, evaluate
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.servo_command import (COMMANDS, DEFAULT_COMMAND, command_lead,
                                                  hold_torque, paused, servo_commands)
from flipkit.planning.plans.verify import TOL, require_verified

LOOKAHEAD_RANGE = SERVOJ_LOOKAHEAD  # s, servoj lookahead_time (URScript manual)
GAIN_RANGE = (100.0, 2000.0)  # servoj gain, proportional (URScript manual)
START_TOL_RANGE = (1e-4, 0.1)  # rad, the start guard's tolerance per joint
SERVO_RATES = (125.0, 250.0, 500.0)  # Hz: servoj t of 8 ms (a CB3's cycle), 4 ms, 2 ms (e-Series)
DECIMALS = 8  # joint angles printed to 1e-8 rad
STOP_ACCEL = 2.0  # rad/s², stopj after the stream (the plan ends at rest)


@dataclass(frozen=True)
class ServoOptions:
    """How the program streams the plan.

    Attributes:
        lookahead: ``servoj`` lookahead_time (s), in :data:`LOOKAHEAD_RANGE`; default 0.1.
        gain: ``servoj`` gain, in :data:`GAIN_RANGE`; default 300.
        command: One of :data:`~flipkit.planning.plans.servo_command.COMMANDS`; default
            :data:`~flipkit.planning.plans.servo_command.DEFAULT_COMMAND` (``"raw"``).
        start_tol: The start guard's tolerance per joint (rad), in :data:`START_TOL_RANGE`.
    """

    lookahead: float = SERVOJ_LOOKAHEAD_DEFAULT
    gain: float = 300.0
    command: str = DEFAULT_COMMAND
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
    """``rate`` (Hz) if it is one of :data:`SERVO_RATES`, else ConfigError."""
    try:
        rate = float(rate)
    except (TypeError, ValueError):
        rate = math.nan
    if not any(abs(rate - r) < 1e-9 for r in SERVO_RATES):
        raise ConfigError(f"urscript rate must be one of {', '.join(f'{r:g}' for r in SERVO_RATES)}"
                          f" Hz (servoj t a whole number of controller cycles: 8 ms on a CB3, "
                          f"2 ms on an e-Series), got {rate!r}")
    return rate


def stream_times(total: float, rate: float) -> np.ndarray:
    """The send times (s) of a servoj stream of ``total`` s: t_j = j / rate, j = 0 ..
    ⌈total · rate⌉ + 1. Samples past the plan's end hold its final configuration, and the
    last two are equal, so the stream ends at rest."""
    n = int(math.ceil(total * rate - 1e-9))
    return np.arange(n + 2) / rate


def servo_stream(plan: Plan, rate: float, command: str = DEFAULT_COMMAND, *,
                 lookahead: float = SERVOJ_LOOKAHEAD_DEFAULT, servo=None,
                 t_pause: float = math.inf, pause: float = 0.0, force=False):
    """The servoj stream of ``plan``: send times t (n,) (s, :func:`stream_times`), position
    commands (n, 6) (rad) and the velocities the servo is given with them (n, 6) (rad/s).

    This is the one place a stream is made: the export writes it and the simulation's
    position mode sends it (:func:`flipkit.simulation.control.plan_references`).
    ``compensated`` commands are made as :func:`~flipkit.planning.plans.servo_command.
    servo_commands` makes them, for the servo model ``servo`` (default the plan's nominal
    one at this rate) and, with ``lookahead`` (s) > 0, for servoj's smoothing with that
    lookahead; ``raw`` ones are the plan's (q, q̇) at the send times.

    Args:
        t_pause, pause: The plan stops at run time ``t_pause`` for ``pause`` s (the arm held
            while a re-plan runs); the stream is then ``pause`` s longer.
    """
    if command not in COMMANDS:
        raise InvalidChoiceError("position command", command, COMMANDS)
    if plan.status != "solved" and not force:
        raise ConfigError(f"plan status is {plan.status!r}, not 'solved'; use --force to "
                          "export it anyway")
    cell = plan.cell()
    # the servo model at this rate (an export), or the one a cell gives (its own rate)
    nominal = (replace(cell.physics, servo_rate_hz=rate) if servo is None else servo)
    nominal = replace(nominal, servo_lookahead_s=float(lookahead))
    t = stream_times(plan.duration + pause, rate)
    lead = command_lead(nominal) if command == "compensated" else 0.0
    at = np.minimum(paused(t + lead, t_pause, pause), plan.duration)  # plan times they act at
    q_d, qd_d, u_d, qdd_d = evaluate(plan, at, accelerations=True)
    past = at >= plan.duration - 1e-12  # after the plan: at rest, held against gravity
    qd_d[past], qdd_d[past] = 0.0, 0.0
    model = None
    if command == "compensated":  # the torques and the controller's model enter its offset
        model = Robot(cell, with_burger=False).model  # the controller's: arm and spatula
        if past.any():
            u_d[past] = hold_torque(plan)
    q_c, qd_c = servo_commands(plan, t, at, q_d, qd_d, u_d, qdd_d, model, nominal, command)
    return t, q_c, qd_c


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
                   force: bool = False, tol: float = TOL, where=None, on_check=None) -> int:
    """Verify ``plan``, make its URScript program, read the program back and check its stream
    (:func:`~flipkit.planning.plans.export.check_written`), then write it to ``path``; return
    the sample count.

    Args:
        plan: The plan. path: Output file. rate: Controller rate (Hz), one of
            :data:`SERVO_RATES`.
        options: :class:`ServoOptions`.
        force: Export even a plan whose status is not ``solved`` (it must still verify).
        tol: Verification tolerance (:data:`flipkit.planning.plans.verify.TOL`).
        on_check: Called with the stream's check
            (:class:`~flipkit.planning.plans.stream_check.StreamCheck`) once it passed.
        where: How messages and the program's header name the plan; default ``"plan"``.

    Raises:
        VerificationError: The plan fails verification; nothing is written.
        ExportError: The program's stream fails its check (a joint over the arm's published
            speed, a jump, a start or end off the plan's, the blade off the plan); nothing is
            written.
        FlipkitError: A bad rate or option, or the file cannot be written.
    """
    where = "plan" if where is None else str(where)
    t, q_cmd, _ = servo_stream(plan, check_servo_rate(rate), options.command,
                               lookahead=options.lookahead, force=force)
    require_verified(plan, where, force=force, tol=tol)
    text = urscript_text(plan, t, q_cmd, rate, options, Path(where).name)
    checked = check_written(plan, "urscript", text, where)
    if on_check is not None:
        on_check(checked)
    write_text(Path(path), text)
    return t.size
