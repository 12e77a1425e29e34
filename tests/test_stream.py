"""Throughput (issue 32, item 3): the table's dwell frees served spots (a ten-burger cook is
accepted and its spots reused only after the dwell), the stream of drops (no overlapping
burgers, deterministic, a full grill refused), the duration model, the stream's report and
``flipkit schedule --stream``. Motion planners are fast fakes with fixed times."""

import json

import numpy as np
import pytest

from flipkit import cli
from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.planning.kitchen import motions
from flipkit.planning.kitchen.cook import (EXAMPLE_ORDER, CookBurger, check_cook,
                                          read_cook_csv, table_spots)
from flipkit.planning.kitchen.cpsat import MotionTimes
from flipkit.planning.kitchen.durations import MotionModel, plan_model, representative_order
from flipkit.planning.kitchen.motions import PlannedMotion
from flipkit.planning.kitchen.optimal import schedule_cook_cpsat
from flipkit.planning.kitchen.schedule import schedule_cook
from flipkit.planning.kitchen.stream import (StreamError, check_stream, n_drops,
                                             stream_order)
from flipkit.planning.kitchen.table import DWELL_S, assign_spots, check_dwell, table_rate_cap
from flipkit.planning.kitchen.throughput import run_stream, sweep_rates
from flipkit.planning.kitchen.windows import Windows

CELL = CellConfig()
MODEL = MotionModel(MotionTimes(3.40, 2.32), MotionTimes(5.90, 1.35), "test")
TEN = EXAMPLE_ORDER.with_name("cook_ten.csv")


# ---------------------------------------------------------------- the table's dwell
def test_a_ten_burger_cook_is_accepted_and_spots_are_reused_after_the_dwell():
    order = read_cook_csv(TEN, CELL)  # ten burgers, the table has nine spots
    assert len(order) == 10 > len(table_spots(CELL))
    spots = assign_spots(order, table_spots(CELL))
    # b09's serve mark (190 s) is 40 s = dwell + margin after b01's: the nearest spot again
    assert [a.previous for a in spots] == [None] * 8 + ["b01", "b02"]
    assert spots[8].spot == spots[0].spot and spots[9].spot == spots[1].spot
    for name, schedule in (("cpsat", schedule_cook_cpsat), ("greedy", schedule_cook)):
        tl = schedule(order, MODEL.planners(), np.zeros(6), cell=CELL)
        assert tl.ok and all(b.serve_time is not None for b in tl.burgers), name
        ends = {m.burger: m.end for m in tl.motions if m.kind == "serve"}
        for b, a in zip(tl.burgers, spots):
            assert b.table_spot == a.spot
            if a.previous:
                assert b.serve_time >= ends[a.previous] + DWELL_S - 1e-3


@pytest.mark.parametrize("policy", ["cpsat", "greedy"])
def test_a_serve_waits_for_its_spot_to_be_cleared(policy):
    one_spot = [(0.40, 0.60)]
    order = [CookBurger("a", 0.0, 0.64, -0.33), CookBurger("b", 10.0, 0.84, 0.12)]
    schedule = schedule_cook_cpsat if policy == "cpsat" else schedule_cook
    tl = schedule(order, MODEL.planners(), np.zeros(6), cell=CELL, spots=one_spot,
                  dwell_s=60.0, windows=Windows(serve=(0, 30)))
    a_end = next(m.end for m in tl.motions if m.key == "serve:a")
    assert tl.burgers[1].serve_time == pytest.approx(a_end + 60.0, abs=1e-3)  # not at 160 s
    assert tl.to_dict()["dwell_s"] == 60.0


def test_dwell_bounds_and_the_table_rate_cap():
    assert check_dwell(0) == 0.0 and check_dwell("45") == 45.0
    for bad in (-1, float("nan"), 1e5, "x"):
        with pytest.raises(ConfigError, match=r"\[0, 3600\]"):
            check_dwell(bad)
    assert table_rate_cap(9, 120.0) == pytest.approx(270.0)
    assert table_rate_cap(9, DWELL_S) > 3600 / (3.4 + 5.9)  # the table never binds the arm
    with pytest.raises(ConfigError):
        assign_spots(read_cook_csv(TEN, CELL), [])


# ---------------------------------------------------------------- the stream
def test_stream_burgers_never_overlap_and_the_stream_is_deterministic():
    windows = Windows()
    hold = 90 + windows.flip[1] + 60 + windows.serve[1]
    order = stream_order(300, 12, seed=4, cell=CELL, windows=windows)
    assert len(order) == n_drops(300, 12) == 60
    assert [b.t_drop for b in order[:3]] == [0.0, 12.0, 24.0]
    d = CELL.burger.diameter
    for i, a in enumerate(order):
        assert CELL.grill.contains((a.x, a.y))
        for b in order[i + 1:]:
            if b.t_drop - a.t_drop < hold:  # both on the grill at once
                assert np.hypot(a.x - b.x, a.y - b.y) >= d
    assert check_cook(order, CELL) == order
    assert stream_order(300, 12, seed=4, cell=CELL) == order
    assert stream_order(300, 12, seed=5, cell=CELL) != order


def test_a_full_grill_and_bad_stream_options_are_refused():
    with pytest.raises(StreamError, match="the grill is full"):
        stream_order(900, 5, cell=CELL)
    for rate, minutes, message in ((0, 5, "RATE"), (100, -1, "--minutes"),
                                   (float("nan"), 5, "RATE"), (1e5, 5, "RATE"),
                                   (100, 1e6, "--minutes")):
        with pytest.raises(StreamError, match=message):
            check_stream(rate, minutes)


# ---------------------------------------------------------------- the model and report
def test_the_duration_model_keeps_the_longest_representative_plan():
    seen = []

    def planner(kind):
        def plan(job, q):
            seen.append((kind, job.burger, job.table_spot))
            dur = {"flip": 3.3, "serve": 5.8}[kind] + 0.05 * len(seen)
            return PlannedMotion(True, dur, 1.0 + 0.1 * len(seen), np.asarray(q), 0.1,
                                 landing=tuple(job.location[:2]) if kind == "flip" else None)
        return plan

    model = plan_model({k: planner(k) for k in ("flip", "serve")}, np.zeros(6), CELL)
    burgers, spots = representative_order(CELL)
    assert [s[0] for s in seen] == ["flip"] * 3 + ["serve"] * 3  # flips first
    assert [s[2] for s in seen[3:]] == spots
    assert model.flip == MotionTimes(pytest.approx(3.45), pytest.approx(1.3))
    assert model.serve == MotionTimes(pytest.approx(6.1), pytest.approx(1.6))
    assert "3 planned flips (3.35-3.45 s)" in model.source
    pm = model.planners()["flip"](motions.MotionJob("flip", "x", (0.7, -0.1, 0.072)),
                                  np.ones(6))
    assert pm.ok and pm.landing == (0.7, -0.1) and np.array_equal(pm.q_end, np.ones(6))


def test_stream_report_below_and_at_a_resonant_rate():
    tl, low = run_stream(50, 10, MODEL, policy="cpsat")
    assert (low.n_burgers, low.n_within, low.per_hour_within) == (9, 9, 50.0)
    assert low.windows_met and low.max_lateness_s == pytest.approx(0.0, abs=1e-3)
    busy = 9 * (3.40 + 5.90)
    span = max(m.end for m in tl.motions) - min(m.start for m in tl.motions)
    assert low.utilisation == pytest.approx(busy / span)
    # a drop a minute puts each serve's mark on the next flip's: windows break
    rows = sweep_rates([60], 10, MODEL)
    cp, greedy = rows
    assert cp["policy"] == "cpsat" and not cp["windows_met"]
    assert cp["n_within"] > greedy["n_within"]  # fewest burgers beyond their windows
    assert greedy["max_lateness_s"] == pytest.approx(6.87, abs=1e-3)
    assert sweep_rates([900], 5, MODEL, policies=("greedy",))[0]["refused"].startswith(
        "the grill is full")


def test_a_burger_blocked_at_every_heading_counts_as_missed():
    """With the plans' footprints, a stream counts the burgers whose motions meet another
    burger at every scoop heading as missed: a footprint reaching 40 cm round its burger
    blocks every burger that shares the grill with another while its motions run; at 20 per
    hour none does (each is served before the next drops) and none is blocked."""
    import dataclasses

    from flipkit.planning.kitchen.reach import blocked_burgers
    from flipkit.planning.kitchen.sweep import Footprint

    wide = Footprint(blade=[(1.0, "scoop", np.array([[-0.4, -0.4], [0.4, -0.4], [0.4, 0.4],
                                                      [-0.4, 0.4]]))])
    model = dataclasses.replace(MODEL, footprints={"flip": wide, "serve": wide})
    tl, plain = run_stream(50, 10, MODEL, policy="greedy")
    tl2, rep = run_stream(50, 10, model, policy="greedy")
    blocked = blocked_burgers(tl2, model.footprints, CELL)
    assert plain.n_blocked is None and "not checked" in plain.summary()
    assert rep.n_blocked == len(blocked) > 0 and f"{rep.n_blocked} blocked" in rep.summary()
    assert rep.n_within == plain.n_within - rep.n_blocked
    assert rep.per_hour_within == pytest.approx(50 * rep.n_within / rep.n_burgers)
    _, sparse = run_stream(20, 10, model, policy="greedy")
    assert sparse.n_blocked == 0 and sparse.n_within == sparse.n_burgers


# ---------------------------------------------------------------- the command line
@pytest.fixture
def fake_planners(monkeypatch):
    monkeypatch.setattr(motions, "default_planners",
                        lambda kinds, cell=None, solver="auto", atlas=None, caches=None:
                        {k: v for k, v in MODEL.planners().items() if k in kinds})


def test_cli_stream_report(tmp_path, capsys, fake_planners):
    out = tmp_path / "s.json"
    assert cli.main(["schedule", "--stream", "200", "--minutes", "6", "--json", str(out),
                     "--workers", "1"]) == 0
    doc = json.loads(out.read_text())
    assert doc["stream"]["n_burgers"] == 20 and doc["stream"]["per_hour_within"] == 200
    assert doc["motion_model"]["serve"] == {"duration_s": 5.9, "event_s": 1.35}
    assert all(m["plan"] is None for m in doc["motions"])
    line = capsys.readouterr().out
    assert "20/20 burgers within their windows, 200 per hour" in line
    assert not (tmp_path / "s_plans").exists()
    # at a resonant rate the report is written and the exit is 1, one line why
    assert cli.main(["schedule", "--stream", "60", "--minutes", "10", "--json", str(out),
                     "--workers", "1", "--policy", "greedy"]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "beyond its window" in err
    assert json.loads(out.read_text())["stream"]["n_within"] == 5


def test_cli_stream_with_plan_plans_every_motion(tmp_path, fake_planners):
    out = tmp_path / "s.json"
    assert cli.main(["schedule", "--stream", "120", "--minutes", "2.5", "--plan", "--json",
                     str(out), "--workers", "1", "--no-progress", "--seed", "3"]) == 0
    doc = json.loads(out.read_text())
    assert len(doc["burgers"]) == 5 and doc["stream"]["n_within"] == 5


@pytest.mark.parametrize("argv, message", [
    (["--stream", "100"], "needs --minutes"),
    (["--minutes", "3", str(EXAMPLE_ORDER)], "go with --stream"),
    (["--stream", "100", "--minutes", "3", str(EXAMPLE_ORDER)], "not BURGERS.csv and --stream"),
    ([], "BURGERS.csv, --stream RATE or --random N"),
    (["--stream", "100", "--minutes", "3", "--figure", "g.png"], "--plan"),
    (["--stream", "100", "--minutes", "3", "--flip-only"], "--plan"),
    (["--stream", "1e5", "--minutes", "3"], "RATE"),
    ([str(EXAMPLE_ORDER), "--dwell", "-1"], "--dwell"),
    ([str(EXAMPLE_ORDER), "--window", "flip=0"], "EVENT=EARLY,LATE"),
    ([str(EXAMPLE_ORDER), "--time-limit", "0"], "--time-limit"),
])
def test_cli_stream_and_option_errors_are_one_line(argv, message, tmp_path, capsys):
    out = tmp_path / "t.json"
    assert cli.main(["schedule", *argv, "--json", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("flipkit: error:") and "\n" not in err and message in err
    assert not out.exists()
