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
