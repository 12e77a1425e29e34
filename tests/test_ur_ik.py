"""Closed-form UR10 IK: every branch reproduces the pose, one of them is the configuration the
pose came from, and a pose out of reach has no branch."""

import numpy as np
import pytest

from flipkit.config import CellConfig, RobotConfig
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot
from flipkit.model.ur_ik import BRANCHES, URAnalyticIK, dh_forward, dh_inverse


@pytest.fixture(scope="module")
def ik(robot):
    return URAnalyticIK(robot)


def test_dh_inverse_inverts_dh_forward_on_all_eight_branches():
    rng = np.random.default_rng(1)
    counts = []
    for q in rng.uniform(-np.pi, np.pi, (50, 6)):
        T = dh_forward(q)
        sols = dh_inverse(T)
        found = ~np.isnan(sols[:, 0])
        counts.append(int(found.sum()))
        for s in sols[found]:
            np.testing.assert_allclose(dh_forward(s), T, atol=1e-9)
        dist = np.abs((sols - q + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
        assert np.nanmin(dist) < 1e-7
    # the other shoulder can leave the wrist centre out of the elbow's reach: 2, 4 or 6
    # branches then; most poses have all eight (seeded: 160 of 200)
    assert counts.count(BRANCHES) >= 35 and min(counts) >= 2 and all(c % 2 == 0 for c in counts)


def test_many_poses_at_once_are_the_poses_one_by_one(robot, ik):
    """The batch over poses (the tracker's path) gives each pose's branches, NaN where one
    does not exist: random poses, a wrist singularity (θ5 = 0) and poses out of reach."""
    rng = np.random.default_rng(5)
    poses = [robot.placement(q).homogeneous for q in rng.uniform(-np.pi, np.pi, (40, 6))]
    q = rng.uniform(-1.0, 1.0, 6)
    q[4] = 0.0
    poses.append(robot.placement(q).homogeneous)
    for p in ([3.0, 0.0, 0.5], [0.0, 0.0, 3.0]):
        far = np.eye(4)
        far[:3, 3] = p
        poses.append(far)
    many = ik.solve_many(np.array(poses))
    assert many.shape == (len(poses), BRANCHES, 6)
    for T, sols in zip(poses, many):
        np.testing.assert_array_equal(sols, ik.solve(T))
    assert np.isnan(many[-2:]).all() and not np.isnan(many[-3]).all()
    for s in many[-3][~np.isnan(many[-3][:, 0])]:  # the singular pose's branches reproduce it
        np.testing.assert_allclose(robot.placement(s).homogeneous, poses[-3], atol=1e-9)


def test_spatula_poses_of_the_urdf_model(robot, ik):
    rng = np.random.default_rng(2)
    lo, hi = robot.q_min, robot.q_max
    for q in rng.uniform(lo, hi, (30, 6)):
        T = robot.placement(q).homogeneous
        sols = ik.solve(T)
        ok = ~np.isnan(sols[:, 0])
        assert ok.any()
        for s in sols[ok]:
            np.testing.assert_allclose(robot.placement(s).homogeneous, T, atol=1e-9)
            assert np.all(s >= lo - 1e-12) and np.all(s <= hi + 1e-12)
        k, best = ik.nearest(T, q)
        np.testing.assert_allclose(best, q, atol=1e-7)


def test_q_home_is_found_again(robot, ik):
    k, q = ik.nearest(robot.placement(robot.q_home).homogeneous, robot.q_home)
    np.testing.assert_allclose(q, robot.q_home, atol=1e-7)


def test_out_of_reach_has_no_branch(robot, ik):
    T = robot.placement(robot.q_home).homogeneous
    T[:3, 3] = (2.5, 0.0, 0.5)  # 2.5 m: the UR10 reaches 1.3 m
    assert np.isnan(ik.solve(T)).all() and ik.nearest(T, robot.q_home) is None


def test_a_moved_base_is_followed(robot):
    base = np.eye(4)
    base[:3, 3] = (0.1, -0.2, 0.05)
    moved = Robot(CellConfig(robot=RobotConfig(base_in_world=tuple(map(tuple, base)))))
    ik = URAnalyticIK(moved)
    q = moved.q_home
    k, sol = ik.nearest(moved.placement(q).homogeneous, q)
    np.testing.assert_allclose(sol, q, atol=1e-7)


def test_another_arm_is_refused(robot, monkeypatch):
    import flipkit.model.ur_ik as ur

    monkeypatch.setattr(ur, "D", (0.2,) + ur.D[1:])  # not the UR10's shoulder height
    with pytest.raises(ConfigError, match="not the UR10"):
        URAnalyticIK(robot)


def test_the_analytic_tracker_follows_a_joint_path_on_one_branch(robot):
    """Poses of a smooth joint path q(t) away from the wrist singularity (θ5 stays > 0): the
    tracker returns q(t) itself, on one branch; a
    pose out of reach keeps the last configuration, marked branch −1."""
    from types import SimpleNamespace

    from flipkit.baseline.analytic_track import AnalyticTracker

    t = np.linspace(0.0, 1.0, 101)
    q_path = robot.q_home + np.outer(np.sin(np.pi * t), [0.3, -0.2, 0.4, 0.5, -0.3, 1.2])
    M = [robot.placement(q).homogeneous for q in q_path]
    traj = SimpleNamespace(t=t, p=np.array([m[:3, 3] for m in M]),
                           R=np.array([m[:3, :3] for m in M]))
    track = AnalyticTracker(robot).track(traj, robot.q_home)
    np.testing.assert_allclose(track.q, q_path, atol=1e-7)
    assert len(set(track.branch)) == 1 and track.branch[0] >= 0
    traj.p[50] = (2.5, 0.0, 0.5)
    track = AnalyticTracker(robot).track(traj, robot.q_home)
    assert track.branch[50] == -1 and np.array_equal(track.q[50], track.q[49])
    np.testing.assert_allclose(track.q[51:], q_path[51:], atol=1e-7)
