"""Planning a cook or a batch in worker processes: the same motions, solved and verified, on the
same schedule as the serial run.

The plans used to depend on the process's history (CI: a batch plan's joint path 0.05 rad from
its worker twin): coal's Box support keeps a static set by the process's first box query
(:func:`flipkit.model.collision.pin_box_support`, tests/test_determinism.py). With it pinned,
the batch below is compared bit for bit.
"""

import numpy as np
import pytest

from flipkit.config import CellConfig
from flipkit.experiments.sweep import make_executor
from flipkit.planning.kitchen.cook import CookBurger, check_cook, table_spots
from flipkit.planning.kitchen.motions import default_planners
from flipkit.planning.kitchen.prefetch import PrefetchPlanners
from flipkit.planning.kitchen.schedule import schedule_cook
from flipkit.planning.plans.verify import verify_plan

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
        assert (a.start, a.end, a.event) == pytest.approx((b.start, b.end, b.event), abs=0.05)
        assert [s.name for s in a.plan.segments] == [s.name for s in b.plan.segments]
        assert b.plan.status == "solved" and verify_plan(b.plan, space=CELL.space).ok
        assert np.abs(b.plan.segments[0].q[0] - q_home).max() == 0.0  # from rest at home
    # (the planning clocks, serial and prefetched: python -m bench.bench flip --cook)


@pytest.mark.slow
def test_parallel_batch_equals_the_serial_one():
    from flipkit.config import TABLE1_LOCATIONS
    from flipkit.planning.planners.planner import plan_batch

    locs = [TABLE1_LOCATIONS[6], TABLE1_LOCATIONS[8]]
    serial = plan_batch(locs, progress=False, solver="sqp")
    executor = make_executor(workers=2)
    try:
        parallel = plan_batch(locs, progress=False, solver="sqp", executor=executor)
    finally:
        executor.shutdown()
    assert [p.status for p in serial] == [p.status for p in parallel] == ["solved"] * 2
    for a, b in zip(serial, parallel):
        assert [s.name for s in a.segments] == [s.name for s in b.segments]
        assert verify_plan(b, space=CELL.space).ok
        np.testing.assert_array_equal(a.segments[0].q[0], b.segments[0].q[0])  # same start
        for sa, sb in zip(a.segments, b.segments):  # the same plan, bit for bit
            np.testing.assert_array_equal(sa.q, sb.q)


def test_a_flip_asked_for_again_does_not_plan_its_serve_again(monkeypatch):
    """Each round of a cook's clearance asks for every flip again; the serve from an unchanged
    landing is the plan already made (it was planned anew every round, one wasted serve per
    burger and round)."""
    import concurrent.futures as cf
    from types import SimpleNamespace

    from flipkit.planning.kitchen import prefetch
    from flipkit.planning.kitchen.motions import MotionJob

    planned = []

    def fake_plan(kind, job, q_start, cell, solver, atlas=None):
        planned.append((kind, job.burger))
        return SimpleNamespace(ok=True, landing=(0.70, -0.20), planning_time_s=0.0)

    monkeypatch.setattr(prefetch, "plan_motion", fake_plan)
    order = check_cook(ORDER, CELL)
    with cf.ThreadPoolExecutor(1) as pool:
        planners = PrefetchPlanners(order, ("flip", "serve"), CELL.robot.q_home,
                                    table_spots(CELL), pool, CELL)
        flip = MotionJob("flip", "b1", order[0].location(CELL))
        for _round in range(3):
            planners["flip"](flip, CELL.robot.q_home)
        pool.shutdown(wait=True)
    assert planned.count(("serve", "b1")) == 1
    assert planned.count(("flip", "b1")) == 1
