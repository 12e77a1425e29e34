"""A scoop a blade can do: only the tip, where the blade flexes, is pressed into the grill; the
neck and the back edge never go below its surface, in the plan and in verify."""

import copy
import math

import numpy as np
import pytest

from flipkit.behaviors import targets as tg
from flipkit.behaviors.options import SCOOP_PRESS, SCOOP_TIP_BAND
from flipkit.behaviors.transcribe import blade_floor
from flipkit.config import CellConfig
from flipkit.model.robot import Robot
from flipkit.planning.plans.verify import verify_plan
from flipkit.model.robot import BLADE_CORNERS

PRESSED = ("go_to_burger", "scoop", "pickup")


def corner_heights(robot, cell, q):
    l, w = cell.spatula.length / 2, cell.spatula.width / 2
    out = []
    for x in q:
        M = robot.placement(x)
        out.append([(M.translation + M.rotation @ np.array([a * l, b * w, 0.0]))[2]
                    for a, b in BLADE_CORNERS])
    return np.array(out)


def test_the_floors_press_the_tip_only():
    cell = CellConfig()
    hg = cell.grill.height
    for name in PRESSED:
        floor = blade_floor(name, cell, 20)
        assert floor.shape == (21, 4)
        assert np.all(floor[:, 2:] >= hg)  # the back corners: never below the surface
    np.testing.assert_allclose(blade_floor("scoop", cell, 20)[:, :2], hg - SCOOP_PRESS - SCOOP_TIP_BAND)
    end = tg.scoop_end(cell, (0.7, -0.1, hg))
    assert end.o[1] == pytest.approx(math.asin(SCOOP_PRESS / cell.spatula.length))
    assert end.p[2] == pytest.approx(hg - SCOOP_PRESS / 2)


def test_the_planned_neck_stays_on_or_above_the_grill(flip_plan):
    cell = flip_plan.cell()
    robot, hg = Robot(cell), cell.grill.height
    lowest_tip = np.inf
    for seg in flip_plan.segments:
        if seg.name not in PRESSED:
            continue
        h = corner_heights(robot, cell, seg.q)
        assert h[:, 2:].min() >= hg - 1e-6, seg.name  # neck: on the surface at the lowest
        lowest_tip = min(lowest_tip, h[:, :2].min())
    assert lowest_tip < hg - SCOOP_PRESS + SCOOP_TIP_BAND + 1e-6  # the tip is pressed in


def test_verify_fails_a_scoop_that_presses_the_neck_in(flip_plan):
    """The scoop's last nodes lowered 2 mm by the shoulder: the back corners go below the
    grill, and grill_clearance fails there by about that much."""
    plan = copy.deepcopy(flip_plan)
    assert verify_plan(plan).groups["grill_clearance"].ok
    k = [s.name for s in plan.segments].index("scoop")
    seg = plan.segments[k]
    robot = Robot(plan.cell())
    J = robot.pose_jacobians(seg.q[-1])[2]  # ∂p/∂q of the blade centre
    dq = np.linalg.lstsq(J[2:3], [-0.002], rcond=None)[0]
    seg.q[-3:] = seg.q[-3:] + dq
    group = verify_plan(plan).groups["grill_clearance"]
    assert not group.ok and plan.segments[group.segment].name in ("scoop", "pickup")
    assert 0.0005 < group.violation < 0.004
