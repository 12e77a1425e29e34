"""Resample a verified plan at a controller rate and write it as CSV.

A controller only gets verified plans: :func:`write_csv` runs
:func:`flipkit.planning.plans.verify.verify_plan` first and writes nothing if the plan fails it
(``--force`` waives the plan's *status*, never the verification).

Within a segment the collocation fixes (q, q̇, q̈) at the nodes; between two consecutive
nodes q is the cubic Hermite interpolant of (q, q̇) and q̇ that of (q̇, q̈)
(:class:`scipy.interpolate.CubicHermiteSpline`), so a trajectory that is cubic in time —
which Hermite–Simpson collocation represents exactly — is reproduced exactly. Segments are
concatenated on a global clock; a sample on a segment boundary is taken from the later
segment (both agree on a continuous plan). Samples are at t_j = j / rate, j = 0 ..
⌊T_total · rate⌋; the last one is at most 1/rate before the end. :func:`evaluate` gives the
same interpolant (and u, linear between nodes) at any times; the URScript and ROS 2 writers
(:mod:`~flipkit.planning.plans.export_urscript`, :mod:`~flipkit.planning.plans.export_ros2`)
build on these two.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from flipkit.errors import FlipkitError
from flipkit.planning.plans.plan_file import Plan
from flipkit.fileio import replace_with
from flipkit.planning.plans.verify import TOL, require_verified

MAX_ROWS = 10_000_000  # refuse absurd rates rather than fill the disk
RATE_RANGE = (1.0, 10_000.0)  # Hz: controller rates accepted
_EPS = 1e-9  # s, slack on the last sample time (floating-point T_total · rate)


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
        (t, q, qd): times (n,) (s), positions (n, nq) (rad), velocities (n, nq) (rad/s).

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
    q, qd, _ = evaluate(plan, t)
    return t, q, qd


def evaluate(plan: Plan, t, accelerations: bool = False):
    """The plan's interpolant at times ``t`` (s, from the plan's start).

    q and q̇ are as in :func:`resample`, u (N·m) is linear between nodes (as the simulation's
    feed-forward). A time outside [0, T_total] takes the first or last node's values.

    Args:
        plan: The plan. t: Times (n,) (s), any order.
        accelerations: Also return q̈ (n, nq) (rad/s²), the derivative of q̇'s interpolant.

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
        q[rows] = CubicHermiteSpline(seg.t, seg.q, seg.qd, axis=0)(local)
        rate = CubicHermiteSpline(seg.t, seg.qd, seg.qdd, axis=0)
        qd[rows] = rate(local)
        if accelerations:
            qdd[rows] = rate(local, 1)
        u[rows] = np.column_stack([np.interp(local, seg.t, seg.u[:, j]) for j in range(nq)])
    return (q, qd, u, qdd) if accelerations else (q, qd, u)


def write_csv(plan: Plan, path, rate: float, *, force: bool = False, tol: float = TOL,
              where=None) -> int:
    """Verify ``plan``, then write ``t,q1..qn,qd1..qdn`` (s, rad, rad/s) at ``rate`` to
    ``path``; return the row count.

    Values are written with 17 significant digits (round-trip exact).

    Args:
        plan: The plan. path: Output CSV. rate: Controller rate (Hz).
        force: Export even a plan whose status is not ``solved`` (it must still verify).
        tol: Verification tolerance (scaled units, :data:`flipkit.planning.plans.verify.TOL`).
        where: How messages name the plan (its file); default ``"plan"``.

    Raises:
        VerificationError: The plan is not solved (without ``force``) or fails the
            independent check (the message names the worst
            check group, its segment and amount); nothing is written.
        FlipkitError: As :func:`resample`, or the file cannot be written.
    """
    t, q, qd = resample(plan, rate, force=force)
    require_verified(plan, "plan" if where is None else where, force=force, tol=tol)
    nq = q.shape[1]
    header = ",".join(["t"] + [f"q{j + 1}" for j in range(nq)] + [f"qd{j + 1}" for j in range(nq)])
    replace_with(Path(path), lambda tmp: np.savetxt(tmp, np.column_stack([t, q, qd]),
                                                    delimiter=",", header=header, comments="",
                                                    fmt="%.17g"))
    return t.size
