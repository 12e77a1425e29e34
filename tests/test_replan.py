"""Sense, plan, act: the flip re-planned for the burger's measured place on the blade, in the
MuJoCo cell; and the baselines that must fail — a plan made without the landing constraint,
and a replan that cannot be solved (the verified original then runs on)."""

import numpy as np
import pytest

from flipkit.behaviors.options import SegmentOptions
from flipkit.simulation.judges import LANDING_TOL, judge_flip, judge_scoop, landing_target
from flipkit.errors import ConfigError, FlipkitError
from flipkit.simulation.execute import execute_plan
from flipkit.config import SensingUncertainty
from flipkit.planning.planners.chain import Planner
from flipkit.planning.planners.planner import (keeps_promise, plan_flip, replan_flip,
                                               sensed_scenarios)
from flipkit.planning.plans.verify import verify_plan


def always_replan(plan, on_blade):
    return replan_flip(plan, on_blade, keep=False)


@pytest.fixture(scope="module")
def replanned(flip_plan):
    return execute_plan(flip_plan, "feedforward", replan=always_replan)


def test_replanned_flip_is_verified_and_made_for_the_sensed_burger(flip_plan, replanned):
    ex = replanned
    sensed = np.asarray(ex.sensed_on_blade)
    assert ex.replan_failure is None and ex.plan is not flip_plan
    # the scoop drags the burger toward the blade's tip: measured ahead of the blade centre
    assert 0.005 < sensed[0] < flip_plan.spatula["length"] / 2
    assert ex.plan.status == "solved" and verify_plan(ex.plan).ok
    flip = ex.plan.segment("flip")
    np.testing.assert_allclose(flip.landing["burger_on_blade"], sensed, atol=1e-12)
    kept = [s.name for s in ex.plan.segments[:3]]
    assert kept == ["go_to_burger", "scoop", "pickup"]
    for a, b in zip(flip_plan.segments[:3], ex.plan.segments[:3]):
        np.testing.assert_array_equal(a.q, b.q)  # executed before the sensing, or unchanged


def test_replanned_flip_lands_the_places_the_camera_may_have_missed(flip_plan, replanned):
    """The measurement errs by 5 mm per axis: the re-plan lands the places 2 sigma (1 cm)
    along and across the blade from it as the plan lands its scenarios, and verify checks
    each of them."""
    sensed = np.asarray(replanned.sensed_on_blade)
    flip = replanned.plan.segment("flip")
    places = np.array([row["burger_on_blade"][:2] for row in flip.landing["scenarios"]])
    want = sensed + np.array([[-0.01, 0.0], [0.01, 0.0], [0.0, -0.01], [0.0, 0.01]])
    np.testing.assert_allclose(places, want, atol=1e-12)
    assert all(row["r_land"] == flip_plan.segment("flip").landing["scenarios"][0]["r_land"]
               for row in flip.landing["scenarios"])
    report = verify_plan(replanned.plan)
    assert report.ok and "landing_scenarios" in report.groups
    # so the re-plan keeps its promise for a burger 9 mm off the measurement, unsolved
    models = Planner(flip_plan.cell()).models
    assert keeps_promise(replanned.plan, sensed + (0.009, 0.0), models)


def test_sensed_scenarios_span_the_camera_error_on_the_blade(flip_plan):
    cell = flip_plan.cell()
    got = sensed_scenarios(cell, (0.01, -0.02), SensingUncertainty(sigma=0.004, k_sigma=1.5))
    np.testing.assert_allclose(got, [(0.004, -0.02), (0.016, -0.02), (0.01, -0.026),
                                     (0.01, -0.014)], atol=1e-12)
    edge = sensed_scenarios(cell, (0.075, 0.0))  # clipped at the blade's tip (8 cm)
    assert edge[1][0] == pytest.approx(0.08) and edge[0][0] == pytest.approx(0.065)
    for bad in ({"sigma": -0.001}, {"k_sigma": float("nan")}):
        with pytest.raises(ConfigError, match="must be a finite number"):
            SensingUncertainty(**bad)


def test_replanned_flip_lands_on_its_spot(replanned):
    run, bounds = replanned.run, replanned.bounds
    assert judge_scoop(run, bounds["scoop"]).ok
    verdict = judge_flip(run, bounds["flip"], landing_target(replanned.plan))
    assert verdict.ok, verdict
    assert np.all(np.abs(verdict.offset) <= LANDING_TOL)


def test_a_plan_without_the_landing_constraint_misses(flip_plan):
    loc = flip_plan.burger["location"]
    plan = plan_flip(loc, options=SegmentOptions(landing=False))
    flip = plan.segment("flip")
    assert flip.landing is None and plan.status == "failed"  # verify: no landing
    assert "landing" in plan.failure
    plan.status = "solved"  # execute it anyway, as the paper's flip (26) alone
    ex = execute_plan(plan, "feedforward")
    verdict = judge_flip(ex.run, ex.bounds["flip"], np.asarray(loc)[:2])
    assert not verdict.ok
    assert np.max(np.abs(verdict.offset)) > LANDING_TOL or not verdict.upside_down


def test_a_failed_replan_leaves_the_verified_plan_running(flip_plan):
    def refuse(plan, on_blade):
        raise FlipkitError("no solution found (infeasible)")

    ex = execute_plan(flip_plan, "feedforward", replan=refuse)
    assert ex.plan is flip_plan and "infeasible" in ex.replan_failure
    assert ex.sensed_on_blade is not None


def test_replan_rejects_a_burger_off_the_blade(flip_plan):
    with pytest.raises(ConfigError, match="on the blade"):
        replan_flip(flip_plan, (0.5, 0.0))


def test_no_replan_for_a_burger_the_scoop_missed(flip_plan):
    """A burger lying 20 cm to the side of the scoop's line is not on the blade when the
    scoop ends: the cell does not re-plan for a clipped, made-up position on the blade; the
    verified plan runs on and the judges see the miss."""
    calls = []

    def record(plan, on_blade):
        calls.append(on_blade)
        return replan_flip(plan, on_blade)

    draw = {"dx_m": 0.0, "dy_m": 0.2, "grill_offset_m": 0.0, "mu_factor": 1.0, "mass_factor": 1.0}
    ex = execute_plan(flip_plan, "feedforward", draw, replan=record)
    assert calls == [] and ex.plan is flip_plan
    assert ex.replan_failure.startswith("burger not on the blade after the scoop")
    assert abs(ex.sensed_on_blade[1]) > flip_plan.spatula["width"] / 2
    assert not judge_scoop(ex.run, ex.bounds["scoop"]).ok


def test_a_replan_too_slow_for_the_run_leaves_the_verified_plan_under_way(flip_plan,
                                                                             monkeypatch):
    """A re-plan whose wall time would hold the arm past the run's room (a loaded machine)
    is dropped: the run ends on the verified plan, the record says why, nothing raises."""
    import flipkit.simulation.execute as execute

    clock = [0.0]
    monkeypatch.setattr(execute.time, "perf_counter", lambda: clock[0])

    def slow(plan, on_blade):
        clock[0] += 1000.0  # the re-plan took 1000 s
        return plan

    ex = execute_plan(flip_plan, "feedforward", replan=slow)
    assert ex.plan is flip_plan
    assert "re-plan took 1000.00 s" in ex.replan_failure
    assert "verified plan ran on" in ex.replan_failure
    assert judge_flip(ex.run, ex.bounds["flip"], landing_target(flip_plan)).ok
