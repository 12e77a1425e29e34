"""The plan file: synthetic plans, JSON round trip, validation on load, cell rebuild.

The synthetic plans here (also used by test_verify and test_export) need no optimiser: each
joint follows a rest-to-rest cubic in time, which Hermite–Simpson collocation represents
exactly, and u = RNEA(q, q̇, q̈) with the segment's payload.
"""

import json

import numpy as np
import pytest

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.behaviors.models import Models
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.behaviors import targets as tg
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, PlanFileError
from flipkit.model.ik import solve_pose
from flipkit.model.orientation import rpy
from flipkit.planning.plans.plan_file import FORMAT, Plan
from flipkit.planning.plans.segment import Segment, SolverInfo
from flipkit.solvers.sqp import SolveResult

LOCATION = (0.68, -0.31, 0.072)  # Table I, location 5
BASE_TURN = np.array([0.3, 0, 0, 0, 0, 0])  # rad: a pure base rotation keeps the blade flat


def cubic_segment(name, q0, q1, T, robot, N=20, goal=True):
    """Rest-to-rest cubic q(t) = q0 + (q1 − q0)(3s² − 2s³), s = t/T, with u = RNEA."""
    t = np.linspace(0.0, T, N + 1)
    s, d = t / T, np.asarray(q1, float) - np.asarray(q0, float)
    q = np.asarray(q0, float) + np.outer(3 * s**2 - 2 * s**3, d)
    qd, qdd = np.outer(6 * s - 6 * s**2, d) / T, np.outer(6 - 12 * s, d) / T**2
    u = np.array([robot.inverse_dynamics(*z) for z in zip(q, qd, qdd)])
    pose = None
    if name == "translate" and goal:
        M = robot.placement(q[-1])
        pose = tg.Pose(tuple(M.translation), tuple(rpy(M.rotation)))
    cone = list(range(N + 1)) if name in ("translate", "pickup") else []
    return Segment(name, T, t, q, qd, qdd, u, np.tile(q[:1].T, (1, 7)), cone,
                   SolverInfo("synthetic", "solved", 0, 0.0, float((u**2).sum()), 0.0), pose)


@pytest.fixture(scope="package")
def models():
    return Models(CellConfig())


def translate_plan(models, turns=(BASE_TURN, -BASE_TURN), durations=(1.0, 0.8)):
    """Translate plan: base rotations from q_home, chained, blade flat and level throughout."""
    q, segments = models.bare.q_home, []
    for dq, T in zip(turns, durations):
        segments.append(cubic_segment("translate", q, q + dq, T, models.loaded))
        q = q + dq
    return Plan.from_segments("translate", models.cell, segments)


def chain_plan(models, approach=False):
    """A flip plan without the flip: scoop (held still: blade flat on the grill under the
    burger), pickup, turn back home — or, with ``approach``, only go to burger from home.
    End configurations by tight IK; each segment lasts its behaviour's longest duration."""
    cell, r = models.cell, models.bare
    ready, scoop, pick = (f(cell, LOCATION) for f in (tg.scoop_ready, tg.scoop_end, tg.pickup_end))
    if approach:
        q_ready = solve_pose(r, ready.p, ready.o, r.q_home, tol=1e-22)
        segments = [cubic_segment("go_to_burger", r.q_home, q_ready, SUBBEHAVIORS["go_to_burger"].duration[1],
                                  models.bare)]
    else:
        q_scoop = solve_pose(r, scoop.p, scoop.o, r.q_home, tol=1e-22)
        q_pick = solve_pose(r, pick.p, pick.o, q_scoop, tol=1e-22)
        legs = (("scoop", q_scoop, q_scoop), ("pickup", q_scoop, q_pick),
                ("turn_back", q_pick, r.q_home))
        segments = [cubic_segment(name, qa, qb, SUBBEHAVIORS[name].duration[1], models.for_segment(name))
                    for name, qa, qb in legs]
    return Plan.from_segments("flip", cell, segments, location=LOCATION)


@pytest.fixture
def plan_file(models, tmp_path):
    return translate_plan(models).to_json(tmp_path / "plan.json")


def test_round_trip_is_exact_and_keys_follow_the_format(models, tmp_path):
    plan = translate_plan(models)
    path = plan.to_json(tmp_path / "p.json")
    doc = json.loads(path.read_text())
    assert list(doc) == ["format", "behavior", "status", "created_by", "robot", "gravity",
                         "grill_height", "spatula", "burger", "cone", "segments",
                         "cell_geometry"]
    assert doc["format"] == FORMAT and doc["status"] == "solved"
    assert list(doc["robot"]) == ["urdf", "urdf_sha256", "base_in_world", "tool_parent_frame",
                                  "spatula_in_parent", "payload", "q_home", "arm"]
    assert doc["robot"]["arm"] == {"profile": "ur10", "speed_margin": 0.9,
                                   "safety_preset": "least_restricted"}
    seg = doc["segments"][0]
    assert list(seg) == ["name", "T", "t", "q", "qd", "qdd", "u", "alpha", "cone_nodes",
                         "solver", "payload", "goal"]
    assert np.array(seg["q"]).shape == (21, 6) and np.array(seg["alpha"]).shape == (6, 7)
    assert set(doc["created_by"]) == {"flipkit", "git"}
    back = Plan.load(path)
    for a, b in zip(plan.segments, back.segments):
        for key in ("t", "q", "qd", "qdd", "u", "alpha"):
            np.testing.assert_array_equal(getattr(a, key), getattr(b, key))
        assert a.goal == b.goal and a.cone_nodes == b.cone_nodes and a.solver == b.solver
    assert back.to_json(tmp_path / "again.json").read_text() == path.read_text()


def test_cell_is_rebuilt_from_the_file(models, plan_file):
    cell, ref = Plan.load(plan_file).cell(), models.cell
    assert cell.spatula.thickness == pytest.approx(ref.spatula.thickness, rel=1e-9)
    assert (cell.spatula.length, cell.spatula.width, cell.spatula.handle, cell.spatula.mass) == (
        ref.spatula.length, ref.spatula.width, ref.spatula.handle, ref.spatula.mass)
    assert cell.burger == ref.burger and cell.grill.height == ref.grill.height
    assert cell.robot.urdf_path == ref.robot.urdf_path and cell.gravity == ref.gravity
    robot = Plan.load(plan_file).robot_for("pickup", cell)
    assert len(robot.payload) == 2 and SUBBEHAVIORS["pickup"].carries_burger


def test_payload_that_does_not_match_the_cell_is_rejected(models):
    plan = translate_plan(models)
    plan.robot["payload"][1]["mass"] = 0.2
    with pytest.raises(PlanFileError, match=r"robot.payload\[1\]"):
        plan.robot_for("translate")


def test_segment_from_a_collocation_solution(models):
    goal = flat_pose((0.70, -0.10, 0.25))
    nlp = transcribe("translate", models, models.bare.q_home, goal=goal)
    result = SolveResult(x=nlp.x0, status="max_iter", iterations=3, wall_time_s=0.5,
                         objective=nlp.objective(nlp.x0), max_violation=0.1)
    seg = Segment.from_solution(nlp, result)
    L = nlp.layout
    assert seg.q.shape == seg.u.shape == (21, 6) and seg.alpha.shape == (6, 7)
    assert seg.T == nlp.x0[L.T_index] and seg.t[-1] == pytest.approx(seg.T)
    np.testing.assert_array_equal(seg.qdd, L.nodes(nlp.x0)[:, 2])
    assert seg.cone_nodes == list(range(21)) and seg.goal == goal
    assert seg.solver.status == "max_iter" and seg.solver.name == "sqp"
    assert Plan.from_segments("translate", models.cell, [seg]).status == "failed"


def test_constructors_validate(models):
    seg = translate_plan(models).segments[0]
    base = dict(vars(seg), cone_nodes=[], goal=None)
    with pytest.raises(ConfigError, match="T: expected a positive"):
        Segment(**{**base, "T": -1.0})
    with pytest.raises(ConfigError, match=r"qd: expected shape \(21, 6\), got \(21, 5\)"):
        Segment(**{**base, "qd": seg.qd[:, :5]})
    with pytest.raises(ConfigError, match="u: expected an array of numbers"):
        Segment(**{**base, "u": [["1"] * 6] * 21})
    with pytest.raises(ConfigError, match="goal: only translate"):
        Segment(**{**base, "name": "scoop", "goal": seg.goal})
    with pytest.raises(ConfigError, match="cone_nodes"):
        Segment(**{**base, "name": "pickup", "cone_nodes": [21]})
    with pytest.raises(ConfigError, match="iterations"):
        SolverInfo("sqp", "solved", 2.5, 0.1, 1.0, 0.0)


def _edit(doc, path, value):
    *head, last = path
    for key in head:
        doc = doc[key]
    if value is KeyError:
        del doc[last]
    else:
        doc[last] = value


@pytest.mark.parametrize("path, value, message", [
    (("format",), "flipkit-plan/3", "format: expected one of 'flipkit-plan/1', 'flipkit-plan/2'"),
    (("status",), "done", "status: 'done' is not one of"),
    (("cone",), "round", "cone: 'round' is not one of"),
    (("segments", 0, "qdd"), KeyError, r"segments\[0\].qdd: missing key"),
    (("robot", "q_home"), KeyError, "robot.q_home: missing key"),
    (("segments", 1, "u", 3, 2), float("nan"), r"segments\[1\].u: contains a non-finite"),
    (("segments", 0, "q"), [[0.0] * 6] * 20,
     r"segments\[0\].q: expected shape \(21, n\), got \(20, 6\)"),
    (("segments", 0, "alpha"), [[0.0] * 7] * 5, r"segments\[0\].alpha: expected shape \(6, n\)"),
    (("segments", 1, "name"), "juggle", r"segments\[1\].name: 'juggle' is not one of"),
    (("segments", 0, "solver", "iterations"), -2, r"segments\[0\].solver.iterations"),
    (("segments", 0, "t"), "fast", r"segments\[0\].t: expected an array"),
    (("robot", "base_in_world"), [[1, 0, 0]], r"robot.base_in_world: expected shape \(4, 4\)"),
    (("burger", "mu"), 0.0, "burger.mu: expected a positive"),
    (("behavior",), "flip", "do not fit behavior 'flip'"),
    (("segments",), [], "segments: expected a non-empty list"),
])
def test_malformed_files_raise_one_line_plan_file_errors(plan_file, path, value, message):
    doc = json.loads(plan_file.read_text())
    _edit(doc, path, value)
    plan_file.write_text(json.dumps(doc))
    with pytest.raises(PlanFileError, match=message) as err:
        Plan.load(plan_file)
    assert "\n" not in str(err.value) and str(plan_file) in str(err.value)


@pytest.mark.parametrize("text, message", [
    (None, "cannot read plan file"), ("{not json", "not a JSON file"),
    ("[1, 2]", "top level: expected a JSON object"), ('{"format": 1}', "format: expected"),
])
def test_unreadable_files(tmp_path, text, message):
    path = tmp_path / "plan.json"
    if text is not None:
        path.write_text(text)
    with pytest.raises(PlanFileError, match=message) as err:
        Plan.load(path)
    assert "\n" not in str(err.value)


def test_flip_segments_must_come_in_order(models, tmp_path):
    plan = chain_plan(models)
    doc = json.loads(plan.to_json(tmp_path / "p.json").read_text())
    doc["segments"].reverse()
    (tmp_path / "p.json").write_text(json.dumps(doc))
    with pytest.raises(PlanFileError, match="in this order"):
        Plan.load(tmp_path / "p.json")


def test_the_plan_records_the_cell_it_was_made_in(models, tmp_path):
    """Grill and table areas, limits, margin, walls and the acceleration bound survive the
    file: ``Plan.cell()`` (and so ``flipkit verify``) rebuilds that cell, not the defaults."""
    from dataclasses import replace

    from flipkit.config.cell import TableConfig
    from flipkit.config.space import BACK_WALL, CellBox, SpaceConfig

    hood = CellBox("hood", (0.5, -0.6, 0.9), (1.0, 0.3, 1.0))
    cell = replace(models.cell, table=TableConfig(0.12, (0.25, 0.5), (0.5, 0.75)),
                   space=SpaceConfig(margin=0.03, walls=(BACK_WALL, hood)),
                   robot=replace(models.cell.robot, accel_limit=15.0))
    plan = translate_plan(models)
    plan = Plan.from_segments("translate", cell, plan.segments)
    back = Plan.load(plan.to_json(tmp_path / "p.json")).cell()
    assert back.table == cell.table and back.space == cell.space
    assert back.robot.accel_limit == 15.0 and back.grill == cell.grill and back.limits == cell.limits
    assert back.robot.free_accel_limit == np.inf  # recorded as null: the torques alone
    doc = json.loads((tmp_path / "p.json").read_text())
    assert doc["cell_geometry"]["free_accel_limit"] is None
    del doc["cell_geometry"]["free_accel_limit"]  # written before the free motions' bound:
    (tmp_path / "one.json").write_text(json.dumps(doc))  # one bound for every segment
    assert Plan.load(tmp_path / "one.json").cell().robot.free_accel_limit == 15.0
    del doc["cell_geometry"]  # a file written before the record: today's defaults
    (tmp_path / "old.json").write_text(json.dumps(doc))
    old = Plan.load(tmp_path / "old.json").cell()
    assert old.space == CellConfig().space and old.table == CellConfig().table


@pytest.mark.parametrize("edit, key", [
    (lambda g: g["space"].update(margin=-1.0), "cell_geometry.space"),
    (lambda g: g["table"].pop("x_range"), "cell_geometry.table"),
    (lambda g: g["space"]["walls"][0].update(lower=[0, 0]), "cell_geometry.space"),
    (lambda g: g.update(accel_limit="fast"), "cell_geometry.accel_limit"),
    (lambda g: g.update(free_accel_limit=-1.0), "cell_geometry.free_accel_limit"),
    (lambda g: g.update(free_accel_limit=True), "cell_geometry.free_accel_limit"),
    (lambda g: g.update(jerk_limit=1.0), "cell_geometry: expected the keys"),
    (lambda g: g["grill"].update(height=0.08), "cell_geometry.grill.height"),
    (lambda g: g.pop("limits"), "cell_geometry: expected the keys"),
])
def test_a_malformed_cell_record_is_refused_in_one_line(models, tmp_path, edit, key):
    doc = json.loads(translate_plan(models).to_json(tmp_path / "p.json").read_text())
    edit(doc["cell_geometry"])
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    with pytest.raises(PlanFileError, match=key) as info:
        Plan.load(tmp_path / "bad.json")
    assert "\n" not in str(info.value)


def test_free_motions_are_bounded_by_the_torques_alone(models):
    """Go to burger and turn back get the free motions' acceleration bound (none by default);
    the segments that carry or touch the burger keep the planner's 20 rad/s²."""
    from flipkit.behaviors.spec import Subbehavior

    q = models.cell.robot.q_home
    free = {name: spec.free_motion for name, spec in SUBBEHAVIORS.items()}
    assert {n for n, f in free.items() if f} == {"go_to_burger", "turn_back"}
    for name in ("go_to_burger", "scoop"):
        nlp = transcribe(name, models, q, location=(0.69, -0.16, 0.072))
        qdd = nlp.x_ub[nlp.layout.iqdd(3)]
        limits = next(b for b in nlp.blocks if b.name == "interpolant_limits")
        expected = np.inf if free[name] else models.cell.robot.accel_limit
        np.testing.assert_array_equal(qdd, expected)
        np.testing.assert_array_equal(limits.hi[:6], expected)
    with pytest.raises(ConfigError, match="free motion"):
        Subbehavior("held", (0.2, 0.5), carries_burger=True, free_motion=True, end="rest",
                    guess=lambda *a: None)
    for bad in (0.0, -1.0, float("nan"), "fast"):
        with pytest.raises(ConfigError, match="free_accel_limit"):
            CellConfig().robot.__class__(free_accel_limit=bad)


def test_verify_holds_each_segment_to_its_own_acceleration_bound(flip_plan, tmp_path):
    """A flip plan's free motions accelerate beyond the planner's 20 rad/s²: verify passes them
    in the default cell (no bound for free motions), and fails them in a cell that bounds
    them; a record of such a bound (or a file without the record: the planner's bound for
    every segment) is a plan for another cell, refused in the default one."""
    from dataclasses import replace

    from flipkit.planning.plans.cell_in_use import CellMismatchError
    from flipkit.planning.plans.verify import verify_plan

    go = flip_plan.segment("go_to_burger")
    assert np.abs(go.qdd).max() > flip_plan.cell().robot.accel_limit
    assert verify_plan(flip_plan).ok
    doc = json.loads(flip_plan.to_json(tmp_path / "p.json").read_text())
    for record in (30.0, "absent"):
        if record == "absent":
            del doc["cell_geometry"]["free_accel_limit"]
        else:
            doc["cell_geometry"]["free_accel_limit"] = record
        (tmp_path / "b.json").write_text(json.dumps(doc))
        plan = Plan.load(tmp_path / "b.json")
        with pytest.raises(CellMismatchError, match="cell_geometry.free_accel_limit"):
            verify_plan(plan)
        bound = 20.0 if record == "absent" else record
        cell = replace(CellConfig(), robot=replace(CellConfig().robot, free_accel_limit=bound))
        report = verify_plan(plan, cell=cell)
        worst = report.groups["qdd_limits"]
        assert not worst.ok and report.segments[worst.segment] in ("go_to_burger", "turn_back")
