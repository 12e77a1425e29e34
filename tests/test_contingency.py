"""Contingency flips (flipkit.planning.planners.contingency): re-plans made ahead for places
beyond a robust plan's scenario set, handed out by a check of the measured place instead of a
solve."""

import numpy as np
import pytest

from flipkit.errors import ConfigError
from flipkit.planning.planners.chain import Planner
from flipkit.planning.planners.contingency import (MARGIN, Contingencies,
                                                   contingency_places)
from flipkit.planning.planners.planner import covers, keeps_promise, landing_miss, promise
from flipkit.planning.plans.verify import verify_plan


@pytest.fixture(scope="module")
def side(flip_plan):
    """The contingencies of the two sideways places (the slowest part: two solves)."""
    return Contingencies.prepare(flip_plan, contingency_places(flip_plan)[2:])


def _flip(plan):
    return plan.segment("flip")


def test_places_lie_past_the_scenarios_by_the_margin(flip_plan):
    landing = _flip(flip_plan).landing
    pts = np.array([r["burger_on_blade"][:2] for r in landing["scenarios"]])
    x0, y0 = landing["burger_on_blade"][:2]
    back, front, right, left = contingency_places(flip_plan)
    assert back == pytest.approx((pts[:, 0].min() - MARGIN[0], y0))
    assert front == pytest.approx((pts[:, 0].max() + MARGIN[0], y0))
    assert right == pytest.approx((x0, pts[:, 1].min() - MARGIN[1]))
    assert left == pytest.approx((x0, pts[:, 1].max() + MARGIN[1]))
    # clipped to the blade (16 x 12 cm) when the margin reaches past it
    far = contingency_places(flip_plan, margin=(0.5, 0.5))
    assert max(abs(p[0]) for p in far) == pytest.approx(0.08)
    assert max(abs(p[1]) for p in far) == pytest.approx(0.06)


def test_each_contingency_is_a_verified_replan_for_its_place(flip_plan, side):
    assert len(side.flips) == 2 and not side.failed and side.wall_time_s > 0
    assert len(side.ready_s) == 2 and side.ready_s[0] < side.ready_s[1] <= side.wall_time_s
    assert side.sense_s is None and side.wait_s(1) == 0.0  # no sense time: all count ready
    models = Planner(flip_plan.cell()).models
    for place, plan in side.flips:
        assert plan.status == "solved" and verify_plan(plan).ok
        for name in ("go_to_burger", "scoop", "pickup"):  # kept from the plan
            old = flip_plan.segment(name)
            np.testing.assert_array_equal(plan.segment(name).q,
                                          old.q)
        assert _flip(plan).landing["burger_on_blade"][:2] == pytest.approx(place)
        assert landing_miss(_flip(plan), place, models) <= _flip(plan).landing["r_land"] + 1e-3
        # and the plan itself does not keep its promise there: that is what it is for
        assert not keeps_promise(flip_plan, place, models)


def test_lookup_hands_out_the_contingency_that_lands_the_measured_place(flip_plan, side):
    (place, plan), _ = side.flips
    assert side.lookup(place) is plan
    models = Planner(flip_plan.cell()).models
    kept = []
    for step in (0.003, -0.003, 0.009, -0.009, 0.02):  # further out, further in
        near = (place[0], place[1] + np.sign(place[1]) * step)
        kept.append(landing_miss(_flip(plan), near, models) <= promise(flip_plan)
                    or covers(_flip(plan).landing, near))
        assert (side.lookup(near) is plan) == kept[-1]
    # a contingency is robust to the camera's error: it covers the places 9 mm from its own
    assert kept[:4] == [True] * 4
    assert side.lookup((-0.075, 0.0)) is None  # at the blade's back: none lands it


def test_the_replan_keeps_the_plan_uses_a_contingency_or_solves(flip_plan, side):
    x0, y0 = _flip(flip_plan).landing["burger_on_blade"][:2]
    assert side(flip_plan, (x0, y0)) is flip_plan  # the predicted place: kept
    (place, plan), _ = side.flips
    assert side(flip_plan, place) is plan
    solved = side(flip_plan, (-0.075, 0.0))
    assert solved is not flip_plan and all(solved is not p for _, p in side.flips)
    assert solved.status == "solved"
    assert _flip(solved).landing["burger_on_blade"][:2] == pytest.approx((-0.075, 0.0))
    with pytest.raises(ConfigError, match="another plan"):
        side(solved, place)
    with pytest.raises(ConfigError):
        side(flip_plan, (0.3, 0.0))  # off the blade


def test_bench_replan_times_the_replan_with_and_without_contingencies(capsys):
    from bench.bench_replan import bench_replan

    loc, x0 = [0.69, -0.16, 0.072], 0.036
    result = {"locations": [{"location": loc, "landings": [
        {"replan": {"sensed_on_blade": [x0, 0.0]}},
        {"replan": {"sensed_on_blade": [x0, -0.035]}}]}]}
    out = bench_replan(result, contingencies=True)
    near, far = out["rows"]
    assert near["kept"] and near["contingency_how"] == "kept"
    assert not far["kept"] and far["status"] == "solved"  # solved without contingencies
    assert far["contingency_how"] == "contingency"  # handed one with them
    assert far["contingency_time_s"] < far["time_s"]
    c = out["summary"]["contingencies"]
    assert c["served"] == {"kept": 1, "contingency": 1, "solved": 0}
    assert c["prepared"][0]["solved"] == 4 and c["prepare_worst_s"] > 0
    assert "handed a contingency" in capsys.readouterr().out


def test_bench_replan_records_a_place_off_the_blade_as_refused(capsys):
    """A sensed place past the blade's edge is refused by the planner: the bench records and
    counts it apart instead of stopping, and times the others."""
    from bench.bench_replan import bench_replan

    result = {"locations": [{"location": [0.69, -0.16, 0.072], "landings": [
        {"replan": {"sensed_on_blade": [0.083, 0.0]}},
        {"replan": {"sensed_on_blade": [0.036, 0.0]}}]}]}
    out = bench_replan(result)
    off, on = out["rows"]
    assert "within ±0.08" in off["refused"] and on["kept"]
    assert out["summary"]["refused"] == 1 and out["summary"]["replans"] == 1
    assert "1 sensed place(s) off the blade refused" in capsys.readouterr().out


def test_prepared_on_an_executor_the_contingencies_are_the_same(flip_plan, side):
    from concurrent.futures import ThreadPoolExecutor

    place, plan = side.flips[0]
    with ThreadPoolExecutor(1) as pool:
        pooled = Contingencies.prepare(flip_plan, [place], executor=pool)
    (same, other), = pooled.flips
    assert same == pytest.approx(place) and len(pooled.ready_s) == 1
    np.testing.assert_array_equal(_flip(other).q, _flip(plan).q)
