"""Space limits of the whole arm (issue 13): the cell's boxes, distances of the arm's shapes to
them with gradients checked against finite differences, the NLP block, the segments' pairs,
verify's independent check, and the orientation (pitch) limits of Constraint 1."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import central_fd
from test_plan import models  # noqa: F401  (fixture)
from test_plan import translate_plan

from flipkit.behaviors.clearance import TOOL_SHAPES
from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.behaviors.models import Models
from flipkit.behaviors.transcribe import transcribe
from flipkit.config import CellConfig, TaskLimits
from flipkit.config.space import BACK_WALL, CellBox, SpaceConfig
from flipkit.errors import ConfigError
from flipkit.model.collision import ArmShapes
from flipkit.model.orientation import rpy
from flipkit.planning.plans.verify import verify_plan
from flipkit.planning.plans.verify_clearance import CellGeometry, min_clearances
from flipkit.transcription.constraints.clearance import CAP, ArmClearance
from flipkit.transcription.layout import Evaluation, Layout


@pytest.fixture(scope="module")
def shapes(models):
    return models.shapes


def _random_configurations(robot, seed, n):
    rng = np.random.default_rng(seed)
    return [robot.q_home + rng.uniform(-1.2, 1.2, robot.nq) for _ in range(n)]


# ------------------------------------------------------------------ config
def test_cell_boxes_come_from_the_config():
    cell = CellConfig()
    boxes = {b.name: b for b in cell.boxes()}
    assert set(boxes) == {"grill", "table", "wall"} and cell.space.margin == 0.02
    g, t = boxes["grill"], boxes["table"]
    assert g.upper[2] == cell.grill.height and g.lower[:2] == (0.60, -0.50)
    assert t.upper[2] == cell.table.height and boxes["wall"] == BACK_WALL
    assert np.allclose(g.center, (0.74, -0.17, 0.036)) and np.allclose(g.size, (0.28, 0.66, 0.072))


@pytest.mark.parametrize("bad", [
    dict(margin=-0.01), dict(margin=float("nan")), dict(handle_radius=0.0),
    dict(walls=(CellBox("grill", (0, 0, 0), (1, 1, 1)),)),
    dict(walls=(BACK_WALL, BACK_WALL)), dict(walls=("wall",))])
def test_space_config_rejects_bad_values(bad):
    with pytest.raises(ConfigError):
        SpaceConfig(**bad)


def test_cell_box_needs_ordered_corners():
    with pytest.raises(ConfigError):
        CellBox("hood", (0.5, 0.0, 1.0), (0.4, 0.2, 1.2))


def test_pitch_range_is_checked():
    assert TaskLimits().pitch_range == (-1.2, 1.2)
    for bad in ((0.5, -0.5), (-1.6, 1.0), (-1.0, float("inf"))):
        with pytest.raises(ConfigError):
            TaskLimits(pitch_range=bad)


# ------------------------------------------------------------------ distances
def test_shapes_cover_every_moving_link(shapes):
    assert shapes.names == ("shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3",
                            "ee", "handle", "blade")
    assert set(TOOL_SHAPES) <= set(shapes.names)


def test_distance_matches_a_hand_computed_case(shapes, models):
    """The blade at q_home lies flat 0.30 m above the base, its centre at (0.62, −0.20): its
    underside is 0.30 − 0.003 − 0.072 above the grill's top, and it overhangs the grill area
    (x from 0.54 to 0.70), so that is the distance."""
    q, grill = models.bare.q_home, shapes.box_index("grill")
    d, _ = shapes.distance(q, shapes.shape_index("blade"), grill)
    assert d == pytest.approx(0.30 - 0.003 - 0.072, abs=1e-6)
    # the handle's axis ends at the heel, (0.54, −0.20, 0.30): 6 cm short of the grill's edge
    # x = 0.60, 0.228 m above its top; minus the handle's 1 cm radius
    d, _ = shapes.distance(q, shapes.shape_index("handle"), grill)
    assert d == pytest.approx(np.hypot(0.06, 0.30 - 0.072) - 0.01, abs=2e-4)


FD_H = 1e-5  # m: GJK's tolerance (1e-9 m) over h stays ≤ 1e-4 of the gradients' scale


def _check_pairs(shapes, q, pairs):
    for k, b in pairs:
        _, grad = shapes.distance(q, k, b)
        fd = central_fd(lambda x: shapes.distance(x, k, b)[0], q, h=FD_H)
        np.testing.assert_allclose(grad, fd, atol=2e-5, rtol=1e-4,
                                   err_msg=f"{shapes.names[k]}/{shapes.box_names[b]} at {q}")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_distance_gradients_match_finite_differences(shapes, models, seed):
    """Every (shape, box) pair at random configurations over the joint ranges."""
    robot, rng = models.bare, np.random.default_rng(seed)
    every = [(k, b) for k in range(len(shapes.names)) for b in range(len(shapes.box_names))]
    for q in [rng.uniform(robot.q_min, robot.q_max) for _ in range(4)]:
        _check_pairs(shapes, q, every)


def test_distance_gradients_when_penetrating(shapes, models):
    """Pairs that overlap (coal's EPA depth, negative distance): the same gradient formula."""
    robot, rng, found = models.bare, np.random.default_rng(3), []
    while len(found) < 6:
        q = rng.uniform(robot.q_min, robot.q_max)
        found += [(q, (k, b)) for k in range(len(shapes.names)) for b in range(3)
                  if shapes.distance(q, k, b)[0] < -0.005]
    for q, pair in found[:6]:
        _check_pairs(shapes, q, [pair])


def test_nearest_is_the_exact_minimum(shapes, models):
    """The broad phase never drops the nearest pair; the cap reads far configurations as CAP."""
    pairs = np.array([(k, b) for k in range(len(shapes.names)) for b in range(3)])
    for q in _random_configurations(models.bare, 5, 20):
        every = min(shapes.distance(q, k, b)[0] for k, b in pairs)
        d, grad, k, b = shapes.nearest(q, pairs)
        assert d == pytest.approx(every, abs=1e-12)
        np.testing.assert_allclose(grad, shapes.distance(q, k, b)[1])
        capped = shapes.nearest(q, pairs, cap=0.05)
        assert capped[0] == pytest.approx(min(every, 0.05), abs=1e-12)
        if every > 0.05:
            assert capped[2] == -1 and not capped[1].any()


# ------------------------------------------------------------------ NLP block
def test_block_jacobian_matches_finite_differences(models, shapes):
    L, robot = Layout(6, 20), models.bare
    rng = np.random.default_rng(7)
    q = np.array(_random_configurations(robot, 8, L.n_nodes))
    x = L.pack(q, rng.normal(size=q.shape), rng.normal(size=q.shape), rng.normal(size=q.shape),
               rng.normal(size=(6, 7)), 0.5)
    block = ArmClearance(L, shapes, range(1, L.n_nodes), lambda i: SUBBEHAVIORS["flip"].exempt(i, 20))
    vals, jac = block.evaluate(Evaluation(L, robot, x))
    assert block.m == 20 and np.all(vals <= CAP) and np.any(vals < 0.02)
    J = np.zeros((block.m, L.n))
    J[block.rows, block.cols] = jac
    fd = central_fd(lambda z: block.evaluate(Evaluation(L, robot, z))[0], x, h=FD_H)
    np.testing.assert_allclose(J, fd, atol=2e-5, rtol=1e-4)
    assert np.all(block.lo == 0.02) and np.all(np.isinf(block.hi))


def test_pitch_rows_match_finite_differences(models):
    """The orientation rows (Constraint 1): pitch o_y and its Jacobian, through a flip-like
    roll past ±π where o_x wraps and o_y does not."""
    from flipkit.transcription.constraints.kinematic import KinematicBlock

    L, robot = Layout(6, 20), models.bare
    q = robot.q_home + np.outer(np.linspace(0, 1, L.n_nodes), [0.2, -0.3, 0.4, 0.5, 0.1, -3.6])
    z = np.zeros_like(q)
    x = L.pack(q, z, z, z, np.zeros((6, 7)), 0.5)
    block = KinematicBlock("task_orientation", L, "pitch", range(1, L.n_nodes), -1.2, 1.2)
    vals, jac = block.evaluate(Evaluation(L, robot, x))
    np.testing.assert_allclose(vals, [rpy(robot.rotation(qi))[1] for qi in q[1:]])
    J = np.zeros((block.m, L.n))
    J[block.rows, block.cols] = jac
    fd = central_fd(lambda v: block.evaluate(Evaluation(L, robot, v))[0], x, h=1e-6)
    np.testing.assert_allclose(J, fd, atol=1e-6, rtol=1e-6)


def test_block_rejects_unknown_names_and_bad_margins(models, shapes):
    L = Layout(6, 20)
    with pytest.raises(ConfigError, match="no arm shape"):
        ArmClearance(L, shapes, [1], {("elbow", "grill")})
    with pytest.raises(ConfigError, match="no cell box"):
        ArmClearance(L, shapes, [1], {("blade", "hood")})
    with pytest.raises(ConfigError):
        ArmClearance(L, shapes, [1], margin=CAP)


def test_segments_exempt_only_the_tool_at_the_grill(models):
    """Scoop-like segments exempt the tool end from the grill; the flip from its first quarter
    on holds it; the other links keep the margin everywhere, the table and wall always."""
    tool = {(s, "grill") for s in TOOL_SHAPES}
    for name in ("go_to_burger", "scoop", "pickup"):
        assert SUBBEHAVIORS[name].exempt(20, 20) == tool
    for name in ("flip", "carry"):  # both start where the pickup ends
        assert SUBBEHAVIORS[name].exempt(4, 20) == tool and SUBBEHAVIORS[name].exempt(5, 20) == set()
    for name in ("translate", "turn_back"):
        assert SUBBEHAVIORS[name].exempt(1, 20) == set()
    nlp = transcribe("translate", models, models.bare.q_home,
                        goal=translate_plan(models).segments[0].goal)
    block = next(b for b in nlp.blocks if b.name == "arm_clearance")
    assert block.m == 20 and all(len(p) == 27 for p in block.pairs)
    assert any(b.name == "task_orientation" for b in nlp.blocks)


def test_a_hood_over_the_elbow_is_seen_by_the_block(models):
    """A hood box hung just above where the elbow goes in a translate: the initial guess
    breaks the clearance rows, and the nearest pair is a link of the arm, not the blade."""
    plan = translate_plan(models)
    robot, seg = models.bare, plan.segments[0]
    robot.placement(seg.q[10])
    elbow = robot.data.oMi[3].translation  # the elbow joint (forearm's origin)
    hood = CellBox("hood", (elbow[0] - 0.3, elbow[1] - 0.3, elbow[2] + 0.03),
                   (elbow[0] + 0.3, elbow[1] + 0.3, elbow[2] + 0.3))
    cell = replace(models.cell, space=SpaceConfig(walls=(BACK_WALL, hood)))
    hooded = Models(cell)
    nlp = transcribe("translate", hooded, seg.q[0], goal=seg.goal)
    block = next(b for b in nlp.blocks if b.name == "arm_clearance")
    L = nlp.layout
    x = L.pack(seg.q, seg.qd, seg.qdd, seg.u, np.zeros((6, 7)), seg.T)
    vals, _ = block.evaluate(Evaluation(L, robot, x))
    assert vals.min() < 0.02
    shape, box = block.nearest[int(np.argmin(vals))]
    assert hooded.shapes.box_names[box] == "hood"
    assert hooded.shapes.names[shape] in ("upper_arm", "forearm")
    # verify, told of the hood, fails the same plan; without it the plan passes
    assert verify_plan(plan).groups["arm_clearance"].ok
    report = verify_plan(plan, space=cell.space)
    # both segments pass under the hood (out and back along the same arc): either is worst
    assert not report.groups["arm_clearance"].ok and report.groups["arm_clearance"].segment in (0, 1)


# ------------------------------------------------------------------ verify
def _tampered(models, box: str):
    """A translate plan one of whose nodes puts a link of the arm into ``box``."""
    plan = translate_plan(models)
    geometry = CellGeometry(models.bare, models.cell)
    b = geometry.box_names.index(box)
    arm = [geometry.shape_names.index(s) for s in ("upper_arm", "forearm", "wrist_1")]
    rng = np.random.default_rng(11)
    for _ in range(3000):
        q = rng.uniform(models.bare.q_min, models.bare.q_max)
        d = geometry.distances(q)[:, b]
        if d[arm].min() < -0.01:
            plan.segments[0].q[7] = q
            return plan, float(d.min())
    raise AssertionError(f"no configuration of the arm found inside the {box}")


@pytest.mark.parametrize("box", ["table", "wall"])
def test_verify_fails_a_link_inside_a_box(models, box):
    plan = translate_plan(models)
    report = verify_plan(plan)
    assert report.groups["arm_clearance"].ok and report.groups["orientation"].ok
    plan, depth = _tampered(models, box)
    report = verify_plan(plan)
    g = report.groups["arm_clearance"]
    assert not g.ok and (g.segment, g.node) == (0, 7)
    assert g.violation >= 0.02 - depth - 1e-9  # the margin plus at least that depth


def test_verify_fails_a_pitch_beyond_the_limit(models):
    plan = translate_plan(models)
    seg, robot = plan.segments[0], models.bare
    seg.q[5] = robot.q_home - np.array([0, 0, 0, 1.5, 0, 0])  # wrist 1: pitch −0.58, roll −1.49
    assert verify_plan(plan).groups["orientation"].ok  # inside ±1.2 rad
    for turn in np.linspace(0.0, 3.0, 31):  # wrist 2 turns the rolled blade into pitch
        seg.q[5] = robot.q_home - np.array([0, 0, 0, 1.5, -turn, 0])
        if abs(rpy(robot.rotation(seg.q[5]))[1]) > 1.3:
            break
    assert abs(rpy(robot.rotation(seg.q[5]))[1]) > 1.3
    report = verify_plan(plan)
    assert not report.groups["orientation"].ok and report.groups["orientation"].node == 5


def test_min_clearances_report_every_applied_pair(models):
    plan = translate_plan(models)
    table = min_clearances(plan)
    assert len(table) == 27 and all(v["distance"] > 0.02 for v in table.values())
    assert table["blade/grill"]["distance"] == pytest.approx(0.225, abs=0.01)


# ------------------------------------------------------------------ planning
def test_a_hood_where_the_elbow_goes_is_refused_or_avoided(models):
    """A hood box around the elbow's place at the end of a translate (README's example): the
    planner either refuses (a failed plan naming the clearance) or finds a motion that keeps
    every link 2 cm from it — never a solved plan through the hood."""
    from flipkit.planning.planners.planner import plan_translate

    start, goal = (0.64, -0.33, 0.15), (0.75, 0.0, 0.15)
    free = plan_translate(start, goal, solver="sqp")
    assert free.status == "solved", free.failure
    robot = models.bare
    robot.placement(free.segments[0].q[-1])
    elbow = robot.data.oMi[3].translation.copy()
    hood = CellBox("hood", tuple(elbow + (-0.2, -0.2, 0.0)), tuple(elbow + (0.2, 0.2, 0.3)))
    space = SpaceConfig(walls=(BACK_WALL, hood))
    report = verify_plan(free, space=space)  # the free plan's elbow goes into the hood
    assert not report.groups["arm_clearance"].ok
    hooded = plan_translate(start, goal, cell=replace(models.cell, space=space), solver="sqp")
    if hooded.status == "solved":
        d = min_clearances_in(hooded, space)
        assert d >= 0.02 - 1e-5
    else:
        assert "arm_clearance" in hooded.failure or "end_" in hooded.failure, hooded.failure


def min_clearances_in(plan, space):
    """Least applied distance (m) of ``plan`` against ``space``."""
    report = verify_plan(plan, space=space)
    assert report.groups["arm_clearance"].ok, report.table()
    cell = replace(plan.cell(), space=space)
    geometry = CellGeometry(plan.robot_for(plan.segments[0], cell), cell)
    return min(geometry.distances(q)[:, -1].min() for seg in plan.segments for q in seg.q[1:])


def test_nearest_at_many_configurations_is_the_least_pair_distance(shapes, models):
    """ArmShapes.nearest_nodes (the NLP block's batched broad phase; nearest is it at one
    configuration) gives, configuration by configuration, the least of the pairwise distances
    (ArmShapes.distance, one coal query per pair): distance, gradient and nearest pair, under
    random pair masks and caps (a cap below every distance: the cap, −1 and a zero gradient)."""
    rng = np.random.default_rng(7)
    qs = np.array(_random_configurations(models.bare, 11, 12))
    S, B = len(shapes.names), len(shapes.box_names)
    for cap in (CAP, 0.05, 1e-6):
        allowed = rng.uniform(size=(len(qs), S, B)) < 0.7
        allowed[0] = True
        d, g, k, b = shapes.nearest_nodes(qs, allowed, cap)
        for i, q in enumerate(qs):
            pairs = [tuple(p) for p in np.argwhere(allowed[i])]
            each = {p: shapes.distance(q, *p) for p in pairs}
            p_min = min(pairs, key=lambda p: each[p][0])
            if each[p_min][0] < cap:
                d1, g1, (k1, b1) = each[p_min][0], each[p_min][1], p_min
            else:
                d1, g1, (k1, b1) = cap, np.zeros(models.bare.nq), (-1, -1)
            assert d[i] == pytest.approx(d1, abs=1e-12) and (k[i], b[i]) == (k1, b1)
            np.testing.assert_allclose(g[i], g1, atol=1e-10)
            d2, g2, k2, b2 = shapes.nearest(q, np.array(pairs).reshape(-1, 2), cap)
            assert (d2, k2, b2) == (d[i], k[i], b[i]) and np.array_equal(g2, g[i])
    assert np.all(k == -1) and np.all(d == 1e-6) and not g.any()  # cap 1e-6: every pair beyond


def test_verify_skips_only_pairs_surely_beyond_the_floor(models):
    """CellGeometry.distances with a floor measures every pair that could lie nearer than the
    floor exactly and gives the others a lower bound at or above it, so verify's check of the
    margin reads the same as with every pair measured."""
    cell = CellConfig()
    geometry = CellGeometry(models.bare, cell)
    hits = 0
    for q in _random_configurations(models.bare, 5, 40):
        exact = geometry.distances(q)
        for floor in (cell.space.margin, 0.1):
            got = geometry.distances(q, floor)
            near = exact < floor
            np.testing.assert_allclose(got[near], exact[near], atol=1e-12)
            assert np.all(got[~near] >= np.minimum(exact[~near], floor) - 1e-12)
            assert np.all(got <= exact + 1e-12)  # a lower bound or the distance itself
            hits += int(near.sum())
    assert hits > 0  # some pairs did come within the floor
