"""All ten Table I locations: pickup-and-flip plans with the default solver chain (the SQP,
IPOPT from the same start where the SQP fails), each solved, continuous, verified."""

import numpy as np
import pytest

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.config import TABLE1_LOCATIONS
from flipkit.planning.planners.planner import plan_flip
from flipkit.behaviors import targets as tg
from flipkit.planning.plans.verify import verify_plan


@pytest.mark.parametrize("index", range(len(TABLE1_LOCATIONS)))
def test_table1_location_plans_and_verifies(index):
    plan = plan_flip(TABLE1_LOCATIONS[index], solver="auto")
    assert plan.status == "solved", [(s.name, s.solver.status) for s in plan.segments]
    report = verify_plan(plan)
    assert report.ok, report.worst()
    assert [s.name for s in plan.segments] == list(FLIP_NAMES)
    for a, b in zip(plan.segments, plan.segments[1:]):  # chained by (29)
        np.testing.assert_allclose(a.q[-1], b.q[0], atol=1e-9)
        np.testing.assert_allclose(a.qd[-1], b.qd[0], atol=1e-9)
    flip = plan.segments[FLIP_NAMES.index("flip")]
    assert flip.cone_nodes == list(range(14))  # the paper's 0.6 N, extended to before the release
    assert flip.landing["offset"] <= flip.landing["r_land"] + 1e-6
    assert all(s.solver.name in ("sqp", "ipopt") for s in plan.segments)
    _scoop_brakes_within_friction_under_the_burger(plan)


def _scoop_brakes_within_friction_under_the_burger(plan):
    """The scoop carries the cone at every node where its tip has passed under the burger's
    centre (the braking that drags a burger toward the tip), and the planned blade obeys it."""
    from flipkit.model.contact import make_cone
    from flipkit.model.robot import Robot

    cell = plan.cell()
    robot, cone = Robot(cell, with_burger=False), make_cone(plan.cone, cell.burger.mu, cell.gravity)
    scoop = plan.segments[FLIP_NAMES.index("scoop")]
    pb, half = np.asarray(plan.burger["location"]), cell.spatula.length / 2
    assert scoop.cone_nodes == tg.scoop_cone_nodes(cell, len(scoop.t) - 1)
    for i, q in enumerate(scoop.q):
        M = robot.placement(q)
        tip = M.translation + M.rotation @ np.array([half, 0.0, 0.0])
        if tip[0] >= pb[0]:  # the scoop heads along world +x (targets.scoop_ready)
            assert i in scoop.cone_nodes, i
        if i in scoop.cone_nodes:
            assert cone.margin(robot.state(scoop.q[i], scoop.qd[i], scoop.qdd[i])) >= -1e-6, i
