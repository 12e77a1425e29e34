"""Initial guesses of the behaviours' segments (:func:`initial_guess`), at T = T_max.

Each is dynamically consistent (u = RNEA(q, q̇, q̈) along a Bezier polynomial,
:mod:`flipkit.transcription.guess`); the solver starts there. A warm-start atlas, when present,
replaces them for the segments it seeds (:mod:`flipkit.planning.atlas`).
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


def flip_guess_pose(cell: CellConfig, pb) -> tg.Pose:
    """A pose inside the flip end set, used only to seed the initial guess."""
    p = tg.pickup_end(cell, pb).p
    return tg.Pose((p[0] + 0.02, p[1], cell.grill.height + 0.22), (-2.6, 0.0, 0.0))


def return_home_guess(L, robot, q_start, qd_start, T):
    """Return home's guess: the withdrawal it must make (nodes 0..WITHDRAW_NODES: the blade
    slides back along its own −x, 1 cm past WITHDRAW_DISTANCE, attitude kept; IK node by
    node), then a smoothstep joint path to q_home, fitted by the Bezier polynomial with a rest
    at the end. (A joint path straight home violated the withdrawal by 0.4 (scaled) and took
    20–36 SQP iterations, measured on serves.)"""
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


def initial_guess(name, L, robot, q_start, qd_start, T, pose, pb, cell, rest_at_end):
    """Initial guess at T = T_max.

    Where the segment has a task-space path (go to burger, scoop, pickup) the spatula pose
    is interpolated from start to end (smoothstep in time, the tip kept on the grill for
    the scoop), solved by IK node by node and fitted by the Bezier polynomial; otherwise a
    joint-space Bezier path to an IK solution of the end pose (flip: a pose in its end set;
    turn back: q_home).
    """
    if name == "return_home":
        return return_home_guess(L, robot, q_start, qd_start, T)
    if name == "turn_back":
        # Critically damped return to q_home from the (moving) start state: it brakes first
        # instead of extrapolating the start velocity past the joint limits.
        w, t = 4.0 / T, L.s * T  # peak |q̈| ≈ w²|q_0 − q_home| stays near the limit
        e0 = q_start - robot.q_home
        waypoints = robot.q_home + (e0 + np.outer(t, qd_start + w * e0)) * np.exp(-w * t)[:, None]
        return fit_guess(L, robot, np.clip(waypoints, robot.q_min, robot.q_max), T, qd_start, True)
    if name in ("go_to_burger", "scoop", "pickup", "carry", "place"):
        p0, R0 = robot.position(q_start), robot.rotation(q_start)
        o0, o1 = rpy(R0), np.asarray(pose.o)
        waypoints, q = [], q_start
        for s in L.s:
            w = s * s * (3 - 2 * s)
            o = (1 - w) * o0 + w * o1
            p = (1 - w) * p0 + w * np.asarray(pose.p)
            if name == "scoop":  # keep the tip pressed: p_z = h_g − press + (l/2) sin o_y
                p[2] = cell.grill.height - tg.SCOOP_PRESS + cell.spatula.length / 2 * np.sin(o[1])
            try:
                q = solve_pose(robot, p, o, q)
            except UnreachableError:
                if name not in sv.SERVE_ONLY:
                    raise
                # the straight carry to the table passes near the base: a joint-space path
                return bezier_guess(L, robot, q_start, sv.reach(robot, pose, (q_start, q)),
                                    T, qd_start)
            waypoints.append(q)
        return fit_guess(L, robot, waypoints, T, qd_start, rest_at_end)
    seed_pose = pose if pose is not None else flip_guess_pose(cell, pb)
    guess = q_start.copy()
    if name == "flip":
        guess[-1] -= 2.6  # roll the blade over about its own axis (wrist 3)
    q_end = solve_pose(robot, seed_pose.p, seed_pose.o, guess)
    return bezier_guess(L, robot, q_start, q_end, T, qd_start)


__all__ = ["flip_guess_pose", "initial_guess", "return_home_guess"]
