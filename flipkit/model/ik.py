"""Single-pose inverse kinematics of the spatula frame (start configurations, q_home).

Closed-loop damped least squares on the SE(3) log error, the scheme of pinocchio's own
inverse-kinematics example, with joint limits enforced by clamping. Trajectory IK for the
end-effector-space baseline uses placo instead (:mod:`flipkit.baseline`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from flipkit.errors import UnreachableError
from flipkit.model.orientation import rpy_matrix
from flipkit.model.robot import Robot


def solve_pose(robot: Robot, position, orientation, q_guess=None, *, tol: float = 1e-9,
               max_iter: int = 300, damping: float = 1e-6) -> np.ndarray:
    """Joint angles that put the spatula at ``position`` (m) with rpy ``orientation`` (rad).

    Args:
        robot: The robot model.
        position: Target blade-centre position (m).
        orientation: Target o = (o_x, o_y, o_z) (rad).
        q_guess: Starting configuration (default q_home); the solution is the nearby branch.
        tol: Squared-norm tolerance on the 6D log error.

    Raises:
        UnreachableError: The pose cannot be reached within the joint limits.
    """
    position = np.asarray(position, dtype=float)
    if not (np.all(np.isfinite(position)) and np.all(np.isfinite(orientation))):
        raise UnreachableError(f"spatula pose must be finite, got p={position.tolist()}")
    target = pin.SE3(rpy_matrix(orientation), position)
    guess = np.array(robot.q_home if q_guess is None else q_guess, dtype=float)
    # Second try: the guess turned about the base so that it faces the target's azimuth.
    here = robot.position(guess)
    turned = guess.copy()
    turned[0] += np.arctan2(position[1], position[0]) - np.arctan2(here[1], here[0])
    err = np.inf
    for start in (guess, turned):
        q, err = _clik(robot, target, start, tol, max_iter, damping)
        if err < tol:
            return q
    raise UnreachableError(
        f"spatula pose p={np.round(position, 4).tolist()} o={np.round(orientation, 4).tolist()} "
        f"is out of reach (IK residual {np.sqrt(err):.2e})")


def _clik(robot: Robot, target: pin.SE3, q, tol, max_iter, damping):
    m, d, fid = robot.model, robot.data, robot.frame_id
    q = np.array(q, dtype=float)
    err = np.inf
    for _ in range(max_iter):
        pin.framesForwardKinematics(m, d, q)
        dM = target.actInv(d.oMf[fid])
        e = pin.log6(dM).vector
        err = float(e @ e)
        if err < tol:
            return q, err
        J = pin.computeFrameJacobian(m, d, q, fid, pin.ReferenceFrame.LOCAL)
        J = pin.Jlog6(dM) @ J
        step = -J.T @ np.linalg.solve(J @ J.T + damping * np.eye(6), e)
        q = np.clip(q + step, robot.q_min, robot.q_max)
    return q, err
