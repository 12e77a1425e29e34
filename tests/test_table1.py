"""All ten Table I locations: pickup-and-flip plans with the default solver chain (the SQP,
IPOPT from the same start where the SQP fails), each solved, continuous, verified."""

import numpy as np
import pytest

from flipkit.config import TABLE1_LOCATIONS
from flipkit.planning.planner import plan_flip
from flipkit.behaviors.targets import SUBBEHAVIORS
from flipkit.planning.verify import verify_plan


@pytest.mark.parametrize("index", range(len(TABLE1_LOCATIONS)))
def test_table1_location_plans_and_verifies(index):
    plan = plan_flip(TABLE1_LOCATIONS[index], solver="auto")
    assert plan.status == "solved", [(s.name, s.solver.status) for s in plan.segments]
    report = verify_plan(plan)
    assert report.ok, report.worst()
    assert [s.name for s in plan.segments] == list(SUBBEHAVIORS)
    for a, b in zip(plan.segments, plan.segments[1:]):  # chained by (29)
        np.testing.assert_allclose(a.q[-1], b.q[0], atol=1e-9)
        np.testing.assert_allclose(a.qd[-1], b.qd[0], atol=1e-9)
    flip = plan.segments[SUBBEHAVIORS.index("flip")]
    assert flip.cone_nodes == list(range(15))  # the paper's 0.6 N, extended to the release
    assert flip.landing["offset"] <= flip.landing["r_land"] + 1e-6
    assert all(s.solver.name in ("sqp", "ipopt") for s in plan.segments)
