"""``flipkit verify``'s check of a plan against the arm's safety preset: the tool's speed and
the arm's momentum, recomputed from the plan's arrays with pinocchio
(:class:`~flipkit.model.tool_motion.ToolMotion`).

The preset is the cell's (``robot.arm.safety_preset`` of the plan file, a name looked up in
:mod:`flipkit.config.arm`, never numbers the file states). The plan is checked at its nodes
and at :data:`SUBSTEPS` − 1 points inside each interval of the cubic Hermite interpolant the
controller follows. The preset's force and power concern contact with the environment, which
a plan does not model: the simulated safety system (:mod:`flipkit.simulation.safety`)
watches those.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from flipkit.model.tool_motion import ToolMotion

SUBSTEPS = 4  # points per interval (its start and three inside)


def check_safety(report, k: int, seg, robot, tol: float) -> None:
    """Add segment ``k``'s rows to the ``safety_limits`` group: TCP speed (m/s) and momentum
    (kg·m/s) over the preset's, with the relative tolerance ``tol``.

    Args:
        report: The :class:`~flipkit.planning.plans.verify_report.VerificationReport`.
        seg: The segment. robot: Its model, with the payload it carries.
    """
    preset = robot.profile.preset(robot.cell.robot.safety_preset)
    spline = CubicHermiteSpline(seg.t, seg.q, seg.qd, axis=0)
    frac = np.arange(SUBSTEPS) / SUBSTEPS
    times = np.append((seg.t[:-1, None] + np.diff(seg.t)[:, None] * frac).ravel(), seg.t[-1])
    q, qd = spline(times), spline(times, 1)
    tool = ToolMotion(robot)
    rows = np.array([tool.speed_and_momentum(a, b) for a, b in zip(q, qd)])
    limit = np.array([preset.tcp_speed, preset.momentum])
    nodes = np.minimum(np.arange(len(times)) // SUBSTEPS, seg.N)
    over = np.maximum(rows - limit, 0.0)
    for node in np.unique(nodes):
        report.add("safety_limits", k, over[nodes == node].max(axis=0), tol * limit,
                   int(node))


__all__ = ["SUBSTEPS", "check_safety"]
