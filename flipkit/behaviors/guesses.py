"""Initial guesses of the subbehaviours' segments, at T = T_max; each spec names its own
(``guess(ctx, T, pose)``).

Each is dynamically consistent (u = RNEA(q, q̇, q̈) along a Bezier polynomial,
:mod:`flipkit.transcription.guess`); the solver starts there. A warm-start atlas, when present,
replaces them for the segments it seeds (:mod:`flipkit.planning.planners.atlas`).
"""

from __future__ import annotations

import numpy as np

from flipkit.behaviors import serve as sv
from flipkit.behaviors import targets as tg
from flipkit.config import CellConfig
from flipkit.errors import UnreachableError
from flipkit.model.ik import solve_pose
from flipkit.model.orientation import rpy
from flipkit.transcription.guess import bezier_guess, fit_guess


def flip_guess_pose(cell: CellConfig, pb, heading: float = 0.0) -> tg.Pose:
    """A pose inside the flip end set along the scoop ``heading`` (rad), used only to seed
    the initial guess."""
    p = tg.pickup_end(cell, pb).p
    pose = tg.Pose((p[0] + 0.02, p[1], cell.grill.height + 0.22), (-2.6, 0.0, 0.0))
    return tg.headed(pose, pb, heading)


def withdraw_then_home(L, robot, q_start, qd_start, T):
    """Return home's guess: the withdrawal it must make (nodes 0..WITHDRAW_NODES: the blade
    slides back along its own −x, 1 cm past WITHDRAW_DISTANCE, attitude kept; IK node by
    node), then a smoothstep joint path to q_home, fitted by the Bezier polynomial with a rest
    at the end. (A joint path straight home violates the withdrawal, and the SQP spends many
    iterations repairing it.)"""
    n = sv.WITHDRAW_NODES
    st = robot.placement(q_start)
    o0, q, waypoints = rpy(st.rotation), q_start, []
    for i in range(n + 1):
        w = (i / n) ** 2 * (3 - 2 * i / n)
        p = st.translation - w * (sv.WITHDRAW_DISTANCE + 0.01) * st.rotation[:, 0]
        try:
            q = solve_pose(robot, p, o0, q)
        except UnreachableError:  # the withdrawal is out of reach: the segment will say so
            break
        waypoints.append(q)
    q_w, rest = waypoints[-1], L.N + 1 - len(waypoints)
    for k in range(1, rest + 1):
        w = (k / rest) ** 2 * (3 - 2 * k / rest)
        waypoints.append((1 - w) * q_w + w * robot.q_home)
    return fit_guess(L, robot, np.clip(waypoints, robot.q_min, robot.q_max), T, qd_start, True)


def pose_path(ctx, knots, *, tip_pressed: bool = False, solved: list | None = None) -> list:
    """Joint waypoints at the segment's nodes along a spatula pose path: ``knots`` are
    ``(s, p, o)`` (s from 0 to 1 in node time, blade-centre position (m), rpy (rad)); between
    two knots p and o follow a smoothstep in s, and each node's pose is solved by IK from the
    previous node's solution. ``tip_pressed`` keeps the blade tip pressed into the grill (the
    scoop): p_z = h_g − press + (l/2) sin o_y. ``solved``: a list that receives each node's
    solution as it is found (what was reached before an :class:`UnreachableError`).

    Raises:
        UnreachableError: A node's pose is out of reach.
    """
    cell, q = ctx.cell, ctx.q_start
    waypoints = [] if solved is None else solved
    for s in ctx.layout.s:
        k = next(j for j in range(1, len(knots)) if s <= knots[j][0] + 1e-12)
        (s0, pa, oa), (s1, pb, ob) = knots[k - 1], knots[k]
        u = (s - s0) / (s1 - s0)
        w = u * u * (3 - 2 * u)
        o = (1 - w) * np.asarray(oa) + w * np.asarray(ob)
        p = (1 - w) * np.asarray(pa) + w * np.asarray(pb)
        if tip_pressed:
            p[2] = cell.grill.height - tg.SCOOP_PRESS + cell.spatula.length / 2 * np.sin(o[1])
        q = solve_pose(ctx.robot, p, o, q)
        waypoints.append(q)
    return waypoints


def task_path_guess(ctx, T, pose, *, tip_pressed: bool = False,
                    joint_fallback: bool = False):
    """The spatula pose interpolated from start to ``pose`` (smoothstep in time), solved by IK
    node by node and fitted by the Bezier polynomial (go to burger, scoop, pickup, carry,
    place).

    Args:
        ctx: The segment's :class:`~flipkit.behaviors.spec.Context`. T: Duration (s).
        pose: End pose. tip_pressed: Keep the blade tip pressed into the grill (the scoop):
            p_z = h_g − press + (l/2) sin o_y. joint_fallback: Where IK fails on the way (a
            straight carry to the table passes near the base), a joint-space path to an IK
            solution of the end pose instead.
    """
    L, robot, q_start = ctx.layout, ctx.robot, ctx.q_start
    knots = [(0.0, robot.position(q_start), rpy(robot.rotation(q_start))),
             (1.0, np.asarray(pose.p, float), np.asarray(pose.o, float))]
    solved = []
    try:
        waypoints = pose_path(ctx, knots, tip_pressed=tip_pressed, solved=solved)
    except UnreachableError:
        if not joint_fallback:
            raise
        last = solved[-1] if solved else q_start  # the seed the path reached before it failed
        return bezier_guess(L, robot, q_start, sv.reach(robot, pose, (q_start, last)),
                            T, ctx.qd_start)
    return fit_guess(L, robot, waypoints, T, ctx.qd_start, ctx.spec.at_rest)


def end_pose_guess(ctx, T, pose):
    """A joint-space Bezier path to the IK solution of ``pose`` nearest the start (translate)."""
    q_end = solve_pose(ctx.robot, pose.p, pose.o, ctx.q_start.copy())
    return bezier_guess(ctx.layout, ctx.robot, ctx.q_start, q_end, T, ctx.qd_start)


def flip_guess(ctx, T, pose):
    """A joint-space Bezier path to a pose in the flip's end set (:func:`flip_guess_pose`),
    the blade rolled over about its own axis (wrist 3 − 2.6 rad)."""
    seed_pose = flip_guess_pose(ctx.cell, ctx.location, ctx.task.heading)
    guess = ctx.q_start.copy()
    guess[-1] -= 2.6
    q_end = solve_pose(ctx.robot, seed_pose.p, seed_pose.o, guess)
    return bezier_guess(ctx.layout, ctx.robot, ctx.q_start, q_end, T, ctx.qd_start)


def turn_back_guess(ctx, T, pose):
    """A critically damped return to q_home from the (moving) start state: it brakes first
    instead of extrapolating the start velocity past the joint limits."""
    L, robot, q_start, qd_start = ctx.layout, ctx.robot, ctx.q_start, ctx.qd_start
    w, t = 4.0 / T, L.s * T  # peak |q̈| ≈ w²|q_0 − q_home| stays near the limit
    e0 = q_start - robot.q_home
    waypoints = robot.q_home + (e0 + np.outer(t, qd_start + w * e0)) * np.exp(-w * t)[:, None]
    return fit_guess(L, robot, np.clip(waypoints, robot.q_min, robot.q_max), T, qd_start, True)


def return_home_guess(ctx, T, pose):
    """Return home's guess: :func:`withdraw_then_home`."""
    return withdraw_then_home(ctx.layout, ctx.robot, ctx.q_start, ctx.qd_start, T)


__all__ = ["end_pose_guess", "flip_guess", "flip_guess_pose", "return_home_guess",
           "task_path_guess", "turn_back_guess", "withdraw_then_home"]
