"""A command stream checked as written, sample by sample, against the arm's published limits.

An export is parsed back from its own text (:mod:`~flipkit.planning.plans.stream_parse`) and
checked here before the file is written; the simulation's position mode runs the same array.
How a controller moves between the samples decides what the arm is asked for:

* ``hold`` (URScript ``servoj``): each target is reached over one period 1/rate, so the arm's
  speed is the difference of consecutive targets over the period and its acceleration the
  difference of those speeds;
* ``cubic`` (ROS 2 JointTrajectory with positions and velocities, as ``joint_trajectory_
  controller`` splines them, and the CSV's t, q, q̇): the cubic Hermite between consecutive
  samples, whose speed peaks at an interval's end or its parabola's vertex.

The checks (:func:`check_stream`), each naming the joint, the time and the amount:

* ``position``: every sample within the arm's joint range (profile and URDF);
* ``speed``: within the profile's published joint speed (``Robot.qd_limit``);
* ``acceleration``: UR publishes no joint acceleration limit (:mod:`flipkit.config.arm`), so
  the stream may ask no joint for more than the verified plan's own peak acceleration on
  that joint times :data:`ACCEL_SLACK` (plus :data:`ACCEL_FLOOR`): what the plan was
  verified with, not a step the plan never took;
* ``start``: the first sample is the plan's first configuration (and the URScript guard's
  ``q_start``), to :data:`EQUAL_TOL`;
* ``end``: the last sample is the plan's final configuration, at rest;
* ``deviation``: the blade's centre and corners stay within :data:`DEVIATION_M` of where the
  verified plan has them, at the samples and between them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from flipkit.errors import ExportError
from flipkit.planning.plans.hermite import hermite_extremes
from flipkit.model.robot import Robot

DEVIATION_M = 0.002  # m, the blade's distance from the verified plan
EQUAL_TOL = 1e-7  # rad: the start and end equalities (URScript prints 1e-8 rad)
REST_TOL = 1e-6  # rad/s: the stream's last speed, at rest
ACCEL_SLACK = 1.10  # the stream's accelerations over the verified plan's peak, at most
ACCEL_FLOOR = 1.0  # rad/s², added to the peak: the rounding of a sampled acceleration
INTERPOLATIONS = ("hold", "cubic")
_CORNERS = ((0.0, 0.0), (1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0))  # centre, corners


@dataclass
class StreamCheck:
    """What a stream asks of the arm, and the first failed check.

    Attributes:
        interpolation: ``hold`` or ``cubic``. samples: How many. speed_ratio: The largest
            joint speed over the published limit. accel_ratio: The largest acceleration over
            its bound (module docstring). deviation_m: The blade's largest distance from the
            verified plan (m). failures: One line per failed check, the worst first of each.
    """

    interpolation: str
    samples: int
    speed_ratio: float = 0.0
    accel_ratio: float = 0.0
    deviation_m: float = 0.0
    failures: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.failures

    def summary(self) -> str:
        return (f"{self.samples} samples ({self.interpolation}): joint speed at most "
                f"{self.speed_ratio:.3f} of the published limit, acceleration "
                f"{self.accel_ratio:.3f} of its bound, blade within "
                f"{1e3 * self.deviation_m:.3f} mm of the verified plan")


def _worst(ratio: np.ndarray):
    """(value, row, joint) of the largest entry of ``ratio`` (rows × joints)."""
    i, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    return float(ratio[i, j]), int(i), int(j)


def plan_peak_accel(plan) -> np.ndarray:
    """The verified plan's largest |q̈| on each joint (rad/s²), over its interpolant (linear
    between nodes: its extremes at the intervals' ends, :func:`hermite_extremes`)."""
    peak = np.zeros(plan.segments[0].q.shape[1])
    for seg in plan.segments:
        for qdd in hermite_extremes(seg.t, seg.q, seg.qd)[:2]:
            peak = np.maximum(peak, np.abs(qdd).max(axis=0))
    return peak


def blade_points(robot: Robot, q: np.ndarray) -> np.ndarray:
    """The blade's centre and four corners (world, m) at each row of ``q``: (n, 5, 3)."""
    half = np.array([robot.cell.spatula.length / 2, robot.cell.spatula.width / 2])
    local = np.array([[a * half[0], b * half[1], 0.0] for a, b in _CORNERS])
    out = np.empty((len(q), len(local), 3))
    for i, qi in enumerate(q):
        M = robot.placement(qi)
        out[i] = M.translation + local @ M.rotation.T
    return out


def _time_of(row: int, t: np.ndarray, interpolation: str, offset: int = 0) -> float:
    """The time (s) of row ``row`` of :func:`_motion`'s speeds (``offset`` 0) or
    accelerations (``offset`` 1): a hold's rows are its intervals, a cubic's its samples and
    then its intervals."""
    if interpolation == "hold":
        return float(t[min(row + offset, len(t) - 1)])
    n = len(t) - 1 + (offset == 0)  # cubic: n samples (speeds) or n − 1 interval starts
    return float(t[row] if row < n else t[min(row - n + offset, len(t) - 1)])


def _motion(interpolation: str, t, q, qd):
    """Speeds (rows × joints), accelerations, and the times and positions between samples
    that the controller passes through."""
    dt = np.diff(t)[:, None]
    if interpolation == "hold":
        v = np.diff(q, axis=0) / dt
        a = np.diff(v, axis=0) / dt[1:]
        return v, a, t[:-1] + dt[:, 0] / 2, (q[:-1] + q[1:]) / 2
    start, end, vertex = hermite_extremes(t, q, qd)
    mid = t[:-1] + dt[:, 0] / 2
    return (np.concatenate([qd, vertex]), np.concatenate([start, end]), mid,
            CubicHermiteSpline(t, q, qd, axis=0)(mid))


def check_stream(plan, t, q, qd=None, *, interpolation: str = "hold", q_start=None,
                 robot: Robot | None = None, evaluate=None) -> StreamCheck:
    """Check the stream ``(t, q[, q̇])`` as written for ``plan`` (module docstring).

    Args:
        plan: The verified plan the stream was made from.
        t: Sample times (s, n, increasing, from the plan's start). q: Positions (n×6, rad).
        qd: Velocities (n×6, rad/s), for ``cubic``.
        interpolation: ``hold`` or ``cubic``.
        q_start: The configuration a start guard checks (URScript), if any.
        robot: The arm (its profile's limits); default built from the plan's cell.
        evaluate: ``evaluate(plan, t) -> (q, qd, u)``, the plan's interpolant
            (:func:`flipkit.planning.plans.export.evaluate`).

    Returns:
        The :class:`StreamCheck`; ``failures`` empty when every check passes.
    """
    if interpolation not in INTERPOLATIONS:
        raise ExportError(f"unknown interpolation {interpolation!r}; valid: "
                          f"{', '.join(INTERPOLATIONS)}")
    t, q = np.asarray(t, float), np.asarray(q, float)
    robot = robot or Robot(plan.cell(), with_burger=False)
    names = robot.profile.joints
    report = StreamCheck(interpolation, len(t))
    fail = report.failures.append
    if len(t) < 2 or np.any(np.diff(t) <= 0) or q.shape != (len(t), robot.nq):
        fail(f"the stream's times must increase over at least two samples of {robot.nq} "
             "joints")
        return report
    qd = None if qd is None else np.asarray(qd, float)
    if interpolation == "cubic" and (qd is None or qd.shape != q.shape):
        fail("a cubic stream needs a velocity per position")
        return report

    low, high = q < robot.q_min - 1e-12, q > robot.q_max + 1e-12
    if low.any() or high.any():
        i, j = np.argwhere(low | high)[0]
        fail(f"position: {names[j]} at {q[i, j]:.4f} rad at t = {t[i]:.3f} s, outside "
             f"[{robot.q_min[j]:.4f}, {robot.q_max[j]:.4f}]")

    v, a, t_mid, q_mid = _motion(interpolation, t, q, qd)
    report.speed_ratio, i, j = _worst(np.abs(v) / robot.qd_limit)
    if report.speed_ratio > 1.0:
        fail(f"speed: {names[j]} at {abs(v[i, j]):.3f} rad/s near t = "
             f"{_time_of(i, t, interpolation):.3f} s, "
             f"{report.speed_ratio:.2f}x the {robot.profile.model}'s {robot.qd_limit[j]:.3f}")
    bound = ACCEL_SLACK * plan_peak_accel(plan) + ACCEL_FLOOR
    if len(a):
        report.accel_ratio, i, j = _worst(np.abs(a) / bound)
        if report.accel_ratio > 1.0:
            fail(f"acceleration: {names[j]} at {abs(a[i, j]):.1f} rad/s² near t = "
                 f"{_time_of(i, t, interpolation, 1):.3f} s, over the verified plan's "
                 f"{bound[j]:.1f} rad/s²")

    first, last = plan.segments[0].q[0], plan.segments[-1].q[-1]
    for what, ref in (("the plan's first configuration", first),
                      ("the start guard's q_start", q_start)):
        if ref is not None and np.abs(q[0] - ref).max() > EQUAL_TOL:
            j = int(np.argmax(np.abs(q[0] - ref)))
            fail(f"start: the first sample's {names[j]} is {q[0, j] - ref[j]:+.4g} rad from "
                 f"{what}")
    if np.abs(q[-1] - last).max() > EQUAL_TOL:
        j = int(np.argmax(np.abs(q[-1] - last)))
        fail(f"end: the last sample's {names[j]} is {q[-1, j] - last[j]:+.4g} rad from the "
             "plan's final configuration")
    end_speed = np.abs(v[-1] if interpolation == "hold" else qd[-1]).max()
    if end_speed > REST_TOL:
        fail(f"end: the stream ends moving, {end_speed:.3g} rad/s")

    if evaluate is not None:
        times = np.concatenate([t, t_mid])
        ours = np.concatenate([q, q_mid])
        planned, _, _ = evaluate(plan, np.minimum(times, plan.duration))
        gap = np.linalg.norm(blade_points(robot, ours) - blade_points(robot, planned), axis=2)
        worst = gap.max(axis=1)
        k = int(np.argmax(worst))
        report.deviation_m = float(worst[k])
        if report.deviation_m > DEVIATION_M:
            fail(f"deviation: the blade is {1e3 * report.deviation_m:.2f} mm from the verified "
                 f"plan at t = {times[k]:.3f} s (at most {1e3 * DEVIATION_M:g} mm)")
    return report


def require_stream(report: StreamCheck, where: str) -> StreamCheck:
    """``report`` if it passed, else ExportError with its first failure (nothing written)."""
    if report.failures:
        more = f" (and {len(report.failures) - 1} more)" if len(report.failures) > 1 else ""
        raise ExportError(f"{where}: the stream fails its check, nothing written: "
                          f"{report.failures[0]}{more}")
    return report


__all__ = ["ACCEL_FLOOR", "ACCEL_SLACK", "DEVIATION_M", "EQUAL_TOL", "INTERPOLATIONS",
           "StreamCheck", "blade_points", "check_stream", "plan_peak_accel", "require_stream"]
