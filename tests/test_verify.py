"""Independent plan check: consistent synthetic plans pass; each corruption fails its group."""

import json

import numpy as np
import pytest
from test_plan import models  # noqa: F401  (fixture)
from test_plan import LOCATION, chain_plan, cubic_segment, translate_plan

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.behaviors import targets as tg
from flipkit.cli import main
from flipkit.errors import ConfigError, VerificationError
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify import GROUPS, INTERPOLANT_TOL, verify_plan
from flipkit.transcription.constraints.interpolant import ACC_SCALE, VEL_SCALE
from flipkit.model.ik import solve_pose


@pytest.fixture(scope="module")
def chain(models):
    return chain_plan(models)


def _fails(plan, group):
    """The report of ``plan``; asserts that ``group`` fails."""
    report = verify_plan(plan)
    assert not report.ok and not report.groups[group].ok, report.table()
    return report


def _redo_u(seg, robot, i):
    seg.u[i] = robot.inverse_dynamics(seg.q[i], seg.qd[i], seg.qdd[i])


@pytest.mark.parametrize("which", ["translate", "chain", "approach"])
def test_consistent_plans_pass(models, chain, which):
    plan = {"translate": lambda: translate_plan(models), "chain": lambda: chain,
            "approach": lambda: chain_plan(models, approach=True)}[which]()
    report = verify_plan(plan)
    if which != "translate":
        # the synthetic flip plans are partial chains: every residual passes, but a flip
        # plan without its five subbehaviours in order must not verify
        assert not report.groups["completeness"].ok
        report.groups.pop("completeness")
    if which == "approach":
        # a joint-space cubic onto the scoop's start pose comes straight down onto it, not
        # as the approach does (flipkit.behaviors.approach): below the floor over the tallest
        # burger a node before the descent, and past the largest burger's rim at its start
        clear = report.groups.pop("grill_clearance")
        assert clear.node == 15 and 0 < clear.violation < 0.01
        path = report.groups.pop("behavior_path")
        assert path.node == 16 and 0.005 < path.violation < 0.03
    assert report.ok, report.table()
    group, segment, amount = report.worst()
    assert amount <= report.groups[group].tolerance
    if which == "translate":
        assert set(report.groups) == set(GROUPS)
        report.raise_if_failed()  # no exception


def test_torque_corrupted_at_one_node_fails_dynamics(models):
    plan = translate_plan(models)
    plan.segments[1].u[7, 2] += 0.01  # N·m
    report = _fails(plan, "dynamics")
    assert report.worst() == ("dynamics", 1, pytest.approx(0.01))
    assert report.groups["dynamics"].node == 7
    with pytest.raises(VerificationError, match="'dynamics' in segment 1"):
        report.raise_if_failed()


def test_midpoint_position_off_the_interpolant_fails_defects_only(models):
    plan = translate_plan(models)
    seg = plan.segments[0]
    seg.q[5, 0] += 1e-3  # rad, base joint: the blade stays flat, u recomputed
    _redo_u(seg, models.loaded, 5)
    report = _fails(plan, "defects")
    assert report.worst()[:2] == ("defects", 0)
    assert report.groups["defects"].violation == pytest.approx(1e-3)
    assert report.groups["dynamics"].ok and report.groups["cone"].ok


def test_joint_position_limit(models):
    plan = translate_plan(models, turns=(np.array([-2.2, 0, 0, 0, 0, 0]),), durations=(2.0,))
    report = _fails(plan, "q_limits")  # q_home[0] - 2.2 < -pi
    assert report.worst()[0] == "q_limits"
    assert report.groups["q_limits"].violation == pytest.approx(0.988933 + 2.2 - np.pi)


def test_joint_velocity_limit(models):
    plan = translate_plan(models, turns=(np.array([1.1, 0, 0, 0, 0, 0]),), durations=(0.6,))
    report = _fails(plan, "qd_limits")  # peak 1.5 * 1.1 / 0.6 = 2.75 rad/s > 0.9 × 2.094
    assert report.groups["qd_limits"].violation == pytest.approx(2.75 - 0.9 * np.radians(120))
    assert report.groups["dynamics"].ok and report.groups["defects"].ok


def test_limits_between_the_nodes(models):
    """Node values within the limits, the interpolant the controller follows beyond them:
    node 11 of a base turn moved so that the Hermite cubic on [t_10, t_11] overshoots q̇_max."""
    from scipy.interpolate import CubicHermiteSpline

    plan = translate_plan(models, turns=(np.array([1.8, 0, 0, 0, 0, 0]),), durations=(1.5,))
    seg, r = plan.segments[0], models.loaded
    assert verify_plan(plan).groups["interpolant"].ok  # a cubic is its own interpolant
    h = seg.t[1] - seg.t[0]
    c = 3 * (seg.q[11, 0] - seg.q[10, 0]) / h - seg.qd[10, 0] - seg.qd[11, 0]
    seg.q[11, 0] += (r.qd_max[0] + 0.3 - c) * h / 3  # middle Bernstein coefficient 0.3 over
    _redo_u(seg, r, 11)
    report = _fails(plan, "interpolant")
    for group in ("qd_limits", "qdd_limits", "dynamics"):
        assert report.groups[group].ok, group
    spl = CubicHermiteSpline(seg.t, seg.q, seg.qd, axis=0)  # dense samples: the same worst row
    t = np.linspace(0, seg.T, 300001)
    tol_v, tol_a = (f * report.tol for f in INTERPOLANT_TOL)
    over_v = np.maximum(np.abs(spl(t, 1)) - r.qd_max, 0).max() / tol_v
    over_a = np.maximum(np.abs(spl(t, 2)) - r.qdd_max, 0).max() / tol_a
    assert 0 < over_v < 0.3 / tol_v  # the curve peaks below its Bernstein coefficient
    # the tolerances are the solver's: its row scales (InterpolantLimits) times tol
    assert INTERPOLANT_TOL == (1 / VEL_SCALE, 1 / ACC_SCALE)
    assert report.groups["interpolant"].ratio == pytest.approx(max(over_v, over_a), rel=1e-4)


def test_discontinuity_between_segments(models):
    plan = translate_plan(models)
    seg, shift = plan.segments[1], np.array([2e-4, 0, 0, 0, 0, 0])  # rad about the base axis
    plan.segments[1] = cubic_segment("translate", seg.q[0] + shift, seg.q[-1] + shift, seg.T,
                                     models.loaded)
    report = _fails(plan, "continuity")
    assert report.worst() == ("continuity", 1, pytest.approx(2e-4))
    assert report.groups["endpoints"].ok and report.groups["dynamics"].ok


def test_cone_with_violent_base_acceleration(models):
    plan = translate_plan(models, turns=(np.array([0.7, 0, 0, 0, 0, 0]),), durations=(0.6,))
    report = _fails(plan, "cone")  # ~0.65 m × 11.7 rad/s² ≫ μ g
    assert report.worst()[0] == "cone" and report.groups["cone"].node in (0, 20)
    for group in ("dynamics", "defects", "qd_limits", "qdd_limits", "endpoints"):
        assert report.groups[group].ok, group


def test_cone_with_little_friction(models):
    plan = translate_plan(models)
    plan.burger["mu"] = 0.01  # the gentle base turn now slides the burger
    assert _fails(plan, "cone").worst()[0] == "cone"


def test_a_scoop_braking_hard_under_the_burger_fails_the_cone(models):
    """A scoop that stops 14 cm of travel in 0.2 s (end deceleration 21 m/s² ≫ μ g) would
    fling the burger toward the tip: verify checks the scoop's cone where the burger is over
    the blade (targets.scoop_cone_nodes), whatever the plan file's own cone_nodes say."""
    r, cell = models.bare, models.cell
    ready, end = tg.scoop_ready(cell, LOCATION), tg.scoop_end(cell, LOCATION)
    q0 = solve_pose(r, ready.p, ready.o, r.q_home, tol=1e-22)
    q1 = solve_pose(r, end.p, end.o, q0, tol=1e-22)
    seg = cubic_segment("scoop", q0, q1, 0.2, models.bare)
    assert seg.cone_nodes == []
    plan = Plan.from_segments("flip", cell, [seg], location=LOCATION)
    report = _fails(plan, "cone")
    assert report.groups["cone"].node in tg.scoop_cone_nodes(cell, 20)
    still = Plan.from_segments("flip", cell, [cubic_segment("scoop", q1, q1, 0.2, models.bare)],
                               location=LOCATION)
    assert verify_plan(still).groups["cone"].ok  # at rest, blade flat: within the cone


def test_paper_cone_form_is_used_when_recorded(models):
    plan = translate_plan(models)
    plan.cone = "paper"
    report = verify_plan(plan)
    assert report.ok and report.groups["cone"].unit == "1"


def test_grill_above_the_blade_fails_clearance(models):
    """Checked in a cell whose grill is at 0.35 m (the blade rides at 0.30 m); a plan that
    claims that grill is refused in the default cell, as planned for another."""
    from dataclasses import replace

    from flipkit.planning.plans.cell_in_use import CellMismatchError
    from flipkit.planning.plans.cell_record import cell_geometry

    plan = translate_plan(models)
    cell = replace(models.cell, grill=replace(models.cell.grill, height=0.35))
    plan.grill_height, plan.cell_geometry = 0.35, cell_geometry(cell)
    report = verify_plan(plan, cell=cell)
    assert not report.groups["grill_clearance"].ok, report.table()
    assert report.groups["grill_clearance"].violation == pytest.approx(0.05, abs=0.01)
    with pytest.raises(CellMismatchError, match="cell_geometry.grill.height, grill_height"):
        verify_plan(plan)


def test_uneven_time_grid(models):
    plan = translate_plan(models)
    plan.segments[0].t[3] += 1e-6
    assert _fails(plan, "time_grid").worst()[0] == "time_grid"


def test_translate_goal_and_rest(models):
    plan = translate_plan(models)
    g = plan.segments[1].goal
    plan.segments[1].goal = tg.Pose((g.p[0] + 1e-3, g.p[1], g.p[2]), g.o)
    assert _fails(plan, "endpoints").groups["endpoints"].violation == pytest.approx(1e-3)
    plan = translate_plan(models)
    plan.segments[1].goal = None  # without a goal: rest and flatness are still checked
    assert verify_plan(plan).ok
    plan.segments[1].qd[-1, 4] = 1e-3
    assert _fails(plan, "endpoints").groups["endpoints"].node == 20


def test_subbehaviour_endpoints_follow_the_burger_location(models, chain):
    plan = chain_plan(models)
    plan.burger["location"] = plan.burger["location"] + np.array([0.01, 0.0, 0.0])
    report = _fails(plan, "endpoints")
    assert report.groups["endpoints"].violation == pytest.approx(0.01, rel=1e-6)
    plan = chain_plan(models)
    last = plan.segments[-1]
    plan.segments[-1] = cubic_segment("turn_back", last.q[0], last.q[-1] + 0.01, last.T,
                                      models.bare)
    assert _fails(plan, "endpoints").worst()[:2] == ("endpoints", 2)


def test_a_flip_that_does_not_flip_fails_its_path_constraints(models, chain):
    q = chain.segments[1].q[-1]  # pickup end, blade up: normal and height outside eq. (26)
    seg = cubic_segment("flip", q, q, SUBBEHAVIORS["flip"].duration[1], models.loaded)
    plan = Plan.from_segments("flip", models.cell, [seg], location=chain.burger["location"])
    report = _fails(plan, "behavior_path")
    assert report.groups["behavior_path"].violation == pytest.approx(1.8, abs=0.01)  # n_z 1 vs -0.8
    assert not report.groups["landing"].ok  # no release, no landing


def test_bad_tolerance():
    with pytest.raises(ConfigError, match="tol must be"):
        verify_plan(None, tol=0.0)


def test_cli_exit_codes(models, tmp_path, capsys):
    good = translate_plan(models).to_json(tmp_path / "good.json")
    assert main(["verify", str(good), "--json", str(tmp_path / "r.json")]) == 0
    out = capsys.readouterr().out
    assert "dynamics" in out and "plan verified" in out
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["ok"] is True and {g["name"] for g in doc["groups"]} == set(GROUPS)

    plan = translate_plan(models)
    plan.segments[0].u[3, 1] += 1.0
    bad = plan.to_json(tmp_path / "bad.json")
    assert main(["verify", str(bad)]) == 1
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "'dynamics' in segment 0" in err and "1 N·m" in err

    (tmp_path / "broken.json").write_text('{"format": "flipkit-plan/1"')
    assert main(["verify", str(tmp_path / "broken.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("flipkit: error:") and "not a JSON file" in err and "\n" not in err
    assert main(["verify", str(tmp_path / "missing.json")]) == 2


def test_rows_recorded_node_by_node_match_one_call_per_node():
    """VerificationReport.add_nodes (one call for a segment's nodes) records the same worst
    row — violation, tolerance, node — as add once per node in order, NaN and ties included."""
    from flipkit.planning.plans.verify import VerificationReport

    rng = np.random.default_rng(3)
    for trial in range(50):
        v = rng.uniform(0, 1, (7, 3)) * (rng.uniform(size=(7, 3)) < 0.5)
        if trial % 5 == 0:
            v[rng.integers(7), rng.integers(3)] = np.nan
        if trial % 7 == 0:
            v[:] = 0.25  # all tied: the first node wins
        tol = rng.uniform(0.1, 1.0, 3)
        nodes = np.arange(7) * 2 + 1
        a, b = VerificationReport(1e-5, ["s"]), VerificationReport(1e-5, ["s"])
        a.add("defects", 0, [0.01], 1.0, 0)  # an earlier segment's row in both
        b.add("defects", 0, [0.01], 1.0, 0)
        for r in range(7):
            a.add("defects", 1, v[r], tol, int(nodes[r]))
        b.add_nodes("defects", 1, v, tol, nodes)
        ga, gb = a.groups["defects"], b.groups["defects"]
        assert (ga.segment, ga.node, ga.tolerance) == (gb.segment, gb.node, gb.tolerance)
        assert ga.violation == gb.violation or (np.isnan(ga.violation) and np.isnan(gb.violation))
