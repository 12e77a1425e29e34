"""Resample a verified plan at a controller rate, check the stream as written, write it as CSV.

A controller only gets verified plans and verified streams: :func:`write_csv` runs
:func:`flipkit.planning.plans.verify.verify_plan` first, then makes the file's text, reads it
back (:mod:`~flipkit.planning.plans.stream_parse`) and checks it against the arm's published
limits (:func:`check_written`, :mod:`~flipkit.planning.plans.stream_check`); it writes nothing
if either fails (``--force`` waives the plan's *status*, never a check).

Within a segment the collocation fixes (q, q̇, q̈) at the nodes; between two consecutive
nodes q is the cubic Hermite interpolant of (q, q̇)
(:class:`scipy.interpolate.CubicHermiteSpline`), so a trajectory that is cubic in time —
which Hermite–Simpson collocation represents exactly — is reproduced exactly, and q̇ and q̈
are its derivatives: a stream's (q, q̇) are one C¹ trajectory, which a controller's spline
through them reproduces (a q̇ interpolated on its own disagrees with q's slope between nodes,
and a spline through both then swings), and the one :func:`flipkit.planning.plans.verify`
bounds. Segments are
concatenated on a global clock; a sample on a segment boundary is taken from the later
segment (both agree on a continuous plan). Samples are at t_j = j / rate, j = 0 ..
⌊T_total · rate⌋, at every node of the plan and at T_total, so that a stream ends where the
plan does, at rest; a t_j within :data:`MIN_GAP` of a period from a node is left out (the
node stands for it), so no two samples share a written time stamp. With the nodes among the samples, the cubic spline a controller lays
through the samples' (q, q̇) is the plan's own interpolant, which verify bounded: on the
rate's grid alone, a spline across a node where the plan's q̈ steps (a segment join) asks
for more acceleration than the plan does. :func:`evaluate` gives the same interpolant (and u,
linear between nodes) at any times; the URScript and ROS 2 writers
(:mod:`~flipkit.planning.plans.export_urscript`, :mod:`~flipkit.planning.plans.export_ros2`)
build on these.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from flipkit.errors import ConfigError, FlipkitError
from flipkit.planning.plans.plan_file import Plan
from flipkit.fileio import write_text
from flipkit.planning.plans.stream_check import StreamCheck, check_stream, require_stream
from flipkit.planning.plans.stream_parse import PARSERS
from flipkit.planning.plans.verify import TOL, require_verified

MAX_ROWS = 10_000_000  # refuse absurd rates rather than fill the disk
RATE_RANGE = (1.0, 10_000.0)  # Hz: rates a plan is resampled at
STREAM_RATES = {"csv": (100.0, 1000.0), "ros2": (100.0, 1000.0)}
"""Hz: the rates each sampled format is written at, a controller's (ros2_control and UR's
own run between 125 and 500 Hz); URScript's are its servo periods
(:data:`flipkit.planning.plans.export_urscript.SERVO_RATES`)."""
_EPS = 1e-9  # s, slack on the last sample time (floating-point T_total · rate)
MIN_GAP = 0.25  # periods: the least spacing of a grid sample from a plan node (resample)


def _check_rate(rate) -> float:
    try:
        rate = float(rate)
    except (TypeError, ValueError):
        raise FlipkitError(f"export rate must be a number (Hz), got {rate!r}") from None
    lo, hi = RATE_RANGE
    if not (math.isfinite(rate) and lo <= rate <= hi):
        raise FlipkitError(f"export rate must be in [{lo:g}, {hi:g}] Hz, got {rate!r}")
    return rate


def resample(plan: Plan, rate: float, *, force: bool = False):
    """Joint positions and velocities of ``plan`` sampled at ``rate``.

    Args:
        plan: The plan. rate: Controller rate (Hz, positive, finite).
        force: Resample even a plan whose status is not ``solved``.

    Returns:
        (t, q, qd): times (n,) (s: the rate's grid, the plan's nodes and its end, module
        docstring), positions (n, nq) (rad), velocities (n, nq) (rad/s).

    Raises:
        FlipkitError: Bad rate, too many rows, or an unsolved plan without ``force``.
    """
    rate = _check_rate(rate)
    if plan.status != "solved" and not force:
        raise FlipkitError(f"plan status is {plan.status!r}, not 'solved'; "
                           "use --force to export it anyway")
    total = float(np.array([s.T for s in plan.segments]).sum())
    n = int(math.floor(total * rate + _EPS * rate)) + 1
    if n < 2:
        raise FlipkitError(f"export at {rate:g} Hz gives {n} row over the plan's {total:.3f} s; "
                           f"give a rate of at least {math.ceil(1 / total):g} Hz for two rows")
    if n > MAX_ROWS:
        raise FlipkitError(f"export would write {n} rows ({total:.3f} s at {rate:g} Hz); "
                           f"the limit is {MAX_ROWS}")
    t = np.arange(n) / rate
    starts = np.concatenate([[0.0], np.cumsum([s.T for s in plan.segments])[:-1]])
    knots = np.concatenate([start + seg.t - seg.t[0] for start, seg in zip(starts,
                                                                           plan.segments)])
    knots = np.unique(np.concatenate([np.minimum(knots, total), [total]]))
    knots = knots[np.concatenate([[True], np.diff(knots) > _EPS])]  # a join counts once
    # A grid time within MIN_GAP periods of a node gives way to the node: two samples a few
    # nanoseconds apart (a node just off the grid) are one time stamp once written, and a
    # spline through them asks for unbounded acceleration.
    k = np.clip(np.searchsorted(knots, t), 1, len(knots) - 1)  # the nodes either side
    gap = np.minimum(np.abs(t - knots[k - 1]), np.abs(knots[k] - t))
    t = np.union1d(t[gap >= MIN_GAP / rate], knots)
    q, qd, _ = evaluate(plan, t)
    return t, q, qd


def check_rate(fmt: str, rate) -> float:
    """``rate`` (Hz) if the format ``fmt`` takes it (:data:`STREAM_RATES`), else ConfigError:
    a rate outside them is refused before any work."""
    rate = _check_rate(rate)
    lo, hi = STREAM_RATES[fmt]
    if not lo <= rate <= hi:
        raise ConfigError(f"{fmt} rate must be in [{lo:g}, {hi:g}] Hz (a controller's rate), "
                          f"got {rate:g}")
    return rate


def check_written(plan: Plan, fmt: str, text: str, where: str, robot=None) -> StreamCheck:
    """The stream of an export's ``text`` (format ``fmt``) read back and checked against the
    plan and the arm's published limits (:func:`~flipkit.planning.plans.stream_check.
    check_stream`).

    Raises:
        ExportError: A check fails (the message names the joint, the time and the amount).
    """
    stream = PARSERS[fmt](text)
    report = check_stream(plan, stream.t, stream.q, stream.qd,
                          interpolation=stream.interpolation, q_start=stream.q_start,
                          robot=robot, evaluate=evaluate)
    return require_stream(report, where)


def evaluate(plan: Plan, t, accelerations: bool = False):
    """The plan's interpolant at times ``t`` (s, from the plan's start).

    q is the cubic Hermite of (q, q̇) and q̇ its derivative (module docstring), u (N·m) is
    linear between nodes (as the simulation's feed-forward). A time outside [0, T_total] takes the first or last node's values.

    Args:
        plan: The plan. t: Times (n,) (s), any order.
        accelerations: Also return q̈ (n, nq) (rad/s²), q's second derivative.

    Returns:
        (q, qd, u): positions (n, nq) (rad), velocities (n, nq) (rad/s), torques (n, nq) (N·m);
        (q, qd, u, qdd) with ``accelerations``.
    """
    t = np.asarray(t, float)
    durations = np.array([s.T for s in plan.segments])
    starts = np.concatenate([[0.0], np.cumsum(durations)[:-1]])
    which = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(durations) - 1)
    nq = plan.segments[0].q.shape[1]
    q, qd, u = np.empty((t.size, nq)), np.empty((t.size, nq)), np.empty((t.size, nq))
    qdd = np.empty((t.size, nq))
    for k, seg in enumerate(plan.segments):
        rows = which == k
        if not rows.any():
            continue
        local = np.clip(t[rows] - starts[k], 0.0, seg.T)
        spline = CubicHermiteSpline(seg.t, seg.q, seg.qd, axis=0)
        q[rows], qd[rows] = spline(local), spline(local, 1)
        if accelerations:
            qdd[rows] = spline(local, 2)
        u[rows] = np.column_stack([np.interp(local, seg.t, seg.u[:, j]) for j in range(nq)])
    return (q, qd, u, qdd) if accelerations else (q, qd, u)


def write_csv(plan: Plan, path, rate: float, *, force: bool = False, tol: float = TOL,
              where=None, on_check=None) -> int:
    """Verify ``plan``, then write ``t,q1..qn,qd1..qdn`` (s, rad, rad/s) at ``rate`` to
    ``path``; return the row count.

    Values are written with 17 significant digits (round-trip exact).

    Args:
        plan: The plan. path: Output CSV. rate: Controller rate (Hz).
        force: Export even a plan whose status is not ``solved`` (it must still verify).
        tol: Verification tolerance (scaled units, :data:`flipkit.planning.plans.verify.TOL`).
        on_check: Called with the stream's check
            (:class:`~flipkit.planning.plans.stream_check.StreamCheck`) once it passed.
        where: How messages name the plan (its file); default ``"plan"``.

    Raises:
        VerificationError: The plan is not solved (without ``force``) or fails the
            independent check (the message names the worst
            check group, its segment and amount); nothing is written.
        ExportError: The stream as written fails its check (:func:`check_written`); nothing
            is written.
        FlipkitError: As :func:`resample`, a rate outside :data:`STREAM_RATES`, or the file
            cannot be written.
    """
    where = "plan" if where is None else str(where)
    t, q, qd = resample(plan, check_rate("csv", rate), force=force)
    require_verified(plan, where, force=force, tol=tol)
    nq = q.shape[1]
    header = ",".join(["t"] + [f"q{j + 1}" for j in range(nq)] + [f"qd{j + 1}" for j in range(nq)])
    buffer = io.StringIO()
    np.savetxt(buffer, np.column_stack([t, q, qd]), delimiter=",", header=header, comments="",
               fmt="%.17g")
    text = buffer.getvalue()
    checked = check_written(plan, "csv", text, where)
    if on_check is not None:
        on_check(checked)
    write_text(Path(path), text)
    return t.size
