"""A goal pose checked before any NLP: reachable within the joint bounds, and clear of the cell.

A segment's last node must put the spatula exactly at its goal pose, inside the joint bounds
the planner imposes (the joint limits, narrowed by :func:`~flipkit.model.singular.branch_bounds`
to keep q3 and q5 off their singularities, on q_home's side) and with every applied (shape,
box) pair of :class:`~flipkit.model.collision.ArmShapes` at least ``cell.space.margin`` apart.
The pose has at most eight joint solutions (:func:`~flipkit.model.ur_ik.dh_inverse`, each up
to 2π shifts), so :func:`check_goal` tries them all in about a millisecond: if none is inside
the bounds and clear, no solver can end there, and the refusal names the limit and the amount.
(The goal's task-area box and the blade's height are the planner's own input checks.)

Conservative by construction (a false refusal is worse than a slow one): the solvers meet the
end pose to 1e-6 (m, rad), so their last node may lie a little off the exact IK branch —
~3e-4 rad where q3 and q5 keep the 0.2 rad margin (the Jacobian's least singular value there
is ≥ 0.008, :mod:`flipkit.model.singular`), which moves a link ≤ 0.5 mm; 2.6e-3 rad at a
stretched elbow. A branch is refused only beyond :data:`JOINT_SLACK` out of the bounds or
:data:`CLEARANCE_SLACK` inside the margin, and never for clearance within
:data:`NEAR_SINGULAR` of the elbow or wrist singularity, where the pose pins the joints
loosely (a wrist-singular pose has a continuum of them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import ConfigError, UnreachableError
from flipkit.model.collision import ArmShapes
from flipkit.model.orientation import rpy_matrix
from flipkit.model.robot import Robot
from flipkit.model.singular import ELBOW, SINGULARITY_MARGIN, WRIST, branch_bounds
from flipkit.model.ur_ik import A, D, URAnalyticIK, dh_inverse, dh_transform

JOINT_SLACK = 0.01  # rad: a branch this far outside the joint bounds is not refused
CLEARANCE_SLACK = 0.001  # m: nor one this far inside the margin
NEAR_SINGULAR = 0.05  # |sin q3| or |sin q5| below it: the branch's clearance never refuses
SHIFTS = 2 * np.pi * np.arange(-2, 3)  # rad: 2π shifts tried per joint
WHAT = {"upper_arm": "upper arm", "ee": "flange box", "handle": "spatula handle",
        "blade": "spatula blade"}  # the others read "<name> housing"


@dataclass(frozen=True)
class GoalCheck:
    """An IK branch that reaches the goal inside the joint bounds and clear of the cell.

    Attributes:
        q: The configuration (rad), each joint shifted by 2π to lie within the bounds and
            nearest ``q_start``: a seed for the goal node of the NLP.
        branch: Its row in :func:`~flipkit.model.ur_ik.dh_inverse` (0..7).
        clearance: Least distance (m) over the applied (shape, box) pairs at ``q``.
        shape, box: That pair's names ("" and clearance inf if no pair applies).
        feasible: How many branches passed the check.
    """

    q: np.ndarray
    branch: int
    clearance: float
    shape: str
    box: str
    feasible: int


def _xyz(v) -> str:
    """(x, y, z) to 2 decimals, or 3 where 2 would round (0.095 is not shown as 0.10)."""
    return "(" + ", ".join(f"{x:.2f}" if abs(x - round(x, 2)) < 5e-7 else f"{x:.3f}"
                           for x in v) + ")"


def _cm(d: float) -> str:
    return f"{abs(d) * 100:.1f} cm {'from' if d >= 0 else 'inside'}"


def _reach(T06: np.ndarray) -> str:
    """Why no branch of T06 exists: how far (m) the wrist is out of the arm's reach
    (the steps of :func:`~flipkit.model.ur_ik.dh_inverse` up to the elbow's planar triangle)."""
    o5 = T06[:3, 3] - D[5] * T06[:3, 2]
    r = float(np.hypot(o5[0], o5[1]))
    if r < abs(D[3]):
        return f"wrist centre {r:.3f} m from the base axis, {abs(D[3]) - r:.3f} m short of d4"
    psi, delta, gap = np.arctan2(o5[1], o5[0]), np.arcsin(D[3] / r), np.inf
    for th1 in (psi + delta, psi + np.pi - delta):
        T16 = np.linalg.solve(dh_transform(0, th1), T06)
        c5 = np.clip(T16[2, 2], -1.0, 1.0)
        for th5 in (np.arccos(c5), -np.arccos(c5)):
            s5 = np.sin(th5)
            th6 = 0.0 if abs(s5) < 1e-9 else np.arctan2(-T16[2, 1] / s5, T16[2, 0] / s5)
            T14 = T16 @ np.linalg.inv(dh_transform(4, th5) @ dh_transform(5, th6))
            rho = float(np.hypot(T14[0, 3], T14[1, 3]))
            gap = min(gap, max(rho - abs(A[1]) - abs(A[2]), abs(abs(A[1]) - abs(A[2])) - rho))
    return f"out of reach by {gap * 100:.1f} cm (elbow triangle {abs(A[1]) + abs(A[2]):.3f} m)"


def check_goal(robot: Robot, shapes: ArmShapes, cell: CellConfig, position, rpy=(0.0, 0.0, 0.0),
               *, q_start=None, singularity_margin: float = SINGULARITY_MARGIN,
               excluded=(), clearance: bool = True) -> GoalCheck:
    """Refuse, fast and with a reason, a goal pose that no NLP can end at.

    Args:
        robot: The segment's arm (its joint limits, q_home, spatula frame).
        shapes: The arm's shapes and the cell's boxes (the planner's ``models.shapes``).
        cell: The cell; its ``space.margin`` (m) is the clearance to keep.
        position: Blade-centre goal (m, world). rpy: Spatula orientation (o_x, o_y, o_z) (rad).
        q_start: The segment's start configuration (rad; default q_home): widens the
            singularity bands as :func:`~flipkit.model.singular.branch_bounds` does.
        singularity_margin: The planner's margin (rad) of q3 and q5 from their singularities.
        excluded: (shape name, box name) pairs the segment does not hold to the margin at its
            last node (translate: none).
        clearance: False for an NLP without the arm's clearance rows (``SegmentOptions``
            ``arm_clearance``): reachability and joint bounds only.

    Returns:
        The passing branch nearest ``q_start`` (fully inside the bounds and margin first).

    Raises:
        ConfigError: A non-finite pose or an unknown pair name.
        UnreachableError: One line: ``goal (x, y, z): <limit and amount>``.
    """
    p, o = np.asarray(position, float).ravel(), np.asarray(rpy, float).ravel()
    if p.shape != (3,) or o.shape != (3,) or not np.all(np.isfinite(np.r_[p, o])):
        raise ConfigError(f"goal pose must be 3 + 3 finite numbers (m, rad), got {p}, {o}")
    where = f"goal {_xyz(p)}" + (f" rpy {_xyz(o)}" if np.any(o) else "")
    ref = robot.q_home if q_start is None else np.asarray(q_start, float)
    lo, hi = branch_bounds(robot.q_min, robot.q_max, robot.q_home, ref, singularity_margin)
    ik, T = URAnalyticIK(robot), np.eye(4)
    T[:3, :3], T[:3, 3] = rpy_matrix(o), p
    T06 = np.linalg.solve(ik.base, T @ np.linalg.inv(ik.spatula)) @ np.linalg.inv(ik.tool)
    raw = dh_inverse(T06)
    rows = np.flatnonzero(~np.isnan(raw[:, 0]))
    if not len(rows):
        raise UnreachableError(f"{where}: {_reach(T06)}")
    # per joint, the 2π shift inside [lo, hi] (or least outside) and nearest the start
    cand = raw[rows][:, None, :] + SHIFTS[None, :, None]  # (branches, shifts, joints)
    out = np.maximum(np.maximum(lo - cand, cand - hi), 0.0)
    least = out == out.min(axis=1, keepdims=True)
    pick = np.argmin(np.where(least, np.abs(cand - ref), np.inf), axis=1)
    q = np.take_along_axis(cand, pick[:, None, :], 1)[:, 0]
    viol = np.take_along_axis(out, pick[:, None, :], 1)[:, 0]
    skip = {(shapes.shape_index(s), shapes.box_index(b)) for s, b in excluded}
    allowed = np.full((len(rows), len(shapes.names), len(shapes.box_names)), bool(clearance))
    for k, b in skip:
        allowed[:, k, b] = False
    dist, _, near_s, near_b = shapes.nearest_nodes(q, allowed)
    margin = cell.space.margin
    loose = np.abs(np.sin(q[:, [ELBOW, WRIST]])).min(axis=1) < NEAR_SINGULAR
    inside = viol.max(axis=1) <= JOINT_SLACK
    ok = inside & ((dist >= margin - CLEARANCE_SLACK) | loose)
    if ok.any():
        strict = (viol.max(axis=1) == 0) & (dist >= margin)
        order = np.lexsort((np.abs(q - ref).max(axis=1), ~strict, ~ok))
        i = int(order[0])
        found = near_s[i] >= 0  # else no pair applied: clearance inf
        return GoalCheck(q[i].copy(), int(rows[i]), float(dist[i]),
                         shapes.names[near_s[i]] if found else "",
                         shapes.box_names[near_b[i]] if found else "", int(ok.sum()))
    if inside.any():  # in the bounds, none clear: the branch that comes closest
        i = int(np.flatnonzero(inside)[np.argmax(dist[inside])])
        s = shapes.names[near_s[i]]
        raise UnreachableError(
            f"{where}: {WHAT.get(s, s + ' housing')} {_cm(dist[i])} the "
            f"{shapes.box_names[near_b[i]]}, margin {margin * 100:g} cm (best of "
            f"{int(inside.sum())} IK branches within the joint bounds)")
    i = int(np.argmin(viol.max(axis=1)))
    j = int(np.argmax(viol[i]))
    name = {ELBOW: "q3 (elbow)", WRIST: "q5 (wrist)"}.get(j, f"q{j + 1}")
    why = (f"{singularity_margin:g} rad from its singularities, q_home's side"
           if lo[j] > robot.q_min[j] or hi[j] < robot.q_max[j] else "the joint limits")
    raise UnreachableError(
        f"{where}: no IK branch within the joint bounds; the nearest has {name} = {q[i, j]:.3f} "
        f"rad, {viol[i, j]:.3f} rad outside [{lo[j]:.3f}, {hi[j]:.3f}] rad ({why})")


__all__ = ["CLEARANCE_SLACK", "JOINT_SLACK", "NEAR_SINGULAR", "GoalCheck", "check_goal"]
