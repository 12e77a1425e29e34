"""RNEA residual against the textbook form D(q)q̈ + C(q,q̇)q̇ + G(q) − u assembled separately."""

import numpy as np
import pinocchio as pin
from conftest import random_states

from flipkit.config import CellConfig
from flipkit.model.robot import Robot


def test_rnea_equals_assembled_lagrangian_dynamics(robot):
    m, d = robot.model, robot.model.createData()
    for q, qd, qdd in random_states(robot, 11):
        D = pin.crba(m, d, q)
        D = np.triu(D) + np.triu(D, 1).T
        C = pin.computeCoriolisMatrix(m, d, q, qd)
        G = pin.computeGeneralizedGravity(m, d, q)
        u = np.linspace(-3, 3, 6)
        np.testing.assert_allclose(robot.dynamics_residual(q, qd, qdd, u),
                                   D @ qdd + C @ qd + G - u, atol=1e-9)


def test_payload_changes_gravity_torque_by_its_weight():
    """Adding the burger (mass m on the blade) adds m g times the lever arm to G(q)."""
    cell = CellConfig()
    bare, loaded = Robot(cell), Robot(cell, with_burger=True)
    q = bare.q_home
    dG = loaded.inverse_dynamics(q, np.zeros(6), np.zeros(6)) - bare.inverse_dynamics(
        q, np.zeros(6), np.zeros(6))
    # Virtual work: dG = J_com^T (m g) with the burger com above the blade centre.
    st = loaded.pose_jacobians(q)
    com = st[0] + st[1] @ np.array([0, 0, (cell.spatula.thickness + cell.burger.thickness) / 2])
    J = st[2] - np.array([[0, -(com - st[0])[2], (com - st[0])[1]],
                          [(com - st[0])[2], 0, -(com - st[0])[0]],
                          [-(com - st[0])[1], (com - st[0])[0], 0]]) @ st[3]
    np.testing.assert_allclose(dG, -J.T @ (cell.burger.mass * np.array(cell.gravity)), atol=1e-9)


def test_world_gravity_and_profile_limits(robot):
    """The URDF's torques (54 N·m on the wrists, within UR's 56), UR's published speeds
    (120 and 180 deg/s, not the URDF's 2.16/3.15/3.2 rad/s), plans held to 95 % of them."""
    np.testing.assert_allclose(robot.model.gravity.linear, [0, 0, -9.81])
    np.testing.assert_allclose(robot.u_max, [330, 330, 150, 54, 54, 54])
    np.testing.assert_allclose(robot.qd_limit, np.radians([120, 120, 180, 180, 180, 180]))
    np.testing.assert_allclose(robot.qd_max, 0.9 * robot.qd_limit)
    np.testing.assert_allclose(robot.model.velocityLimit, robot.qd_limit)
