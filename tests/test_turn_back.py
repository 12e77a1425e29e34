"""The turn back from a flip at the far half of the grill.

There the flip ended on its end margin (cell.space.margin + FLIP_END_ALLOWANCE) with the wrist
housings coming down on the grill at ~1.2 m/s; the turn back starts with that velocity and
could not brake clear by its first node (0.06 s later): the SQP and IPOPT both stopped
locally infeasible, 1-10 mm short, and ``auto`` then spent minutes in IPOPT. The flip now
holds the arm's coasting configuration q_N + τ q̇_N (τ the turn back's first node interval
at its longest) to the margin (:class:`~flipkit.transcription.constraints.clearance.CoastingClearance`).
"""

import numpy as np
import pytest
from conftest import central_fd
from test_plan import models  # noqa: F401  (fixture)

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.behaviors.options import T_STRETCH
from flipkit.behaviors.transcribe import transcribe
from flipkit.errors import ConfigError
from flipkit.transcription.constraints.clearance import CAP, CoastingClearance
from flipkit.transcription.layout import Evaluation, Layout

FAR_GRILL = (0.84, -0.22, 0.072)  # a flip ending here left no turn back (before the fix)


def test_coasting_row_is_the_distance_ahead_with_its_jacobian(models):
    """The row is the least distance at q_N + τ q̇_N and its Jacobian (on q_N and q̇_N) matches
    finite differences, where the arm comes close to the grill."""
    L, robot, shapes = Layout(6, 20), models.bare, models.shapes
    rng = np.random.default_rng(3)
    q = np.tile(robot.q_home, (L.n_nodes, 1))
    # near the grill: the flip's end at FAR_GRILL measured before the fix, moving down
    q[-1] = [-0.86, -1.10, 2.04, -2.12, 0.13, 0.01]
    qd = rng.normal(scale=0.1, size=q.shape)
    qd[-1] = [-0.03, 2.13, 0.02, -3.17, -1.65, -2.58]
    x = L.pack(q, qd, np.zeros_like(q), np.zeros_like(q), rng.normal(size=(6, 7)), 0.6)
    tau = SUBBEHAVIORS["turn_back"].duration[1] / L.N
    block = CoastingClearance(L, shapes, L.N, tau, SUBBEHAVIORS["flip"].exempt(L.N, L.N), 0.02)
    vals, jac = block.evaluate(Evaluation(L, robot, x))
    pairs = np.array([(k, b) for k in range(len(shapes.names))
                      for b in range(len(shapes.box_names))])
    ahead = shapes.nearest(q[-1] + tau * qd[-1], pairs, CAP)[0]
    now = shapes.nearest(q[-1], pairs, CAP)[0]
    assert vals[0] == pytest.approx(ahead) and vals[0] < now  # coming closer
    J = np.zeros((1, L.n))
    J[block.rows, block.cols] = jac
    fd = central_fd(lambda z: block.evaluate(Evaluation(L, robot, z))[0], x, h=1e-5)  # GJK's tolerance over h
    np.testing.assert_allclose(J, fd, atol=2e-5, rtol=1e-4)
    assert block.lo[0] == 0.02 and np.isinf(block.hi[0])
    with pytest.raises(ConfigError):
        CoastingClearance(L, shapes, L.N, 0.0)
    with pytest.raises(ConfigError, match="no cell box"):
        CoastingClearance(L, shapes, L.N, tau, {("blade", "hood")})


def test_only_the_flip_has_the_coasting_row(models):
    """At the flip's last node, with the turn back's first node interval at its longest (its
    bound stretched); not in the turn back, nor without the arm clearance (the
    exact-derivative solvers' problem)."""
    from flipkit.behaviors import targets as tg
    from flipkit.behaviors.options import T_STRETCH, SegmentOptions
    from flipkit.model.ik import solve_pose

    robot = models.bare
    pose = tg.pickup_end(models.cell, np.asarray(FAR_GRILL))
    q = solve_pose(models.loaded, pose.p, pose.o, robot.q_home)
    flip = transcribe("flip", models, q, location=FAR_GRILL)
    rows = [b for b in flip.blocks if b.name == "coasting_clearance"]
    assert len(rows) == 1 and rows[0].node == flip.layout.N
    assert rows[0].tau == pytest.approx(
        T_STRETCH * SUBBEHAVIORS["turn_back"].duration[1] / flip.layout.N)
    back = transcribe("turn_back", models, q, location=FAR_GRILL)
    bare = transcribe("flip", models, q, location=FAR_GRILL,
                         options=SegmentOptions(arm_clearance=False))
    assert not [b for nlp in (back, bare) for b in nlp.blocks if b.name == "coasting_clearance"]


def test_sqp_turns_back_from_a_far_grill_flip():
    """The whole chain at a far-grill location with the SQP alone: every segment solved by
    the SQP, the turn back within 40 iterations and within its (possibly stretched) bound,
    and the plan verified; the flip ends where coasting keeps the margin."""
    from flipkit.behaviors.models import Models
    from flipkit.planning.planners.planner import plan_flip
    from flipkit.config import CellConfig

    plan = plan_flip(FAR_GRILL, solver="sqp")
    assert plan.status == "solved", plan.failure
    assert plan.report.ok
    names = [s.name for s in plan.segments]
    assert names[-1] == "turn_back"
    tb = plan.segments[-1]
    assert tb.solver.name == "sqp" and tb.solver.iterations <= 40
    assert tb.T <= T_STRETCH * SUBBEHAVIORS["turn_back"].duration[1] + 1e-9
    flip = plan.segments[names.index("flip")]
    shapes = Models(CellConfig()).shapes
    pairs = np.array([(k, b) for k in range(len(shapes.names))
                      for b in range(len(shapes.box_names))])
    tau = SUBBEHAVIORS["turn_back"].duration[1] / (len(flip.t) - 1)
    d = shapes.nearest(flip.q[-1] + tau * flip.qd[-1], pairs, CAP)[0]
    assert d >= 0.02 - 1e-6


GRILL_CORNER = (0.875, -0.495, 0.072)  # a cook's flip here left no turn back (before the fix)


def test_coasting_floor_rows_are_the_corner_heights_ahead_with_their_jacobian(models):
    """Four rows, the blade's corner heights at q_N + τ q̇_N (computed here from the spatula's
    placement), with a Jacobian on q_N and q̇_N that matches central differences."""
    from flipkit.transcription.constraints.coasting_floor import CoastingFloor
    from flipkit.model.robot import BLADE_CORNERS

    L, robot, cell = Layout(6, 20), models.bare, models.cell
    rng = np.random.default_rng(5)
    q = np.tile(robot.q_home, (L.n_nodes, 1)) + rng.normal(scale=0.2, size=(L.n_nodes, 6))
    qd = rng.normal(scale=1.0, size=q.shape)
    x = L.pack(q, qd, np.zeros_like(q), np.zeros_like(q), rng.normal(size=(6, 7)), 0.6)
    tau, l, w = 0.042, cell.spatula.length, cell.spatula.width
    block = CoastingFloor(L, L.N, tau, 0.089, l, w)
    vals, jac = block.evaluate(Evaluation(L, robot, x))
    M = robot.placement(q[-1] + tau * qd[-1])
    expect = [(M.translation + M.rotation @ np.array([a * l / 2, b * w / 2, 0.0]))[2]
              for a, b in BLADE_CORNERS]
    np.testing.assert_allclose(vals, expect, atol=1e-12)
    J = np.zeros((4, L.n))
    J[block.rows, block.cols] = jac
    fd = central_fd(lambda z: block.evaluate(Evaluation(L, robot, z))[0], x, h=1e-6)
    np.testing.assert_allclose(J, fd, atol=1e-6, rtol=1e-6)
    assert np.all(block.lo == 0.089) and np.all(np.isinf(block.hi))
    with pytest.raises(ConfigError, match="coasting time"):
        CoastingFloor(L, L.N, 0.0, 0.089, l, w)
    with pytest.raises(ConfigError, match="coasting floor"):
        CoastingFloor(L, L.N, tau, np.nan, l, w)


def test_the_flip_ends_where_the_turn_back_floor_is_reachable(models):
    """The flip's last node carries the turn back's floor at its first node, coasting for the
    turn back's first interval at its longest; the turn back itself has no such rows."""
    from flipkit.behaviors import targets as tg
    from flipkit.behaviors.flip import above_burger
    from flipkit.model.ik import solve_pose

    pose = tg.pickup_end(models.cell, np.asarray(FAR_GRILL))
    q = solve_pose(models.loaded, pose.p, pose.o, models.bare.q_home)
    flip = transcribe("flip", models, q, location=FAR_GRILL)
    rows = [b for b in flip.blocks if b.name == "coasting_floor"]
    assert len(rows) == 1 and rows[0].node == flip.layout.N
    assert rows[0].tau == pytest.approx(
        T_STRETCH * SUBBEHAVIORS["turn_back"].duration[1] / flip.layout.N)
    assert np.all(rows[0].lo == above_burger(models.cell, flip.layout.N)[1])
    back = transcribe("turn_back", models, q, location=FAR_GRILL)
    assert not [b for b in back.blocks if b.name == "coasting_floor"]


def test_a_cook_flip_at_the_grill_corner_turns_back():
    """At the grill area's corner, coming in above other burgers as a cook's flips do, the
    whole chain solves with the SQP alone, and the flip ends with its coasting corners above
    the turn back's floor."""
    from flipkit.behaviors.flip import above_burger
    from flipkit.config import CellConfig
    from flipkit.planning.kitchen.sweep import approach_height
    from flipkit.planning.planners.planner import plan_flip
    from flipkit.model.robot import BLADE_CORNERS

    cell = CellConfig()
    plan = plan_flip(GRILL_CORNER, solver="sqp", approach_height=approach_height(cell))
    assert plan.status == "solved", plan.failure
    assert plan.report.ok and [s.solver.name for s in plan.segments] == ["sqp"] * 5
    flip = plan.segments[[s.name for s in plan.segments].index("flip")]
    tau = T_STRETCH * SUBBEHAVIORS["turn_back"].duration[1] / (len(flip.t) - 1)
    M = plan.robot_for(flip).placement(flip.q[-1] + tau * flip.qd[-1])
    l, w = cell.spatula.length, cell.spatula.width
    lowest = min((M.translation + M.rotation @ np.array([a * l / 2, b * w / 2, 0.0]))[2]
                 for a, b in BLADE_CORNERS)
    assert lowest >= above_burger(cell, 1)[0] - 1e-6
