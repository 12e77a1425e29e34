"""Inverse kinematics along an end-effector trajectory with placo, at a controller rate.

The spatula frame is not in the URDF (flipkit adds it to the pinocchio model in code), so
the tracker writes a temporary copy of the URDF with a fixed ``spatula`` link on the tool
link, at :attr:`flipkit.model.robot.Robot.spatula_in_parent`; visual and collision geometry is
dropped (placo would otherwise resolve ``package://`` meshes, which are irrelevant here).
Each sample warm-starts from the previous configuration and runs a few solver iterations
with joint limits and joint velocity limits; the per-iteration step is dt = Δt / iterations,
so the velocity limit bounds the motion over one sample interval Δt.
"""

from __future__ import annotations

import re
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import placo

from flipkit.errors import ConfigError
from flipkit.model.robot import SPATULA_FRAME, Robot
from flipkit.baseline.ee_opt import EETrajectory


@dataclass
class IKTrack:
    """Joint trajectory from tracking one end-effector trajectory.

    Attributes:
        t: Sample times (s). q: Joint angles (rad), (n, nq). time_s: Wall time of the IK (s).
        branch: Closed-form IK only: each sample's branch (0–7; −1 where none exists).
    """

    t: np.ndarray
    q: np.ndarray
    time_s: float
    branch: np.ndarray | None = None


def spatula_urdf(robot: Robot) -> str:
    """The robot's URDF text without geometry and with a fixed ``spatula`` link added."""
    text = Path(robot.urdf).read_text()
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", text, flags=re.S)
    M = pin.SE3(robot.spatula_in_parent)
    xyz = " ".join(f"{x:.17g}" for x in M.translation)
    rpy = " ".join(f"{x:.17g}" for x in pin.rpy.matrixToRpy(M.rotation))
    link = (f'<link name="{SPATULA_FRAME}"/><joint name="{SPATULA_FRAME}_mount" type="fixed">'
            f'<parent link="{robot.cell.robot.tool_frame}"/><child link="{SPATULA_FRAME}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/></joint>')
    head, sep, tail = text.rpartition("</robot>")
    if not sep:
        raise ConfigError(f"URDF {robot.urdf} has no closing </robot> tag")
    return head + link + sep + tail


class PlacoTracker:
    """placo kinematics solver tracking the spatula frame.

    Args:
        robot: flipkit robot (URDF, spatula mount, base placement, joint names).
        iterations: Solver iterations per sample (≥ 1).
        velocity_limits: Enforce the joint velocity limits in the IK (``robot.qd_max``: the
            arm profile's speeds × the plans' margin, as collocation keeps to).
        w_pos: Weight of the position part of the frame task (soft task).
        w_ori: Weight of the orientation part (per rad against per m).
    """

    def __init__(self, robot: Robot, iterations: int = 3, velocity_limits: bool = True,
                 w_pos: float = 1.0, w_ori: float = 1.0):
        if int(iterations) != iterations or iterations < 1:
            raise ConfigError(f"IK iterations must be a positive integer, got {iterations!r}")
        for name, w in (("w_pos", w_pos), ("w_ori", w_ori)):
            if not (np.isfinite(w) and w > 0):
                raise ConfigError(f"{name} must be a positive finite weight, got {w!r}")
        self.robot, self.iterations = robot, int(iterations)
        with tempfile.TemporaryDirectory(prefix="flipkit-ik-") as tmp:
            path = Path(tmp) / "robot_spatula.urdf"
            path.write_text(spatula_urdf(robot))
            self.placo = placo.RobotWrapper(str(path), placo.Flags.ignore_collisions)
        self.joints = [robot.model.names[j] for j in range(1, robot.model.njoints)]
        missing = set(self.joints) - set(self.placo.joint_names())
        if missing:
            raise ConfigError(f"placo model lacks joints {sorted(missing)}")
        for name, limit, lo, hi in zip(self.joints, robot.qd_max, robot.q_min, robot.q_max):
            # the bounds a plan keeps to (the arm profile's), not the URDF's own
            self.placo.set_velocity_limit(name, float(limit))
            self.placo.set_joint_limits(name, float(lo), float(hi))
        self.placo.set_T_world_fbase(np.asarray(robot.cell.robot.base_in_world, dtype=float))
        self.solver = placo.KinematicsSolver(self.placo)
        self.solver.mask_fbase(True)
        self.solver.enable_joint_limits(True)
        self.solver.enable_velocity_limits(bool(velocity_limits))
        self.task = self.solver.add_frame_task(SPATULA_FRAME, np.eye(4))
        self.task.configure(SPATULA_FRAME, "soft", float(w_pos), float(w_ori))

    def set_q(self, q) -> None:
        """Put the placo model at joint angles q (rad)."""
        for name, value in zip(self.joints, np.asarray(q, dtype=float)):
            self.placo.set_joint(name, float(value))
        self.placo.update_kinematics()

    def get_q(self) -> np.ndarray:
        """Current joint angles of the placo model (rad)."""
        return np.array([self.placo.get_joint(name) for name in self.joints])

    def track(self, traj: EETrajectory, q_start) -> IKTrack:
        """Joint angles along ``traj``, starting from ``q_start`` (rad), one per sample."""
        q_start = np.asarray(q_start, dtype=float)
        if q_start.shape != (self.robot.nq,) or not np.all(np.isfinite(q_start)):
            raise ConfigError(f"q_start must be {self.robot.nq} finite angles, got {q_start}")
        dt = float(traj.t[1] - traj.t[0]) if len(traj.t) > 1 else 1.0
        self.solver.dt = dt / self.iterations
        tic = time.perf_counter()
        self.set_q(q_start)
        q = np.empty((len(traj.t), self.robot.nq))
        target = np.eye(4)
        for k in range(len(traj.t)):
            target[:3, :3], target[:3, 3] = traj.R[k], traj.p[k]
            self.task.T_world_frame = target
            for _ in range(self.iterations):
                self.solver.solve(True)
                self.placo.update_kinematics()
            q[k] = self.get_q()
        return IKTrack(traj.t.copy(), q, time.perf_counter() - tic)
