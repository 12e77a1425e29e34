"""The scoop heading: the go to burger, scoop, pickup and flip stated in a frame turned about
the burger (flipkit.model.task_frame), planned, recorded in the plan file and verified."""

import math

import casadi as ca
import numpy as np
import pytest
from conftest import check_block_jacobian

from flipkit.behaviors import targets as tg
from flipkit.config import CellConfig
from flipkit.errors import UnreachableError
from flipkit.model.casadi_dynamics import CasadiArm
from flipkit.model.task_frame import TaskFrame, rz
from flipkit.transcription.constraints.kinematic import KinematicBlock
from flipkit.transcription.constraints.quantities import QUANTITIES, framed
from flipkit.transcription.layout import Evaluation

FRAME = TaskFrame(0.5, (0.69, -0.16))
CORNER = (0.64, -0.33, 0.072)  # Table I's place nearest the grill's near corner


@pytest.fixture(scope="module")
def flip_nlp():
    """A flip along a heading of −0.3 rad, from its pickup's end."""
    from flipkit.behaviors.models import Models
    from flipkit.behaviors.transcribe import transcribe
    from flipkit.model.ik import solve_pose

    cell = CellConfig()
    models, pb = Models(cell), np.array([0.69, -0.16, 0.072])
    pose = tg.pickup_end(cell, pb, -0.3)
    q0 = solve_pose(models.loaded, pose.p, pose.o, models.loaded.q_home)
    return transcribe("flip", models, q0, np.zeros(6), location=pb, heading=-0.3)


@pytest.mark.parametrize("quantity", ["position", "rpy", "normal", "xaxis", "tip_position",
                                      "velocity", "acceleration"])
def test_framed_block_jacobian(flip_nlp, cell, quantity):
    """A quantity seen in a turned frame: its Jacobian against central differences."""
    ctx = {"length": cell.spatula.length, "width": cell.spatula.width}
    block = KinematicBlock("q", flip_nlp.layout, quantity, [0, 3, 9], -np.inf, np.inf, ctx=ctx,
                           frame=FRAME)
    check_block_jacobian(flip_nlp, block, seed=4)


def test_framed_values_are_the_world_values_turned(flip_nlp, cell):
    """Position, x axis and yaw in the frame, from the world's by an independent rotation."""
    L, x = flip_nlp.layout, flip_nlp.x0
    st = Evaluation(L, flip_nlp.robot, x).state(5)
    A, c = rz(-FRAME.heading), np.array([*FRAME.centre, 0.0])

    def framed(name):
        block = KinematicBlock("q", L, name, [5], -np.inf, np.inf, frame=FRAME)
        return block.evaluate(Evaluation(L, flip_nlp.robot, x))[0]

    np.testing.assert_allclose(framed("position"), A @ (st.p - c) + c, atol=1e-12)
    np.testing.assert_allclose(framed("xaxis"), A @ st.R[:, 0], atol=1e-12)
    yaw = math.atan2(st.R[1, 0], st.R[0, 0])
    assert framed("rpy")[2] == pytest.approx(yaw - FRAME.heading, abs=1e-12)
    assert framed("height")[0] == pytest.approx(st.p[2], abs=1e-15)


@pytest.mark.parametrize("name", ["position", "rpy", "normal", "xaxis"])
def test_framed_symbolic_form_equals_numeric(flip_nlp, cell, name):
    """The CasADi form of a framed quantity gives the numeric value at a random state."""
    robot, rng = flip_nlp.robot, np.random.default_rng(2)
    q, qd, qdd = (robot.q_home + rng.uniform(-0.5, 0.5, 6), rng.uniform(-1, 1, 6),
                  rng.uniform(-3, 3, 6))
    Q, Qd, Qdd = ca.SX.sym("q", 6), ca.SX.sym("qd", 6), ca.SX.sym("qdd", 6)
    quantity = QUANTITIES[name]()
    k = framed(CasadiArm(robot).frame(Q, Qd, Qdd), FRAME)
    f = ca.Function("f", [Q, Qd, Qdd], [quantity.symbolic(k, {})])
    numeric = quantity(FRAME.state(robot.state(q, qd, qdd)), {})[0]
    np.testing.assert_allclose(np.asarray(f(q, qd, qdd)).ravel(), numeric, atol=1e-10)


def test_headed_targets_turn_about_the_burger():
    """Heading 0 is the paper's pose; a heading turns it about the burger, yaw included."""
    cell, pb = CellConfig(), np.array(CORNER)
    paper, turned = tg.scoop_ready(cell, pb), tg.scoop_ready(cell, pb, heading=0.3)
    back = np.array(paper.p) - pb
    np.testing.assert_allclose(np.array(turned.p) - pb, rz(0.3) @ back, atol=1e-12)
    assert turned.o == pytest.approx((paper.o[0], paper.o[1], 0.3))
    end = tg.scoop_end(cell, pb, heading=-0.4)
    np.testing.assert_allclose(end.p[:2], pb[:2], atol=1e-12)  # centred under the burger
    lift = np.array(tg.pickup_end(cell, pb, -0.4).p) - pb
    assert lift[:2] @ np.array([math.cos(-0.4), math.sin(-0.4)]) == pytest.approx(0.02)


def test_default_heading_is_radial_and_the_range_is_refused():
    cell = CellConfig()
    assert tg.default_heading(cell, CORNER) == pytest.approx(math.atan2(-0.33, 0.64))
    assert tg.check_heading(-1.0) == -1.0
    for bad in (1.1, -2.0, float("nan")):
        with pytest.raises(UnreachableError):
            tg.check_heading(bad)


@pytest.fixture(scope="module")
def corner_plan():
    from flipkit import plan_flip

    return plan_flip(CORNER)  # cold start, the default (radial) heading


def test_radial_scoop_fits_the_arm_at_the_corner(corner_plan):
    """At the grill's near corner the radial scoop takes the scoop's own bound (0.6 s), where
    the paper's +x made the wrists undo the base's turn and stretched it; the plan records
    its heading, and the blade ends the scoop along it."""
    from flipkit.model.robot import Robot

    plan = corner_plan
    assert plan.status == "solved"
    assert plan.burger["heading"] == pytest.approx(math.atan2(-0.33, 0.64))
    scoop = plan.step("scoop")
    assert scoop.t[-1] <= 0.6 + 1e-9
    R = Robot(plan.cell()).rotation(scoop.q[-1])
    assert math.atan2(R[1, 0], R[0, 0]) == pytest.approx(plan.burger["heading"], abs=1e-3)


def test_a_tampered_heading_fails_verify(corner_plan, tmp_path):
    """verify takes the heading from the file: a plan whose recorded heading is changed no
    longer meets its end poses and paths."""
    from flipkit import Plan, verify_plan

    path = corner_plan.to_json(tmp_path / "corner.json")
    assert verify_plan(Plan.load(path)).ok
    tampered = Plan.load(path)
    tampered.burger["heading"] = 0.0
    report = verify_plan(tampered)
    assert not report.ok
    failed = {name for name, g in report.groups.items() if not g.ok}
    assert {"endpoints", "behavior_path"} & failed


def test_a_turned_heading_stops_at_the_limit():
    """``turned_heading``: the default heading plus the turn, held within ±HEADING_LIMIT."""
    import math

    from flipkit.behaviors.targets import default_heading, turned_heading
    from flipkit.config import CellConfig
    from flipkit.config.task import HEADING_LIMIT

    cell, near = CellConfig(), (0.75, -0.45, 0.072)
    psi = default_heading(cell, near)
    assert turned_heading(cell, near, math.radians(10)) == pytest.approx(psi + math.radians(10))
    assert turned_heading(cell, near, -math.radians(45)) == pytest.approx(-HEADING_LIMIT)
    assert turned_heading(cell, near, math.radians(120)) == pytest.approx(HEADING_LIMIT)
