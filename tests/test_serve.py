"""Serve (issue 13, item 1): pick a burger up from the grill and put it on the side table.

Geometry and derivatives of the place, the planner's input checks, a solved serve plan that
verify accepts (and corruptions it refuses), the plan file and CLI, the serve judge (a
motionless blade fails it), and one closed-loop MuJoCo execution that lands on the table.
"""

import json

import numpy as np
import pytest
from conftest import central_fd

from flipkit.behaviors.library import SERVE_NAMES
from flipkit.behaviors import serve as sv
from flipkit.behaviors.targets import check_table_spot
from flipkit.cli import main
from flipkit.config import TableConfig
from flipkit.errors import ConfigError, FlipkitError, UnreachableError
from flipkit.model.orientation import rpy
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.planners.serve import plan_serve
from flipkit.planning.planners.serve import replan_serve, table_spot
from flipkit.planning.plans.verify import verify_plan
from flipkit.simulation.judges import SERVE_TOL, judge_serve
from flipkit.simulation.run import BurgerRun

BURGER, SPOT = (0.75, 0.0, 0.073), (0.40, 0.60)


@pytest.fixture(scope="module")
def plan():
    p = plan_serve(BURGER, SPOT)
    assert p.status == "solved", p.failure
    return p


@pytest.fixture(scope="module")
def plan_file(tmp_path_factory):
    """A serve plan written by ``flipkit plan serve`` (exit 0: solved and verified)."""
    path = tmp_path_factory.mktemp("serve") / "serve.json"
    rc = main(["plan", "serve", "--burger", *map(str, BURGER), "--table-spot", *map(str, SPOT),
               "--json", str(path)])
    assert rc == 0 and path.exists()
    return path


# ---------------------------------------------------------------- geometry
@pytest.mark.parametrize("spot", [(0.1, 0.6), (0.4, 0.9), (0.52, 0.6), (np.nan, 0.6), (0.4,),
                                  "here"])
def test_table_spot_off_the_table_or_malformed_is_refused(cell, spot):
    with pytest.raises(UnreachableError) as exc:
        check_table_spot(cell, spot)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("on_blade", [(0.0, 0.0), (0.05, 0.01), (-0.03, -0.02)])
def test_place_end_puts_the_predicted_rest_point_on_the_spot(cell, on_blade):
    end = sv.place_end(cell, SPOT, on_blade)
    np.testing.assert_allclose(sv.predicted_rest(cell, end.p, end.o[2], on_blade), SPOT,
                               atol=1e-12)
    # the tip is PLACE_TIP_GAP above the table, the blade pitched tip down by PLACE_PITCH
    tip_z = end.p[2] - cell.spatula.length / 2 * np.sin(end.o[1])
    assert tip_z == pytest.approx(cell.table.height + sv.PLACE_TIP_GAP)
    assert end.o[1] == sv.PLACE_PITCH and np.tan(sv.PLACE_PITCH) > 0.8  # past atan μ_max


def test_a_burger_further_out_on_the_blade_moves_the_blade_back(cell):
    near, far = (sv.place_end(cell, SPOT, (x, 0.0)).p for x in (0.0, 0.06))
    u = np.array([np.cos(sv.heading(SPOT)), np.sin(sv.heading(SPOT))])
    assert (np.asarray(far[:2]) - near[:2]) @ u < -0.01


def test_in_start_frame_jacobian_matches_finite_differences(robot):
    q0 = robot.q_home + 0.1
    R0, p0 = robot.rotation(q0), robot.position(q0)
    quantity = sv.InStartFrame(R0, p0)
    q = robot.q_home + np.array([0.2, -0.1, 0.15, 0.3, -0.2, 0.1])
    zero = np.zeros(robot.nq)
    value, jac = quantity(robot.state(q, zero, zero), {})
    fd = central_fd(lambda x: quantity(robot.state(x, zero, zero), {})[0], q)
    np.testing.assert_allclose(jac, fd, atol=1e-7)
    np.testing.assert_allclose(value, R0.T @ (robot.position(q) - p0), atol=1e-12)


def test_tip_point_jacobian_matches_finite_differences(robot, cell):
    ctx = {"length": cell.spatula.length}
    q = robot.q_home + np.array([0.1, 0.2, -0.1, 0.3, 0.2, -0.4])
    zero = np.zeros(robot.nq)
    value, jac = sv.TipPoint()(robot.state(q, zero, zero), ctx)
    fd = central_fd(lambda x: sv.TipPoint()(robot.state(x, zero, zero), ctx)[0], q)
    np.testing.assert_allclose(jac, fd, atol=1e-7)
    pose = sv.place_end(cell, SPOT)
    from flipkit.model.ik import solve_pose

    qe = solve_pose(robot, pose.p, pose.o)
    np.testing.assert_allclose(sv.TipPoint()(robot.state(qe, zero, zero), ctx)[0],
                               sv.tip_point(cell, pose), atol=1e-4)  # IK tolerance


# ---------------------------------------------------------------- planner and verify
def test_serve_plan_is_solved_verified_and_chained(plan):
    names = [s.name for s in plan.segments]
    assert names == list(SERVE_NAMES) and plan.behavior == "serve"
    report = verify_plan(plan)
    assert report.ok, report.table()
    for a, b in zip(plan.segments, plan.segments[1:]):
        np.testing.assert_allclose(a.q[-1], b.q[0], atol=1e-9)
    np.testing.assert_allclose(plan.segments[-1].q[-1], plan.robot["q_home"], atol=1e-6)
    np.testing.assert_allclose(table_spot(plan), SPOT)
    # the friction cone holds on every carry node
    carry = plan.segments[3]
    assert carry.cone_nodes == list(range(carry.N + 1))


def test_verify_recomputes_the_serve_constraints(plan):
    place = plan.segments[4]
    saved = dict(place.placing)
    try:
        place.placing = {**saved, "spot": [SPOT[0] + 0.02, SPOT[1]]}  # another spot
        report = verify_plan(plan)
        assert not report.groups["endpoints"].ok and not report.groups["placing"].ok
        place.placing = {**saved, "spot": [0.1, 0.6]}  # off the table
        assert not verify_plan(plan).groups["placing"].ok
    finally:
        place.placing = saved
    back = plan.segments[5]
    q = back.q.copy()
    try:  # the withdrawal: the blade lifted off its plane at node 2 (shoulder joint)
        back.q[2] = back.q[2] + np.array([0.0, 0.05, 0.0, 0.0, 0.0, 0.0])
        report = verify_plan(plan)
        assert not report.groups["behavior_path"].ok
        assert report.groups["behavior_path"].segment == 5
    finally:
        back.q = q
    assert verify_plan(plan).ok


def test_plan_file_round_trip_and_cli_verify(plan_file, capsys):
    loaded = Plan.load(plan_file)
    assert loaded.behavior == "serve" and verify_plan(loaded).ok
    assert loaded.segments[4].placing["spot"] == list(SPOT)
    assert main(["verify", str(plan_file)]) == 0
    capsys.readouterr()


def test_placing_only_on_carry_and_place(plan_file, tmp_path):
    doc = json.loads(plan_file.read_text())
    doc["segments"][0]["placing"] = doc["segments"][4]["placing"]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(doc))
    with pytest.raises(FlipkitError, match="placing"):
        Plan.load(bad)


def test_serve_plans_chain_from_a_start_configuration(plan):
    with pytest.raises(ConfigError, match="start configuration"):
        plan_serve(BURGER, SPOT, q_start=[0.0] * 5)
    with pytest.raises(UnreachableError, match="off the table"):
        plan_serve(BURGER, (0.1, 0.6), q_start=plan.segments[2].q[-1])


def test_replan_serve_needs_a_solved_serve_plan(plan):
    with pytest.raises(ConfigError):
        replan_serve(plan, (0.2, 0.0))  # off the blade
    plan.status = "failed"
    try:
        with pytest.raises(ConfigError, match="solved serve"):
            replan_serve(plan, (0.02, 0.0))
    finally:
        plan.status = "solved"


@pytest.mark.parametrize("argv", [
    ["--burger", "0.75", "0", "0.072", "--table-spot", "0.1", "0.6"],
    ["--burger", "0.75", "0", "0.072", "--table-spot", "nan", "0.6"],
    ["--burger", "0.75", "0", "0.072", "--table-spot", "0.4"],
    ["--burger", "0.3", "0", "0.072", "--table-spot", "0.4", "0.6"],
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, argv):
    path = tmp_path / "p.json"
    rc = main(["plan", "serve", *argv, "--json", str(path)])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not path.exists()


# ---------------------------------------------------------------- judge
def _run(burger_pos, up_z=1.0, n=300, touching=False):
    """A synthetic run of n samples at 1 kHz, the burger still at ``burger_pos``."""
    t = np.arange(n) * 1e-3
    c = np.clip(up_z, -1, 1)
    s = np.sqrt(1 - c * c)
    R = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    blade = np.array([0.62, -0.2, 0.3])
    return BurgerRun(t, np.tile(burger_pos, (n, 1)), np.tile(R, (n, 1, 1)), np.tile(blade, (n, 1)),
                     np.tile(np.eye(3), (n, 1, 1)), np.full(n, touching), np.zeros(n, bool),
                     np.zeros(n), np.zeros(n), 0.10, 0.015, 0.16, 0.12, 0.072)


def test_judge_passes_a_burger_resting_top_up_near_the_spot():
    table = TableConfig()
    v = judge_serve(_run([0.41, 0.61, table.height + 0.0075]), SPOT, table)
    assert v.ok and v.distance == pytest.approx(np.hypot(0.01, 0.01))


def test_judge_fails_a_motionless_blade():
    """The blade never moved: the burger is still on the grill where it was put."""
    table = TableConfig()
    v = judge_serve(_run([BURGER[0], BURGER[1], 0.072 + 0.0075]), SPOT, table)
    assert not v.ok and not v.on_table and v.distance > SERVE_TOL


@pytest.mark.parametrize("case", ["upside_down", "far", "in_the_air", "moving"])
def test_judge_fails_each_way_of_missing(case):
    table = TableConfig()
    z = table.height + 0.0075
    run = {"upside_down": lambda: _run([0.40, 0.60, z], up_z=-1.0),
           "far": lambda: _run([0.40, 0.64, z]),
           "in_the_air": lambda: _run([0.40, 0.60, z + 0.05])}.get(case, lambda: None)()
    if case == "moving":
        run = _run([0.40, 0.60, z])
        run.burger_pos[-50:, 0] += np.linspace(0, 0.01, 50)
    assert not judge_serve(run, SPOT, table).ok


# ---------------------------------------------------------------- simulation
def test_serve_lands_on_the_table_in_simulation(plan):
    from flipkit.simulation.execute import execute_plan
    from flipkit.simulation.judges import judge_pickup, judge_scoop

    ex = execute_plan(plan, replan=replan_serve)
    assert ex.replan_failure is None and ex.plan.status == "solved"
    assert 0.0 < ex.sensed_on_blade[0] < plan.spatula["length"] / 2  # dragged toward the tip
    for a, b in zip(plan.segments[:4], ex.plan.segments[:4]):  # kept up to the sensing
        np.testing.assert_array_equal(a.q, b.q)
    assert ex.plan.segments[4].placing["on_blade"] == pytest.approx(ex.sensed_on_blade)
    run, bounds = ex.run, ex.bounds
    assert judge_scoop(run, bounds["scoop"]).ok and judge_pickup(run, bounds["pickup"]).ok
    verdict = judge_serve(run, SPOT, plan.cell().table)
    assert verdict.ok, verdict
    # the burger rode the blade through the carry
    k = run.index(bounds["carry"][1])
    assert run.on_blade()[k] and rpy(run.burger_rot[k])[0] == pytest.approx(0.0, abs=0.3)


def test_a_serve_is_sensed_before_the_carry_ends_and_holds_only_beyond_the_lead(plan):
    """The serve's re-plan runs during the last SENSE_LEAD of the carry: one quicker than
    that costs no hold, a slower one holds the arm at the carry's end for the rest only."""
    import time

    from flipkit.simulation.execute import SENSE_LEAD, execute_plan

    def taking(wall):
        def replan(p, on_blade):  # changes nothing, takes ``wall`` s
            time.sleep(wall)
            return p
        return replan

    lead = SENSE_LEAD["serve"]
    plain = execute_plan(plan)
    quick = execute_plan(plan, replan=taking(0.1))
    slow = execute_plan(plan, replan=taking(lead + 0.2))
    assert quick.replan_failure is None and slow.replan_failure is None
    assert quick.bounds == plain.bounds  # no hold
    hold = slow.bounds["place"][0] - plain.bounds["place"][0]
    assert slow.replan_time_s - lead - 1e-3 <= hold <= slow.replan_time_s - lead + 2e-3
    assert quick.replan_wait_s == 0.0
    assert slow.replan_wait_s == pytest.approx(slow.replan_time_s - lead, abs=1e-3)
    assert slow.bounds["carry"] == plain.bounds["carry"]


def test_cli_validate_judges_a_serve_plan_on_the_table(plan_file, tmp_path, capsys):
    out = tmp_path / "v.json"
    rc = main(["validate", "--plan", str(plan_file), "--trials", "1", "--workers", "1",
               "--replan", "--no-progress", "--json", str(out)])
    printed = capsys.readouterr().out
    assert rc == 0 and "serve" in printed
    doc = json.loads(out.read_text())
    entry = doc["locations"][0]
    assert set(entry["success"]) == {"scoop", "pickup", "serve"}
    served = entry["success"]["serve"]  # one trial: the Wilson interval of 0/1 or 1/1
    assert doc["summary"]["interval_95"]["serve"] == pytest.approx(
        [0.0, 0.7935] if served == 0 else [0.2065, 1.0], abs=1e-4)
    assert "95 % Wilson intervals: scoop" in printed
    assert entry["spot"] == list(SPOT) and len(entry["rests"]) == 1
    rest = entry["rests"][0]
    assert entry["success"]["serve"] == int(rest["distance"] <= SERVE_TOL and rest["up_z"] > 0.9)


def test_return_home_guess_makes_the_withdrawal():
    """Return home's initial guess slides the blade back in its own plane before heading
    home: the withdrawal rows are met to a few millimetres (a joint path straight home
    missed them by 0.4, scaled), and it ends at q_home at rest."""
    from flipkit.behaviors.models import Models
    from flipkit.behaviors.transcribe import transcribe
    from flipkit.config import CellConfig
    from flipkit.model.ik import solve_pose

    cell = CellConfig()
    models = Models(cell)
    from flipkit.planning.kitchen.cook import table_spots

    spot = table_spots(cell)[0]
    end = sv.place_end(cell, spot, (0.0, 0.0))
    q0 = solve_pose(models.bare, end.p, end.o, models.bare.q_home)
    nlp = transcribe("return_home", models, q0, np.zeros(6), spot=spot)
    groups = nlp.violation_by_group(nlp.x0)
    assert groups["withdraw"] < 0.02 and groups["withdraw_attitude"] < 0.02
    nodes = nlp.layout.nodes(nlp.x0)
    assert np.abs(nodes[-1, 0] - models.bare.q_home).max() < 0.02
    np.testing.assert_allclose(nodes[-1, 1], 0.0, atol=1e-9)


def test_a_cook_serve_is_replanned_for_where_the_burger_is_seen(plan):
    """motions.serve_replanner: the same start and table spot, the scoop at the seen place;
    a place off the grill is refused with its one-line reason (the scheduled serve then
    runs, and the cook's record says why)."""
    from types import SimpleNamespace

    from flipkit.planning.kitchen.motions import serve_replanner

    replan = serve_replanner()
    motion = SimpleNamespace(plan=plan, burger="b1")
    seen = (BURGER[0] + 0.012, BURGER[1] - 0.008)
    new = replan(motion, seen)
    assert new is not None and new.status == "solved" and verify_plan(new).ok
    assert np.allclose(new.burger["location"], (*seen, BURGER[2]))
    assert np.allclose(table_spot(new), table_spot(plan))
    assert np.allclose(new.segments[0].q[0], plan.segments[0].q[0])
    from flipkit.model.robot import Robot  # the scoop ends with the blade centre under it
    robot = Robot(new.cell())
    scoop = new.segment("scoop")
    assert np.allclose(robot.position(scoop.q[-1])[:2], seen, atol=2e-3)
    with pytest.raises(FlipkitError, match="outside the grill area"):
        replan(motion, (2.0, 0.0))
    from flipkit.simulation.cook import sensed_serve

    sensed = []
    scene = SimpleNamespace(data=SimpleNamespace(qpos=np.array([2.0, 0.0, 0.1])),
                            qpos_of=lambda k: slice(0, 3))
    assert sensed_serve(motion, scene, 0, replan, (0.0, 0.0), sensed) is plan
    assert sensed[0]["replanned"] is False
    assert sensed[0]["why"].startswith("the re-plan was refused: burger location (2.000, 0.000)")
