"""The CasADi SX chain (flipkit.model.casadi_dynamics) against pinocchio at seeded states."""

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from flipkit.model.casadi_dynamics import CasadiArm
from flipkit.model.robot import Robot


def _states(robot, seed, n=8):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        yield (rng.uniform(robot.q_min, robot.q_max), rng.uniform(-robot.qd_max, robot.qd_max),
               rng.uniform(-30, 30, robot.nq))


@pytest.fixture(scope="module", params=[False, True], ids=["bare", "loaded"])
def arm(request, cell):
    robot = Robot(cell, with_burger=request.param)
    return robot, CasadiArm(robot)


def test_rnea_matches_pinocchio(arm):
    """τ from the SX graph equals pinocchio.rnea (payload included) to 1e-9 N·m."""
    robot, sx = arm
    for q, qd, qdd in _states(robot, 3):
        tau = np.asarray(sx.rnea_function(q, qd, qdd)).ravel()
        ref = pin.rnea(robot.model, robot.data, q, qd, qdd)
        np.testing.assert_allclose(tau, ref, rtol=0, atol=1e-9)


def test_rnea_derivatives_match_pinocchio(arm):
    """The graph's exact ∂τ/∂(q, q̇, q̈) equal pinocchio's analytic RNEA derivatives."""
    robot, sx = arm
    q, qd, qdd = (ca.SX.sym(s, robot.nq) for s in ("q", "qd", "qdd"))
    tau = sx.rnea(q, qd, qdd)
    jac = ca.Function("J", [q, qd, qdd], [ca.jacobian(tau, v) for v in (q, qd, qdd)])
    for state in _states(robot, 4, n=3):
        ref = pin.computeRNEADerivatives(robot.model, robot.data, *state)
        for got, want in zip(jac(*state), ref):
            np.testing.assert_allclose(np.asarray(got), want, rtol=0, atol=1e-8)


@pytest.mark.parametrize("point", [None, (0.03, -0.02, 0.0)])
def test_blade_kinematics_match_pinocchio(arm, point):
    """Blade frame (or a blade point) position, rotation, velocity and classical acceleration."""
    robot, sx = arm
    q, qd, qdd = (ca.SX.sym(s, robot.nq) for s in ("q", "qd", "qdd"))
    k = sx.frame(q, qd, qdd, point)
    f = ca.Function("k", [q, qd, qdd], [k.p, k.R, k.v, k.a])
    for state in _states(robot, 5):
        st = robot.state(*state, point=point)
        p, R, v, a = (np.asarray(x) for x in f(*state))
        np.testing.assert_allclose(p.ravel(), st.p, atol=1e-12)
        np.testing.assert_allclose(R, st.R, atol=1e-12)
        np.testing.assert_allclose(v.ravel(), st.v, atol=1e-10)
        np.testing.assert_allclose(a.ravel(), st.a, atol=1e-9)
        np.testing.assert_allclose(p.ravel(), robot.position(state[0]) + (
            0 if point is None else robot.rotation(state[0]) @ np.asarray(point)), atol=1e-12)
