"""flipkit.model.goal_check: a translate goal no NLP can end at is refused with the limit and
its amount (issue 28, item 4); goals the planner solves are accepted, with a branch that
reaches the pose inside the joint bounds and clear of the cell. No wall-clock asserts: the
check's time is measured by ``python -m bench.goal_check_bench``."""

import numpy as np
import pytest

from flipkit.errors import ConfigError, UnreachableError
from flipkit.model.collision import ArmShapes
from flipkit.model.goal_check import GoalCheck, check_goal
from flipkit.model.ik import solve_pose
from flipkit.model.robot import Robot
from flipkit.model.singular import SINGULARITY_MARGIN, branch_bounds

FLAT = (0.0, 0.0, 0.0)
README_START = (0.64, -0.33, 0.15)  # README: plan translate --from 0.64 -0.33 0.15 --to 0.75 0.0 0.15
# flipkit.experiments.speed.TRANSLATE_KEY_POINTS (paper Fig. 6): the six translates between
# them, each to the next, are solved by the SQP (docs/benchmarks/bench_translate.txt)
KEY_POINTS = ((0.65, -0.30, 0.15), (0.80, -0.10, 0.15), (0.70, 0.10, 0.15),
              (0.45, 0.74, 0.19), (0.32, 0.62, 0.20), (0.50, 0.52, 0.20))
SOLVED = [(README_START, (0.75, 0.0, 0.15)),  # README's plan translate example
          ((0.65, -0.30, 0.15), (0.80, -0.10, 0.15)),  # tests/test_planner.py GRILL_A -> GRILL_B
          ((0.70, -0.05, 0.15), (0.75, 0.0, 0.15)),  # tests/test_planner.py, the SQP translate
          *[(a, KEY_POINTS[(k + 1) % 6]) for k, a in enumerate(KEY_POINTS)]]


@pytest.fixture(scope="module")
def shapes(cell):
    return ArmShapes(Robot(cell), cell)


def start_q(robot, start):
    """The planner's start configuration: IK near q_home (planning/planners/planner.py plan_translate)."""
    return solve_pose(robot, start, FLAT, robot.q_home)


@pytest.mark.parametrize("goal, message", [
    # inside the back wall (issue 28: SQP infeasible in 0.4 s, then IPOPT up to 300 s)
    ((1.10, 0.0, 0.30), r"^goal \(1\.10, 0\.00, 0\.30\): spatula blade 13\.\d cm inside the wall, "
                        r"margin 2 cm \(best of 2 IK branches within the joint bounds\)$"),
    # the arm within its 2 cm margin of the grill (issue 28: 4.1 s to "end_pose violated by
    # 0.00132"); the limiting shape is the spatula's handle, 2 mm short
    ((0.70, -0.20, 0.10), r"^goal \(0\.70, -0\.20, 0\.10\): spatula handle 1\.8 cm from the grill, "
                          r"margin 2 cm \(best of 2 IK branches within the joint bounds\)$"),
])
@pytest.mark.parametrize("start", [None, README_START])
def test_the_issues_infeasible_goals_are_refused_naming_link_box_and_amount(
        robot, shapes, cell, goal, message, start):
    q0 = None if start is None else start_q(robot, start)
    with pytest.raises(UnreachableError, match=message) as err:
        check_goal(robot, shapes, cell, goal, FLAT, q_start=q0)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("start, goal", SOLVED)
def test_goals_the_planner_solves_are_accepted_with_a_branch_at_the_pose(
        robot, shapes, cell, start, goal):
    q0 = start_q(robot, start)
    got = check_goal(robot, shapes, cell, goal, FLAT, q_start=q0)
    assert isinstance(got, GoalCheck) and got.feasible >= 1 and 0 <= got.branch < 8
    M = robot.placement(got.q)
    np.testing.assert_allclose(M.translation, goal, atol=1e-6)
    np.testing.assert_allclose(M.rotation, np.eye(3), atol=1e-6)
    lo, hi = branch_bounds(robot.q_min, robot.q_max, robot.q_home, q0, SINGULARITY_MARGIN)
    assert np.all(got.q >= lo) and np.all(got.q <= hi)
    assert got.clearance >= cell.space.margin
    # the reported clearance is the least over every (shape, box) pair
    d = [shapes.distance(got.q, k, b)[0] for k in range(len(shapes.names))
         for b in range(len(shapes.box_names))]
    assert min(d) == pytest.approx(got.clearance, abs=1e-9)
    assert (got.shape, got.box) in {(s, b) for s in shapes.names for b in shapes.box_names}
    # the branch is the one the NLP's initial guess goes to (the damped least-squares IK from
    # the start configuration, which stops at a log error of ~3e-5)
    np.testing.assert_allclose(got.q, solve_pose(robot, goal, FLAT, q0), atol=1e-3)


def test_every_solved_reference_segment_ends_at_a_branch_the_check_accepts(robot, shapes, cell):
    """No false refusal on plans the planner did solve: the 57 segment ends of the reference
    plans (tests/data/plan_identity.npz: the ten Table I chains, a serve, a translate) pass the
    check with their start as ``q_start`` and their exempt pairs at node N, and the branch
    returned is the configuration the plan ends in."""
    from plan_identity import REFERENCE

    from flipkit.model.orientation import rpy

    # flipkit/behaviors/clearance.py: the tool end is exempt from the grill at the ends of go
    # to burger, scoop and pickup, and from the table at those of place and return home
    tool = ("blade", "handle", "ee", "wrist_3", "wrist_2")
    exempt = {**dict.fromkeys(("go_to_burger", "scoop", "pickup"), [(t, "grill") for t in tool]),
              **dict.fromkeys(("place", "return_home"), [(t, "table") for t in tool])}
    data = np.load(REFERENCE)
    segments = sorted({k.rsplit("/", 1)[0] for k in data.files if k.count("/") == 3})
    assert len(segments) == 57
    for key in segments:
        name, q = key.split("/")[2], data[f"{key}/q"]
        M = robot.placement(q[-1])
        got = check_goal(robot, shapes, cell, M.translation, rpy(M.rotation), q_start=q[0],
                         excluded=exempt.get(name, ()))
        np.testing.assert_allclose(got.q, q[-1], atol=1e-6, err_msg=key)


def test_a_heading_is_reached_too(robot, shapes, cell):
    o = (0.0, 0.0, 0.5)
    got = check_goal(robot, shapes, cell, (0.75, 0.0, 0.15), o)
    M = robot.placement(got.q)
    np.testing.assert_allclose(M.translation, (0.75, 0.0, 0.15), atol=1e-6)
    np.testing.assert_allclose(M.rotation, robot.placement(solve_pose(
        robot, (0.75, 0.0, 0.15), o, got.q)).rotation, atol=1e-6)


def test_the_goal_is_printed_as_given(robot, shapes, cell):
    with pytest.raises(UnreachableError, match=r"^goal \(0\.72, -0\.10, 0\.095\): spatula handle "
                                               r"1\.3 cm from the grill, margin 2 cm"):
        check_goal(robot, shapes, cell, (0.72, -0.10, 0.095), FLAT)
    with pytest.raises(UnreachableError, match=r"^goal \(1\.10, 0\.00, 0\.30\) rpy \(0\.00, 0\.00, "
                                               r"0\.50\): "):
        check_goal(robot, shapes, cell, (1.10, 0.0, 0.30), (0.0, 0.0, 0.5))


def test_out_of_reach_says_by_how_much(robot, shapes, cell):
    with pytest.raises(UnreachableError, match=r"^goal \(1\.20, 0\.95, 0\.90\): out of reach by "
                                               r"\d+\.\d cm"):
        check_goal(robot, shapes, cell, (1.20, 0.95, 0.90), FLAT)


def test_joint_bounds_name_the_joint_and_the_amount(robot, shapes, cell):
    """A wide singularity margin leaves q3 and q5 a narrow band about π/2 (a start inside it):
    the goal's branches all leave it, and the refusal names the joint, its value and the band;
    a start at the goal branch's q3 and q5 widens the band to them (branch_bounds) and the goal
    passes."""
    q_mid = robot.q_home.copy()
    q_mid[[2, 4]] = np.pi / 2
    with pytest.raises(UnreachableError, match=r"no IK branch within the joint bounds; the nearest "
                                               r"has q[35] \((elbow|wrist)\) = -?\d\.\d{3} rad, "
                                               r"\d\.\d{3} rad outside \[\d\.\d{3}, \d\.\d{3}\] "
                                               r"rad \(1\.4 rad from its singularities"):
        check_goal(robot, shapes, cell, (0.75, 0.0, 0.15), FLAT, q_start=q_mid,
                   singularity_margin=1.4)
    q_goal = check_goal(robot, shapes, cell, (0.75, 0.0, 0.15), FLAT).q
    q0 = robot.q_home.copy()
    q0[[2, 4]] = q_goal[[2, 4]]
    got = check_goal(robot, shapes, cell, (0.75, 0.0, 0.15), FLAT, q_start=q0,
                     singularity_margin=1.4)
    np.testing.assert_allclose(got.q, q_goal, atol=1e-9)


def test_exempt_pairs_are_not_held_to_the_margin(robot, shapes, cell):
    """The refusal at (0.70, −0.20, 0.10) is the handle and the grill's; a segment exempting
    the tool end from the grill (as the subbehaviours at the grill do) would end there."""
    tool = [(s, "grill") for s in ("blade", "handle", "ee", "wrist_3", "wrist_2")]
    got = check_goal(robot, shapes, cell, (0.70, -0.20, 0.10), FLAT, excluded=tool)
    assert (got.shape, got.box) not in tool and got.clearance >= cell.space.margin
    got = check_goal(robot, shapes, cell, (1.10, 0.0, 0.30), FLAT, clearance=False)
    assert (got.shape, got.box, got.clearance) == ("", "", np.inf)  # an NLP without the rows
    with pytest.raises(ConfigError, match="no arm shape"):
        check_goal(robot, shapes, cell, (0.70, -0.20, 0.10), FLAT, excluded=[("spoon", "grill")])


@pytest.mark.parametrize("goal, rpy", [((np.nan, 0.0, 0.15), FLAT), ((0.7, 0.0), FLAT),
                                       ((0.7, 0.0, 0.15), (0.0, np.inf, 0.0))])
def test_malformed_goal(robot, shapes, cell, goal, rpy):
    with pytest.raises(ConfigError, match="finite"):
        check_goal(robot, shapes, cell, goal, rpy)
