"""Behaviours as data: the specs validate, the library holds every behaviour, transcribing
checks the task, and a new subbehaviour is one spec that the one planner chains and that
``verify`` checks like the others."""

from __future__ import annotations

import copy
import json
from dataclasses import replace
from importlib import resources

import numpy as np
import pytest

from flipkit.behaviors import library
from flipkit.behaviors.guesses import end_pose_guess
from flipkit.behaviors.models import Models
from flipkit.behaviors.spec import Behavior, Subbehavior, Task
from flipkit.behaviors.transcribe import blade_floor, flat_pose, transcribe
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.model.ik import solve_pose
from flipkit.planning.planners.chain import Planner
from flipkit.planning.plans.verify import verify_plan
from flipkit.transcription.constraints import KinematicBlock

CELL = CellConfig()
CELL_ROBOT = Models(CELL).loaded


def _spec(**kw):
    base = dict(name="x", duration=(0.2, 0.6), carries_burger=False, end="rest",
                guess=end_pose_guess)
    return Subbehavior(**{**base, **kw})


@pytest.mark.parametrize("kw, word", [({"duration": (0.6, 0.2)}, "duration"),
                                      ({"duration": (0.0, 0.5)}, "duration"),
                                      ({"end": "stopped"}, "rest, home, moving"),
                                      ({"needs": ("burger",)}, "location, goal, spot"),
                                      ({"role": "juggle"}, "role must be one of"),
                                      ({"records": ("notes",)}, "records must be among"),
                                      ({"atlas_anchor": "pin"}, "shift, blend")])
def test_a_malformed_spec_is_refused_in_one_line(kw, word):
    with pytest.raises(ConfigError, match=word) as err:
        _spec(**kw)
    assert "\n" not in str(err.value)


def test_the_library_holds_every_step_of_every_behaviour():
    assert set(library.BEHAVIORS) == {"translate", "flip", "serve"}
    for b in library.BEHAVIORS.values():
        assert all(library.SUBBEHAVIORS[s.name] is s for s in b.steps)
    assert library.FLIP_NAMES == ("go_to_burger", "scoop", "pickup", "flip", "turn_back")
    assert library.SERVE_NAMES[:3] == library.FLIP_NAMES[:3]
    with pytest.raises(InvalidChoiceError, match="'scoop'"):
        library.subbehavior("scop")
    with pytest.raises(InvalidChoiceError, match="'serve'"):
        library.behavior("dance")


def test_a_behaviour_finds_its_steps_by_role():
    flip, serve = library.behavior("flip"), library.behavior("serve")
    assert flip.step("release").name == "flip" and flip.step(flip.sensed).name == "scoop"
    assert serve.step(serve.sensed).name == "carry" and serve.step("place").name == "place"
    assert flip.kept() == ("go_to_burger", "scoop", "pickup")
    assert serve.kept() == ("go_to_burger", "scoop", "pickup", "carry")
    with pytest.raises(ConfigError, match="serve has no release step"):
        serve.step("release")


def test_the_flip_and_carry_hold_the_burger_and_the_turn_back_ends_at_home():
    s = library.SUBBEHAVIORS
    assert [n for n, v in s.items() if v.carries_burger] == ["translate", "pickup", "flip",
                                                             "carry", "place"]
    assert {n for n, v in s.items() if v.end == "moving"} == {"pickup", "flip"}
    assert {n for n, v in s.items() if v.end == "home"} == {"turn_back", "return_home"}


@pytest.mark.parametrize("name, message", [("carry", "carry needs the table spot"),
                                           ("scoop", "scoop needs the burger location"),
                                           ("translate", "translate needs a goal pose")])
def test_transcribing_without_the_task_it_needs_is_one_line(name, message):
    models = Models(CELL)
    with pytest.raises(ConfigError, match=message):
        transcribe(name, models, models.bare.q_home)


def test_floors_follow_the_spec():
    hg, N = CELL.grill.height, 20
    assert np.all(blade_floor("translate", CELL, N) == hg)
    arrival = blade_floor("go_to_burger", CELL, N)  # above the tallest burger, then down
    assert np.all(arrival[:16] > hg + 0.019) and np.all(arrival[16:18] == hg)
    # the tip pressed in over the slide to the scoop's start; the neck never below the grill
    assert np.all(arrival[18:, :2] < hg) and np.all(arrival[:, 2:] >= hg)
    assert blade_floor("translate", CELL, N).shape == (N + 1, 4)
    assert np.all(blade_floor("turn_back", CELL, N) > hg + CELL.burger.thickness)


def test_the_scoop_predicts_the_burger_place_for_the_flip_only_when_unknown():
    after = library.SUBBEHAVIORS["scoop"].after_solve
    known = Task(location=(0.7, 0.0, 0.073), on_blade=(0.01, 0.0))
    assert after(None, known, Models(CELL), None) is known


# A new subbehaviour, declared as one spec: lift the carried burger, flat, to a goal pose.
HOVER = Subbehavior("hover", duration=(0.4, 1.5), carries_burger=True, end="rest",
                    needs=("goal",), end_pose=lambda ctx: ctx.task.goal,
                    cone=lambda ctx: list(range(ctx.layout.n_nodes)), guess=end_pose_guess)


def test_a_new_subbehaviour_is_one_spec_that_the_planner_chains_and_verify_checks(monkeypatch):
    monkeypatch.setitem(library.SUBBEHAVIORS, "hover", HOVER)
    monkeypatch.setitem(library.BEHAVIORS, "translate", Behavior("translate", (HOVER,),
                                                                 stretch=False))
    planner = Planner(CELL, solver="sqp")
    robot = planner.models.loaded
    q0 = solve_pose(robot, (0.70, 0.0, 0.25), (0.0, 0.0, 0.0), robot.q_home)
    plan = planner.chain("translate", Task(goal=flat_pose((0.70, 0.0, 0.35))), q0,
                         np.zeros(robot.nq))
    assert plan.status == "solved", plan.failure
    seg = plan.segments[0]
    assert seg.name == "hover" and 0.4 <= seg.T <= 1.5
    assert np.linalg.norm(robot.position(seg.q[-1]) - (0.70, 0.0, 0.35)) < 1e-4
    assert np.allclose(seg.qd[-1], 0.0, atol=1e-6) and seg.payload == ["spatula", "burger"]
    assert verify_plan(plan, space=CELL.space).ok
    plan.segments[0].q[-1, 0] += 0.05  # the goal missed: verify says so
    assert not verify_plan(plan, space=CELL.space).ok


# A planted subbehaviour, declared in this file alone: carry the burger up to a fixed pose,
# the blade centre never below RISE_FLOOR; ``verify`` checks its end pose (the spec's hook)
# and its path (the spec's own check) with no other module naming it.
RISE_GOAL = flat_pose((0.70, 0.0, 0.35))
RISE_FLOOR = 0.24  # m, below the start (0.25 m)


def rise_floor(ctx):
    L = ctx.layout
    return [KinematicBlock("rise_floor", L, "height", range(1, L.n_nodes), RISE_FLOOR, np.inf)]


def never_below_floor(probe):
    for i, st in enumerate(probe.states):
        probe.add("behavior_path", [max(RISE_FLOOR - st.p[2], 0.0)], i)


RISE = Subbehavior("rise", duration=(0.4, 1.5), carries_burger=True, end="rest",
                   path=rise_floor, end_pose=lambda ctx: RISE_GOAL,
                   cone=lambda ctx: list(range(ctx.layout.n_nodes)), guess=end_pose_guess,
                   checks=(never_below_floor,))


@pytest.fixture(scope="module")
def rise_plan():
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(library.SUBBEHAVIORS, "rise", RISE)
        mp.setitem(library.BEHAVIORS, "rise", Behavior("rise", (RISE,), stretch=False))
        planner = Planner(CELL, solver="sqp")
        robot = planner.models.loaded
        q0 = solve_pose(robot, (0.70, 0.0, 0.25), (0.0, 0.0, 0.0), robot.q_home)
        plan = planner.chain("rise", Task(), q0, np.zeros(robot.nq))
    return plan  # the catalogue as it was


@pytest.fixture
def planted(monkeypatch):
    """The planted spec in the catalogue; ``planted(spec)`` swaps in a changed copy."""
    def plant(spec=RISE):
        monkeypatch.setitem(library.SUBBEHAVIORS, "rise", spec)
        monkeypatch.setitem(library.BEHAVIORS, "rise", Behavior("rise", (spec,), stretch=False))
    plant()
    return plant


def test_verify_checks_a_planted_subbehaviours_end_pose(rise_plan, planted):
    assert rise_plan.status == "solved", rise_plan.failure
    assert verify_plan(rise_plan, space=CELL.space).ok
    off = replace(RISE_GOAL, p=(0.70, 0.0, 0.36))  # the spec's end pose 1 cm higher
    planted(replace(RISE, end_pose=lambda ctx: off))
    report = verify_plan(rise_plan, space=CELL.space)
    assert not report.groups["endpoints"].ok
    assert report.groups["dynamics"].ok and report.groups["behavior_path"].ok
    assert report.groups["endpoints"].violation == pytest.approx(0.01, abs=1e-4)


def test_verify_checks_a_planted_subbehaviours_path_and_fails_a_tampered_copy(rise_plan,
                                                                              planted):
    tampered = copy.deepcopy(rise_plan)
    seg = tampered.segments[0]
    seg.q[:, 1] += 0.3  # the whole path, start to end, swung down (shoulder joint)
    assert np.min([st[2] for st in map(CELL_ROBOT.position, seg.q)]) < RISE_FLOOR
    report = verify_plan(tampered, space=CELL.space)
    assert not report.groups["behavior_path"].ok and not report.groups["endpoints"].ok
    planted(replace(RISE, checks=()))  # without its check, verify has no path rows for it
    assert verify_plan(tampered, space=CELL.space).groups["behavior_path"].ok


def test_the_plan_format_names_every_registered_subbehaviour():
    """A new subbehaviour's name goes into the plan file's schema too."""
    schema = json.loads(resources.files("flipkit.data").joinpath(
        "plan-format.schema.json").read_text())
    names = schema["$defs"]["segment"]["properties"]["name"]["enum"]
    assert sorted(names) == sorted(library.SUBBEHAVIORS)


def test_planners_reuse_the_caches_they_are_given_and_plan_the_same():
    """A planner solves in its caches' SQP workspace: planners given the same caches share
    its compiled subproblems and models, a planner given none compiles its own, and the
    plans are the same either way."""
    from flipkit.planning.planners.caches import PlannerCaches
    from flipkit.solvers.compiled import SQPWorkspace

    goal = Task(goal=flat_pose((0.70, 0.05, 0.30)))
    caches = PlannerCaches()
    first = Planner(CELL, solver="sqp", caches=caches)
    robot = first.models.loaded
    q0 = solve_pose(robot, (0.62, -0.10, 0.25), (0.0, 0.0, 0.0), robot.q_home)
    qd0 = np.zeros(robot.nq)
    a = first.chain("translate", goal, q0, qd0)
    workspace = caches.workspace(SQPWorkspace)
    compiled = dict(workspace._built)
    assert compiled  # the first planner compiled into the caches' workspace
    second = Planner(CELL, solver="sqp", caches=caches)
    b = second.chain("translate", goal, q0, qd0)
    assert second.models is first.models and workspace._built == compiled  # nothing new
    alone = Planner(CELL, solver="sqp")
    c = alone.chain("translate", goal, q0, qd0)
    assert alone.caches.workspace(SQPWorkspace) is not workspace
    assert a.status == b.status == c.status == "solved"
    for other in (b, c):
        np.testing.assert_allclose(a.segments[0].q, other.segments[0].q, atol=1e-9)
