"""flipkit.planning.planners.planner: translate / flip / batch front end, status only 'solved' when verified."""

import numpy as np
import pytest
from test_plan import models  # noqa: F401  (fixture)

import flipkit.planning.planners.planner as planner
import flipkit.planning.planners.chain as chain
from flipkit.experiments.speed import TRANSLATE_KEY_POINTS
from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.errors import ConfigError, InvalidChoiceError, UnreachableError
from flipkit.planning.plans.plan_file import Plan
from flipkit.behaviors.models import Models
from flipkit.planning.planners.chain import solve_segment
from flipkit.planning.planners.planner import (format_summary, plan_batch, plan_flip, plan_translate,
                                      summary_table)
from flipkit.solvers.sqp import SolveResult
from flipkit.planning.plans.verify import verify_plan

GRILL_A, GRILL_B = (0.65, -0.30, 0.15), (0.80, -0.10, 0.15)


@pytest.fixture(scope="module")
def ipopt_translate():
    return plan_translate(GRILL_A, GRILL_B, solver="ipopt")


def test_ipopt_translate_is_solved_and_verified(ipopt_translate):
    plan = ipopt_translate
    assert isinstance(plan, Plan) and plan.behavior == "translate"
    assert plan.status == "solved" and plan.failure is None and plan.report.ok
    assert verify_plan(plan).ok
    seg = plan.segments[0]
    assert seg.solver.name == "ipopt" and seg.solver.status == "solved"
    assert seg.goal.p == pytest.approx(GRILL_B) and seg.goal.o == pytest.approx((0, 0, 0))
    robot = Models(CellConfig()).loaded
    assert robot.position(seg.q[0]) == pytest.approx(GRILL_A, abs=1e-6)
    assert robot.position(seg.q[-1]) == pytest.approx(GRILL_B, abs=1e-6)
    assert plan.wall_time_s >= seg.solver.wall_time_s > 0


def test_sqp_translate_status_matches_verification():
    """The SQP is still being tuned: only the contract is checked, not convergence."""
    plan = plan_translate((0.70, -0.05, 0.15), (0.75, 0.0, 0.15), solver="sqp")
    assert isinstance(plan, Plan) and plan.segments[0].solver.name == "sqp"
    solved = plan.segments[0].solver.status == "solved" and verify_plan(plan).ok
    assert (plan.status == "solved") == solved
    if not solved:
        assert isinstance(plan.failure, str) and "\n" not in plan.failure


def _fake_solver(status):
    """A solve_segment that returns the initial guess with the given status."""
    def fake(nlp, solver="sqp", x0=None, **kw):
        x = np.clip(nlp.x0, nlp.x_lb, nlp.x_ub)
        return SolveResult(x=x, status=status, iterations=3, wall_time_s=0.01,
                           objective=nlp.objective(x), max_violation=1.0, solver=solver)
    return fake


def test_solver_failure_is_reported_with_group(monkeypatch):
    monkeypatch.setattr(chain, "solve_segment", _fake_solver("max_iter"))
    plan = plan_translate(GRILL_A, GRILL_B, solver="ipopt")
    assert plan.status == "failed"
    assert plan.failure.startswith("translate: ") and "violated by" in plan.failure
    assert "max_iter" in plan.failure
    flip = plan_flip(TABLE1_LOCATIONS[2], solver="sqp")  # stops at the first segment
    assert flip.status == "failed" and [s.name for s in flip.segments] == ["go_to_burger"]
    assert flip.failure.startswith("go_to_burger: ")


def test_solved_claim_is_overruled_by_verification(monkeypatch):
    monkeypatch.setattr(chain, "solve_segment", _fake_solver("solved"))
    plan = plan_translate(GRILL_A, GRILL_B)
    assert plan.segments[0].solver.status == "solved"
    assert plan.status == "failed" and plan.failure.endswith("(verify)")


@pytest.mark.parametrize("start, goal, kwargs, error, match", [
    ((np.nan, 0, 0.15), GRILL_B, {}, ConfigError, "finite"),
    ((3.0, 0.0, 0.15), GRILL_B, {}, UnreachableError, "outside the reachable task area"),
    (GRILL_A, (0.7, 0.0), {}, ConfigError, "three finite numbers"),
    (None, GRILL_B, {"q_start": [0.0] * 5}, ConfigError, "6 values"),
    (None, GRILL_B, {"q_start": [0, 0, 0, 0, 0, 3.5]}, ConfigError, "joint 6 .* outside"),
    (GRILL_A, GRILL_B, {"q_start": CellConfig().robot.q_home}, ConfigError, "mm from"),
    (GRILL_A, GRILL_B, {"solver": "snopt"}, InvalidChoiceError, "'sqp', 'ipopt'"),
])
def test_translate_bad_input(start, goal, kwargs, error, match):
    with pytest.raises(error, match=match):
        plan_translate(start, goal, **kwargs)


def test_flip_and_batch_bad_input():
    with pytest.raises(UnreachableError, match="outside the grill"):
        plan_flip((0.3, 0.0, 0.072))
    with pytest.raises(ConfigError, match="start velocity"):
        plan_flip(TABLE1_LOCATIONS[0], qd_start=[10.0] * 6)
    with pytest.raises(ConfigError, match="1 to 5"):
        plan_batch(TABLE1_LOCATIONS[:6], progress=False)
    with pytest.raises(ConfigError, match="1 to 5"):
        plan_batch([], progress=False)
    with pytest.raises(UnreachableError, match="^burger 2: "):
        plan_batch([TABLE1_LOCATIONS[0], (0.7, 0.0, 0.5)], progress=False)


def test_solve_segment_rejects_unknown_solver():
    with pytest.raises(InvalidChoiceError, match="'sqp', 'ipopt'"):
        solve_segment(None, "snopt")


def test_planner_caches_keep_each_cells_models():
    """A cell's models are built once per PlannerCaches and handed to every planner given it;
    other caches build their own."""
    from flipkit.planning.planners.caches import PlannerCaches

    caches = PlannerCaches()
    assert caches.models(CellConfig()) is caches.models(CellConfig())
    assert PlannerCaches().models(CellConfig()) is not caches.models(CellConfig())
    assert chain.Planner(CellConfig(), caches=caches).models is caches.models(CellConfig())


def test_summary_table(ipopt_translate):
    rows = summary_table([ipopt_translate, ipopt_translate])
    seg = ipopt_translate.segments[0]
    assert rows[1] == (2, None, "solved", seg.solver.wall_time_s, seg.solver.iterations,
                       seg.solver.max_violation)
    assert len(format_summary(rows).splitlines()) == 3


def test_translate_key_points_lie_over_grill_and_table():
    cell = CellConfig()
    over = {"grill": 0, "table": 0}
    for p in TRANSLATE_KEY_POINTS:
        for name, area in (("grill", cell.grill), ("table", cell.table)):
            (x0, x1), (y0, y1) = area.x_range, area.y_range
            if x0 <= p[0] <= x1 and y0 <= p[1] <= y1:
                assert 0.05 <= p[2] - area.height <= 0.10
                over[name] += 1
    assert over == {"grill": 3, "table": 3}


def test_auto_falls_back_to_ipopt_when_the_sqp_fails(monkeypatch):
    import flipkit.solvers.sqp as sqp_module

    calls = []

    def failing_sqp(nlp, x0=None, options=None, raise_on_failure=True, workspace=None):
        calls.append("sqp")
        x = np.clip(nlp.x0, nlp.x_lb, nlp.x_ub)
        return SolveResult(x=x, status="stalled", iterations=3, wall_time_s=1.5,
                           objective=nlp.objective(x), max_violation=1.0)

    monkeypatch.setattr(sqp_module, "solve_sqp", failing_sqp)
    models = Models(CellConfig())
    from flipkit.behaviors.transcribe import flat_pose, transcribe
    from flipkit.model.ik import solve_pose

    nlp = transcribe("translate", models, solve_pose(models.loaded, GRILL_A, (0, 0, 0)),
                        goal=flat_pose(GRILL_B))
    res = solve_segment(nlp, "auto")
    assert calls == ["sqp"] and res.success and res.solver == "ipopt"
    assert res.wall_time_s > 1.5  # both attempts are counted


def test_a_segment_infeasible_within_its_bound_gets_a_longer_one():
    """The scoop at (0.630, −0.347) along the paper's +x — wrists 1 and 3 undoing the base's
    turn — has no solution within 0.6 s; the planner tries once more with the bound ×
    T_STRETCH and the plan verifies. (Along the default, radial heading it needs no stretch.)"""
    from flipkit.behaviors.library import SUBBEHAVIORS
    from flipkit.behaviors.options import T_STRETCH
    from flipkit.planning.planners.planner import plan_flip
    from flipkit.planning.plans.verify import verify_plan

    plan = plan_flip((0.629686, -0.347136, 0.072), heading=0.0)
    assert plan.status == "solved", plan.failure
    radial = plan_flip((0.629686, -0.347136, 0.072))
    assert radial.status == "solved" and radial.segment("scoop").T <= 0.6 + 1e-9
    scoop = plan.segment("scoop")
    assert SUBBEHAVIORS["scoop"].duration[1] < scoop.T <= T_STRETCH * SUBBEHAVIORS["scoop"].duration[1] + 1e-9
    # Stretched only where needed: the pickup and flip are not; the turn back from a robust
    # flip's end state near the singularity may be.
    others = [s for s in plan.segments if s.name in ("go_to_burger", "pickup", "flip")]
    assert all(s.T <= SUBBEHAVIORS[s.name].duration[1] + 1e-9 for s in others)
    assert verify_plan(plan).ok


def test_a_duration_beyond_the_stretched_bound_fails_verify(models):
    from test_plan import translate_plan

    from flipkit.behaviors.library import SUBBEHAVIORS
    from flipkit.behaviors.options import T_STRETCH
    from flipkit.planning.plans.verify import verify_plan

    ok = translate_plan(models, durations=(T_STRETCH * SUBBEHAVIORS["translate"].duration[1] - 0.01,))
    bad = translate_plan(models, durations=(T_STRETCH * SUBBEHAVIORS["translate"].duration[1] + 0.01,))
    assert verify_plan(ok).groups["time_grid"].ok
    assert not verify_plan(bad).groups["time_grid"].ok


def test_a_warm_start_found_infeasible_tries_the_stretched_bound_before_the_cold_solve(
        monkeypatch):
    """solve_stretched: when the SQP from the warm start ends ``infeasible`` within the bound,
    the stretched bound is solved next; the cold solve within the bound comes only if that
    fails too. Any other warm failure gets the cold solve first, as before."""
    from flipkit.behaviors.options import SegmentOptions
    from flipkit.solvers.result import Status

    def run(warm_status, stretched_ok):
        calls = []

        class _NLP:
            def __init__(self, stretch):
                self.stretch = stretch

        def fake(nlp, solver="sqp", x0=None):
            calls.append(("stretched" if nlp.stretch else "bound", solver,
                          "warm" if x0 is not None else "cold"))
            if x0 is not None:
                status = warm_status
            elif nlp.stretch:
                status = Status.SOLVED if stretched_ok else Status.INFEASIBLE
            else:
                status = Status.INFEASIBLE
            return SolveResult(x=np.zeros(1), status=status, iterations=1, wall_time_s=0.5,
                               objective=0.0, max_violation=0.0)

        monkeypatch.setattr(chain, "solve_segment", fake)
        nlp, res = chain.solve_stretched(lambda o: _NLP(o.stretch), SegmentOptions(), "auto",
                                         lambda nlp: np.zeros(1))
        return calls, nlp, res

    calls, nlp, res = run(Status.INFEASIBLE, True)
    assert calls == [("bound", "sqp", "warm"), ("stretched", "auto", "cold")]
    assert nlp.stretch and res.success and res.wall_time_s == pytest.approx(1.0)
    calls, nlp, res = run(Status.INFEASIBLE, False)
    assert calls == [("bound", "sqp", "warm"), ("stretched", "auto", "cold"),
                     ("bound", "auto", "cold")]
    assert not nlp.stretch and not res.success and res.wall_time_s == pytest.approx(1.0)
    calls, _, _ = run(Status.MAX_ITER, True)
    assert calls == [("bound", "sqp", "warm"), ("bound", "auto", "cold"),
                     ("stretched", "auto", "cold")]


def test_bench_flip_reports_wall_cpu_and_iterations(capsys):
    """`bench flip` on one location: the row carries the plan's wall and CPU time and the
    solver's iterations, and the printed table has the CPU column."""
    from bench.bench import bench_flip

    out = bench_flip(CellConfig(), 1, 0, atlas=None, ipopt=False)
    row = out["rows"][0]["sqp"]
    assert row["status"] == "solved" and row["iterations"] > 0
    assert 0 < row["cpu_s"] and 0 < row["solve_s"] <= row["wall_s"]
    assert out["median"]["sqp"]["cpu_s"] == row["cpu_s"]
    assert "cpu s" in capsys.readouterr().out
