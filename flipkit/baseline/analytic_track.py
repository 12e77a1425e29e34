"""Inverse kinematics along an end-effector trajectory in closed form: the UR10's eight
branches at every sample, following the branch continuous with the start configuration.

This is the IK step that does not give up early: at each sample every branch of
:class:`~flipkit.model.ur_ik.URAnalyticIK` is computed and the one nearest to the previous
configuration (max joint distance, 2π shifts inside the joint limits) is taken. The tracker
never lags behind the pose: a sample whose pose has no branch inside the joint limits keeps
the previous configuration (the classifier then sees the pose error), and a change of branch
or a step larger than the joints can make in one sample shows as a configuration jump.
"""

from __future__ import annotations

import time

import numpy as np

from flipkit.baseline.ee_opt import EETrajectory
from flipkit.baseline.ik_track import IKTrack
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot
from flipkit.model.ur_ik import URAnalyticIK, nearest_branch


class AnalyticTracker:
    """Closed-form IK of the spatula frame along a trajectory.

    Args:
        robot: The arm (a UR10; see :class:`~flipkit.model.ur_ik.URAnalyticIK`).
    """

    def __init__(self, robot: Robot):
        self.robot, self.ik = robot, URAnalyticIK(robot)

    def track(self, traj: EETrajectory, q_start) -> IKTrack:
        """Joint angles along ``traj`` from ``q_start`` (rad), one per sample; the track's
        ``branch`` holds each sample's branch index (−1: no branch, configuration kept)."""
        q_prev = np.asarray(q_start, dtype=float)
        if q_prev.shape != (self.robot.nq,) or not np.all(np.isfinite(q_prev)):
            raise ConfigError(f"q_start must be {self.robot.nq} finite angles, got {q_start}")
        tic = time.perf_counter()
        n = len(traj.t)
        q, branch = np.empty((n, self.robot.nq)), np.full(n, -1)
        T = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
        T[:, :3, :3], T[:, :3, 3] = traj.R, traj.p
        sols = self.ik.solve_many(T)  # every branch of every sample at once
        for k in range(n):
            found = nearest_branch(sols[k], q_prev)
            if found is not None:
                branch[k], q_prev = found[0], found[1]
            q[k] = q_prev
        return IKTrack(traj.t.copy(), q, time.perf_counter() - tic, branch)
