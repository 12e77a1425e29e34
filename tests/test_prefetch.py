"""Planning a cook ahead in worker processes gives the serial run's plans and timeline."""

import numpy as np
import pytest

from flipkit.config import CellConfig
from flipkit.experiments.sweep import make_executor
from flipkit.planning.cook import CookBurger, check_cook, table_spots
from flipkit.planning.motions import default_planners
from flipkit.planning.prefetch import PrefetchPlanners
from flipkit.planning.schedule import schedule_cook

CELL = CellConfig()
ORDER = [CookBurger("b1", 0.0, 0.64, -0.33), CookBurger("b2", 5.0, 0.69, -0.16)]  # Table I 1, 6


@pytest.mark.slow
def test_prefetched_cook_equals_the_serial_one():
    kinds = ("flip", "serve")
    q_home = CELL.robot.q_home
    serial = schedule_cook(ORDER, default_planners(kinds, CELL), q_home, kinds=kinds, cell=CELL,
                           progress=False)
    executor = make_executor(workers=2)
    try:
        planners = PrefetchPlanners(check_cook(ORDER, CELL), kinds, q_home, table_spots(CELL),
                                    executor, CELL)
        parallel = schedule_cook(ORDER, planners, q_home, kinds=kinds, cell=CELL,
                                 progress=False)
    finally:
        executor.shutdown()
    assert serial.ok and parallel.ok
    assert planners.on_demand == 0  # every motion came from a worker
    assert [m.key for m in serial.motions] == [m.key for m in parallel.motions]
    for a, b in zip(serial.motions, parallel.motions):
        assert (a.start, a.end, a.event) == pytest.approx((b.start, b.end, b.event), abs=1e-6)
        assert [s.name for s in a.plan.segments] == [s.name for s in b.plan.segments]
        for sa, sb in zip(a.plan.segments, b.plan.segments):
            # Not bitwise: a solve in a process that solved other segments before it can
            # differ in the last bits (measured: 3.4e-6 rad at most, on this cook), which the
            # SQP carries to its stopping point; within the solver's tolerance it is the same.
            np.testing.assert_allclose(sa.q, sb.q, rtol=0, atol=1e-4)
            np.testing.assert_allclose(sa.u, sb.u, rtol=1e-3, atol=1e-2)
    # the planning clock follows when plans were in, not the sum of their times
    assert parallel.planning_time_s <= sum(m.planning_time_s for m in parallel.motions)


@pytest.mark.slow
def test_parallel_batch_equals_the_serial_one():
    from flipkit.config import TABLE1_LOCATIONS
    from flipkit.planning.planner import plan_batch

    locs = [TABLE1_LOCATIONS[6], TABLE1_LOCATIONS[8]]
    serial = plan_batch(locs, progress=False, solver="sqp")
    executor = make_executor(workers=2)
    try:
        parallel = plan_batch(locs, progress=False, solver="sqp", executor=executor)
    finally:
        executor.shutdown()
    assert [p.status for p in serial] == [p.status for p in parallel] == ["solved"] * 2
    for a, b in zip(serial, parallel):
        for sa, sb in zip(a.segments, b.segments):
            assert sa.name == sb.name
            np.testing.assert_allclose(sa.q, sb.q, rtol=0, atol=1e-4)
