"""The cook's real planners refuse a place off the grill area as a failed motion with the
planner's reason (flipkit.planning.kitchen.motions.refused), not as an exception that ends
the whole cook without saying whose motion it was."""

import numpy as np
import pytest

from flipkit.config import CellConfig
from flipkit.planning.kitchen.motions import MotionJob, flip_planner, serve_planner

CELL = CellConfig()


def test_a_serve_at_a_landing_off_the_grill_area_is_a_failed_motion_with_its_reason():
    job = MotionJob("serve", "b09", (0.5999, -0.01, CELL.grill.height), table_spot=(0.40, 0.60))
    q0 = np.asarray(CELL.robot.q_home, float)
    pm = serve_planner(CELL)(job, q0)
    assert not pm.ok and pm.plan is None and pm.duration_s == 0.0
    np.testing.assert_array_equal(pm.q_end, q0)
    assert pm.failure.startswith("refused at (0.600, -0.010): burger location")
    assert "outside the grill area" in pm.failure


def test_a_flip_off_the_grill_area_is_refused_the_same_way():
    job = MotionJob("flip", "b01", (0.95, 0.0, CELL.grill.height))
    pm = flip_planner(CELL)(job, np.asarray(CELL.robot.q_home, float))
    assert not pm.ok and "refused at (0.950, 0.000)" in pm.failure


def test_with_sense_pause_lengthens_the_solved_serves_only():
    from flipkit.errors import FlipkitError
    from flipkit.planning.kitchen.motions import SENSE_PAUSE_S, PlannedMotion, with_sense_pause

    def fixed(ok, duration):
        def plan(job, q):
            return PlannedMotion(ok=ok, duration_s=duration, event_s=1.0, q_end=np.zeros(6),
                                 planning_time_s=0.0)
        return plan

    inner = {"flip": fixed(True, 3.7), "serve": fixed(True, 5.5)}
    wrapped = with_sense_pause(inner)
    assert wrapped["flip"](None, None).duration_s == 3.7
    served = wrapped["serve"](None, None)
    assert served.duration_s == pytest.approx(5.5 + SENSE_PAUSE_S) and served.event_s == 1.0
    assert with_sense_pause({"serve": fixed(False, 0.0)})["serve"](None, None).duration_s == 0.0
    assert with_sense_pause(inner, 0.0)["serve"](None, None).duration_s == 5.5
    with pytest.raises(FlipkitError, match="sense pause"):
        with_sense_pause(inner, -0.1)
