"""Every analytic Jacobian against central finite differences on the UR10 + spatula.

Tolerances: 1e-6 absolute (plus 1e-6 relative) for kinematic quantities, central differences
with h = 1e-6 have truncation error O(h²) ≈ 1e-12 and round-off ≈ 1e-10/h ≈ 1e-4·ε-scaled, so
1e-6 leaves margin while catching any missing term (those are O(1)).
"""

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_fd, check_block_jacobian, random_states

from flipkit.model.contact import make_cone
from flipkit.model.orientation import axis_jacobian, rpy_jacobian

TOL = dict(atol=1e-6, rtol=1e-6)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_position_and_angular_jacobian(robot, seed):
    for q, _, _ in random_states(robot, seed):
        p, R, dp_dq, Jw = robot.pose_jacobians(q)
        np.testing.assert_allclose(dp_dq, central_fd(robot.position, q), **TOL)
        # dR = [Jw dq]x R  <=>  Jw[:, k] = log(R(q+h e_k) R(q-h e_k)^T) / 2h
        cols = []
        for k in range(robot.nq):
            e = np.zeros(robot.nq)
            e[k] = 1e-6
            cols.append(pin.log3(robot.rotation(q + e) @ robot.rotation(q - e).T) / 2e-6)
        np.testing.assert_allclose(Jw, np.stack(cols, 1), **TOL)


@pytest.mark.parametrize("seed", [3, 4])
def test_velocity_and_acceleration_jacobians(robot, seed):
    for q, qd, qdd in random_states(robot, seed):
        st = robot.state(q, qd, qdd)
        np.testing.assert_allclose(st.v, central_fd(robot.position, q) @ qd, **TOL)
        fv = lambda x: robot.state(x[:6], x[6:12], x[12:]).v
        fa = lambda x: robot.state(x[:6], x[6:12], x[12:]).a
        x = np.concatenate([q, qd, qdd])
        Jv, Ja = central_fd(fv, x), central_fd(fa, x)
        np.testing.assert_allclose(st.dv_dq, Jv[:, :6], **TOL)
        np.testing.assert_allclose(st.dv_dqd, Jv[:, 6:12], **TOL)
        np.testing.assert_allclose(st.da_dq, Ja[:, :6], atol=1e-5, rtol=1e-6)
        np.testing.assert_allclose(st.da_dqd, Ja[:, 6:12], **TOL)
        np.testing.assert_allclose(st.da_dqdd, Ja[:, 12:], **TOL)


def test_classical_acceleration_is_second_time_derivative(robot):
    """a = d²p/dt² along q(t) = q0 + qd t + qdd t²/2 (checks a is *classical*, not spatial)."""
    for q, qd, qdd in random_states(robot, 5):
        path = lambda t: robot.position(q + qd * t + 0.5 * qdd * t * t)
        h = 1e-4
        a_fd = (path(h) - 2 * path(0.0) + path(-h)) / h**2
        np.testing.assert_allclose(robot.state(q, qd, qdd).a, a_fd, atol=1e-5)


@pytest.mark.parametrize("seed", [6, 7])
def test_orientation_jacobians(robot, seed):
    for q, _, _ in random_states(robot, seed):
        _, R, _, Jw = robot.pose_jacobians(q)
        o, do_dq = rpy_jacobian(R, Jw)
        np.testing.assert_allclose(do_dq, central_fd(lambda x: rpy_jacobian(
            robot.rotation(x), np.zeros((3, 6)))[0], q), **TOL)
        for k in (0, 2):
            _, da = axis_jacobian(R, Jw, k)
            np.testing.assert_allclose(da, central_fd(lambda x: robot.rotation(x)[:, k], q), **TOL)


@pytest.mark.parametrize("form", ["physical", "paper"])
def test_cone_jacobians(robot, cell, form):
    cone = make_cone(form, cell.burger.mu, cell.gravity)
    for q, qd, qdd in random_states(robot, 8):
        h, dq, dqd, dqdd = cone.jacobians(robot.state(q, qd, qdd))
        f = lambda x: cone.values(robot.state(x[:6], x[6:12], x[12:]))
        J = central_fd(f, np.concatenate([q, qd, qdd]))
        np.testing.assert_allclose(np.hstack([dq, dqd, dqdd]), J, atol=1e-5, rtol=1e-6)


@pytest.mark.parametrize("seed", [9, 10])
def test_dynamics_residual_jacobians(robot, seed):
    for q, qd, qdd in random_states(robot, seed):
        tau, dq, dqd, dqdd, du = robot.dynamics_residual_jacobians(q, qd, qdd)
        u = np.ones(6)
        f = lambda x: robot.dynamics_residual(x[:6], x[6:12], x[12:18], x[18:])
        J = central_fd(f, np.concatenate([q, qd, qdd, u]))
        np.testing.assert_allclose(np.hstack([dq, dqd, dqdd, du]), J, atol=1e-5, rtol=1e-6)
        np.testing.assert_allclose(tau, robot.inverse_dynamics(q, qd, qdd))


@pytest.mark.parametrize("seed", [5, 6])
def test_blade_point_state_jacobians(robot, seed):
    """A blade point off the centre (where a dragged burger lies): position, velocity and
    acceleration values and Jacobians against central differences."""
    point = np.array([0.05, -0.012, 0.0])
    for q, qd, qdd in random_states(robot, seed, n=3):
        st = robot.state(q, qd, qdd, point)
        centre = robot.state(q, qd, qdd)
        np.testing.assert_allclose(st.p, centre.p + centre.R @ point, **TOL)
        np.testing.assert_allclose(st.dp_dq, central_fd(lambda x: robot.state(x, qd, qdd, point).p, q), **TOL)
        np.testing.assert_allclose(st.v, st.dp_dq @ qd, **TOL)
        x = np.concatenate([q, qd, qdd])
        fa = central_fd(lambda z: robot.state(z[:6], z[6:12], z[12:], point).a, x)
        np.testing.assert_allclose(np.hstack([st.da_dq, st.da_dqd, st.da_dqdd]), fa, **TOL)
        fv = central_fd(lambda z: robot.state(z[:6], z[6:12], qdd, point).v, x[:12])
        np.testing.assert_allclose(np.hstack([st.dv_dq, st.dv_dqd]), fv, **TOL)
        np.testing.assert_allclose(st.a, fv[:, :6] @ qd + fv[:, 6:] @ qdd, atol=1e-6)


def test_states_of_a_batch_are_the_single_node_states(robot):
    """Robot.states (one pass per node for the centre and every blade point) gives, bit for
    bit, Robot.state at each node and point."""
    states = list(random_states(robot, 11, n=4))
    q, qd, qdd = (np.array([s[k] for s in states]) for k in range(3))
    points = [np.array([0.05, -0.012, 0.0]), np.array([-0.02, 0.03, 0.0])]
    centre, at_points = robot.states(q, qd, qdd, points)
    for k in range(len(q)):
        for st, point in [(centre, None), *zip(at_points, points)]:
            one = robot.state(q[k], qd[k], qdd[k], point)
            for name in ("p", "R", "v", "a", "dp_dq", "Jw", "dv_dq", "dv_dqd", "da_dq",
                         "da_dqd", "da_dqdd"):
                np.testing.assert_array_equal(getattr(st.take(k), name), getattr(one, name))


@pytest.fixture(scope="module")
def flip_nlp():
    from flipkit.behaviors.models import Models
    from flipkit.behaviors.targets import pickup_end
    from flipkit.behaviors.transcribe import transcribe
    from flipkit.config import CellConfig
    from flipkit.model.ik import solve_pose

    cell = CellConfig()
    models = Models(cell)
    pb = np.array([0.69, -0.16, 0.072])
    pose = pickup_end(cell, pb)
    q0 = solve_pose(models.loaded, pose.p, pose.o, models.loaded.q_home)
    return transcribe("flip", models, q0, np.zeros(6), location=pb, on_blade=(0.03, 0.0),
                      scenarios=[(0.02, 0.0), (0.045, 0.0), (0.03, -0.01)])


@pytest.mark.parametrize("quantity", ["position", "height", "rpy", "pitch", "normal", "xaxis",
                                      "tip_height", "tip_position", "blade_heights", "velocity",
                                      "acceleration", "cone_centre", "cone_point",
                                      "paper_cone_point"])
def test_kinematic_block_over_nodes_jacobian(flip_nlp, cell, quantity):
    """Every quantity evaluated over a batch of nodes (not contiguous) against central
    differences, through the NLP's Evaluation that computes the blade points with the
    centre."""
    from flipkit.transcription.constraints.kinematic import KinematicBlock
    from flipkit.transcription.constraints.quantities import Cone

    if quantity.startswith(("cone", "paper")):
        form = "paper" if quantity.startswith("paper") else "physical"
        point = (0.04, -0.01, 0.0) if quantity.endswith("point") else None
        quantity = Cone(make_cone(form, cell.burger.mu, cell.gravity), point)
    ctx = {"length": cell.spatula.length, "width": cell.spatula.width}
    block = KinematicBlock("q", flip_nlp.layout, quantity, [0, 3, 4, 9, 20], -np.inf, np.inf,
                           ctx=ctx)
    check_block_jacobian(flip_nlp, block, seed=3)


def test_node_by_node_quantity_matches_its_batch(flip_nlp, cell):
    """A quantity without broadcasting is applied node by node: the same rows as the built-in
    one it wraps."""
    from flipkit.transcription.constraints.kinematic import KinematicBlock
    from flipkit.transcription.constraints.quantities import BladeCornerHeights
    from flipkit.transcription.layout import Evaluation

    class PerNode(BladeCornerHeights):
        broadcasts = False

    ctx = {"length": cell.spatula.length, "width": cell.spatula.width}
    L, x = flip_nlp.layout, flip_nlp.x0
    ev = Evaluation(L, flip_nlp.robot, x)
    a = KinematicBlock("a", L, BladeCornerHeights(), [1, 2, 7], 0, np.inf, ctx=ctx).evaluate(ev)
    b = KinematicBlock("b", L, PerNode(), [1, 2, 7], 0, np.inf, ctx=ctx).evaluate(ev)
    for u, v in zip(a, b):
        np.testing.assert_array_equal(u, v)


def test_the_corner_heights_are_the_lowest_points_of_the_rolled_blade(flip_nlp, cell):
    """The grill_clearance rows hold the whole blade: at random joint states their smallest
    value is the lowest point of a dense grid over the blade rectangle, which an edge's
    midpoint misses once the blade rolls."""
    from flipkit.transcription.constraints.quantities import BladeCornerHeights
    from flipkit.transcription.layout import Evaluation

    ctx = {"length": cell.spatula.length, "width": cell.spatula.width}
    L, robot = flip_nlp.layout, flip_nlp.robot
    rng = np.random.default_rng(7)
    u, v = np.meshgrid(np.linspace(-0.5, 0.5, 21), np.linspace(-0.5, 0.5, 21))
    grid = np.stack([u.ravel() * ctx["length"], v.ravel() * ctx["width"],
                     np.zeros(u.size)])  # (3, 441) blade frame
    below_midpoints = 0
    for _ in range(5):
        x = flip_nlp.x0 + rng.normal(scale=0.3, size=flip_nlp.n) * (L.n_nodes > 0)
        st = Evaluation(L, robot, x).state(3)
        corners = BladeCornerHeights()(st, ctx)[0]
        lowest = st.p[2] + (st.R @ grid)[2].min()
        assert corners.min() == pytest.approx(lowest, abs=1e-12)
        mids = st.p[2] + (st.R @ np.array([[0.5, -0.5, 0, 0], [0, 0, 0.5, -0.5], [0, 0, 0, 0]])
                          * np.array([[ctx["length"]], [ctx["width"]], [0]]))[2]
        below_midpoints += corners.min() < mids.min() - 1e-6
    assert below_midpoints >= 1  # a rolled blade's corner is lower than every midpoint
