"""The cook-window scheduler (issue 13, item 3): the cook order CSV and its errors, table
spots, the earliest-deadline-first policy with injected fixed-duration planners (ordering,
lateness, slack, threading of configurations, failures), a missing planner, and the
real flip planner end to end through ``flipkit schedule --flip-only``."""

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from flipkit import cli
from flipkit.behaviors import library
from flipkit.config import CellConfig
from flipkit.errors import InvalidChoiceError
from flipkit.planning.kitchen import cook, motions
from flipkit.planning.kitchen.cook import CookBurger, CookOrderError, check_cook, read_cook_csv
from flipkit.planning.kitchen.motions import MissingPlannerError, PlannedMotion
from flipkit.planning.kitchen.schedule import schedule_cook

CELL = CellConfig()
FLIP_T, FLIP_EVENT, SERVE_T, SERVE_EVENT = 3.4, 2.2, 5.0, 1.5  # s, the fixed planners


class Fixed:
    """Deterministic planners: fixed duration, event time and planning time per kind; each
    motion ends at a distinct configuration and every call is logged."""

    def __init__(self, plan_s=1.0, fail=()):
        self.calls, self.plan_s, self.fail = [], plan_s, set(fail)

    def planner(self, kind, duration, event):
        def plan(job, q_start):
            n = len(self.calls) + 1
            self.calls.append((job, np.array(q_start)))
            ok = (kind, job.burger) not in self.fail
            return PlannedMotion(ok=ok, duration_s=duration, event_s=event,
                                 q_end=np.full(6, float(n)), planning_time_s=self.plan_s,
                                 landing=(job.location[0] + 0.01, job.location[1])
                                 if kind == "flip" else None,
                                 failure=None if ok else "pickup: cone violated by 1 (test)")
        return plan

    def planners(self):
        return {"flip": self.planner("flip", FLIP_T, FLIP_EVENT),
                "serve": self.planner("serve", SERVE_T, SERVE_EVENT)}


def order(drops, xs=None):
    xs = xs or [0.62 + 0.11 * (k % 3) for k in range(len(drops))]
    return [CookBurger(f"b{k + 1}", float(t), xs[k], -0.45 + 0.12 * k)
            for k, t in enumerate(drops)]


def run(drops, kinds=("flip", "serve"), **kw):
    fixed = Fixed(**{k: kw.pop(k) for k in ("plan_s", "fail") if k in kw})
    tl = schedule_cook(order(drops), fixed.planners(), np.zeros(6), kinds=kinds, cell=CELL,
                       **kw)
    return tl, fixed


def assert_feasible(tl):
    """No overlapping motions; no side cooked short."""
    done = [m for m in tl.motions if m.ok]
    for a, b in zip(done, done[1:]):
        assert b.start >= a.end - 1e-12
    for b in tl.burgers:
        if b.flip_time is not None:
            assert b.flip_time - b.burger.t_drop >= cook.FIRST_SIDE_S - 1e-9
        if b.serve_time is not None:
            assert b.serve_time - b.flip_time >= cook.SECOND_SIDE_S - 1e-9


# ---------------------------------------------------------------- the policy, exactly
def test_spread_drops_are_flipped_and_served_on_their_marks():
    tl, _ = run([0, 5, 10, 15, 20])
    assert tl.ok and [m.key for m in tl.motions] == (
        [f"flip:b{k}" for k in range(1, 6)] + [f"serve:b{k}" for k in range(1, 6)])
    for b in tl.burgers:
        assert b.lateness() == {"flip": 0.0, "serve": 0.0}
    assert_feasible(tl)
    assert tl.motions[0].start == pytest.approx(90 - FLIP_EVENT)
    # planning started at the first drop, 1 s per motion: flip b1 ready at t = 1 s
    assert tl.motions[0].slack_s == pytest.approx(90 - FLIP_EVENT - 1.0)
    assert tl.min_slack_s == pytest.approx(tl.motions[0].slack_s)
    assert tl.planning_time_s == pytest.approx(10.0)
    spots = cook.table_spots(CELL)
    assert [b.table_spot for b in tl.burgers] == spots[:5]


def test_competing_flips_queue_in_deadline_order_with_exact_lateness():
    tl, _ = run([2, 0, 1], kinds=("flip",))  # listed out of order: sorted by drop
    assert [m.key for m in tl.motions] == ["flip:b2", "flip:b3", "flip:b1"]
    late = {b.burger.burger: b.lateness()["flip"] for b in tl.burgers}
    # b2 lands at 90; b3's flip waits for the arm (ends 87.8 + 3.4 = 91.2) and lands 2.4 s
    # after its mark; b1 waits again: 91.2 + 3.4 + 2.2 = 96.8 against 92
    assert late == pytest.approx({"b2": 0.0, "b3": 2.4, "b1": 4.8})
    assert all(b.serve_time is None and b.lateness()["serve"] is None for b in tl.burgers)
    assert_feasible(tl)


def test_a_serve_due_later_waits_for_an_earlier_flip():
    # b1's serve is due at 150 (lift-off), b2's flip at 148 (landing): flip b2 goes first
    tl, _ = run([0, 58])
    assert [m.key for m in tl.motions] == ["flip:b1", "flip:b2", "serve:b1", "serve:b2"]
    flip_b2_end = 148 - FLIP_EVENT + FLIP_T
    assert tl.burgers[0].serve_time == pytest.approx(flip_b2_end + SERVE_EVENT)
    assert tl.burgers[0].lateness()["serve"] == pytest.approx(flip_b2_end + SERVE_EVENT - 150)
    assert tl.burgers[1].lateness() == pytest.approx({"flip": 0.0, "serve": 0.0})
    assert_feasible(tl)


def test_a_late_flip_pushes_the_serve_to_sixty_seconds_after_landing():
    tl, _ = run([0, 0.5])
    b2 = tl.burgers[1]
    assert b2.lateness()["flip"] == pytest.approx(FLIP_T - 0.5)
    # its serve is due 60 s after its landing (153.4), not at its 150 s mark (150.5), but
    # b1's serve (due 150, lift-off 1.5 s in, 5 s long) holds the arm until 153.5
    assert b2.serve_time == pytest.approx(150 - SERVE_EVENT + SERVE_T + SERVE_EVENT)
    assert b2.serve_time - b2.flip_time >= 60
    # b2's flip (due 150) ties with b1's serve (due 150): b1 (dropped first) goes first,
    # b2 lands 5.7 s late, and with the arm free its serve lifts off exactly 60 s later
    tl1, _ = run([0, 60])
    assert [m.key for m in tl1.motions] == ["flip:b1", "serve:b1", "flip:b2", "serve:b2"]
    late = tl1.burgers[1]
    assert late.lateness()["flip"] == pytest.approx(150 - SERVE_EVENT + SERVE_T - 150
                                                    + FLIP_EVENT)
    assert late.serve_time == pytest.approx(late.flip_time + 60)
    assert late.lateness()["serve"] == pytest.approx(late.lateness()["flip"])


def test_planning_that_falls_behind_gives_negative_slack_and_delays_the_motion():
    tl, _ = run([0, 1], kinds=("flip",), plan_s=50.0)
    m1, m2 = tl.motions
    assert m1.planned_at == 50 and m1.slack_s == pytest.approx(90 - FLIP_EVENT - 50)
    assert m2.planned_at == 100 and m2.slack_s == pytest.approx(87.8 + FLIP_T - 100)
    assert m2.start == 100  # waits for its plan
    assert tl.burgers[1].lateness()["flip"] == pytest.approx(100 + FLIP_EVENT - 91)
    assert tl.to_dict()["slack_s"]["min"] == pytest.approx(m2.slack_s)


def test_plan_start_moves_the_planning_clock():
    tl, _ = run([30, 35], kinds=("flip",), plan_start=0.0)
    assert tl.motions[0].planned_at == 1.0 and tl.plan_start == 0.0


def test_each_motion_starts_where_the_previous_one_ended():
    tl, fixed = run([0, 5, 10])
    starts = [q for _, q in fixed.calls]
    assert np.array_equal(starts[0], np.zeros(6))
    for n, q in enumerate(starts[1:], 1):
        assert np.array_equal(q, np.full(6, float(n)))
    serve_jobs = [job for job, _ in fixed.calls if job.kind == "serve"]
    # the serve goes to where the flip landed (the fixed planner lands 1 cm further in x)
    assert serve_jobs[0].location == pytest.approx((0.63, -0.45, CELL.grill.height))


def test_a_failed_plan_is_not_executed_and_its_burger_is_not_served():
    tl, fixed = run([0, 5, 10], fail=[("flip", "b2")])
    assert not tl.ok
    assert [m.key for m in tl.motions] == ["flip:b1", "flip:b2", "flip:b3", "serve:b1",
                                           "serve:b3"]
    b2 = tl.burgers[1]
    assert b2.flip_time is None and b2.serve_time is None and "cone violated" in b2.failure
    # the arm did not move: flip b3 starts from where flip b1 ended
    assert np.array_equal(fixed.calls[2][1], np.full(6, 1.0))
    doc = tl.to_dict()
    assert doc["status"] == "failed" and doc["motions"][1]["event"] is None
    assert_feasible(tl)


def test_random_orders_respect_cook_times_and_one_arm():
    rng = np.random.default_rng(3)
    for _ in range(20):
        drops = np.sort(rng.uniform(0, 120, 6)).round(2).tolist()
        tl, _ = run(drops)
        assert tl.ok and len(tl.motions) == 12
        assert_feasible(tl)
        doc = tl.to_dict()
        assert set(doc["slack_s"]["by_motion"]) == {m.key for m in tl.motions}


def test_timeline_json_fields():
    doc = run([0, 5])[0].to_dict()
    json.dumps(doc, allow_nan=False)
    assert {"burger", "t_drop", "flip_time", "serve_time", "lateness_s"} <= set(doc["burgers"][0])
    assert {"kind", "burger", "start", "end", "plan"} <= set(doc["motions"][0])
    assert doc["planning_time_s"] == 4.0 and doc["kinds"] == ["flip", "serve"]


# ---------------------------------------------------------------- the planners
def test_a_kind_without_a_planner_is_refused():
    assert set(motions.default_planners(("flip",))) == {"flip"}
    with pytest.raises(InvalidChoiceError, match="'stir'"):
        motions.default_planners(("flip", "stir"))
    with pytest.raises(MissingPlannerError, match="'serve'"):
        schedule_cook(order([0]), {"flip": Fixed().planners()["flip"]}, np.zeros(6))


def test_serve_planner_calls_plan_serve_from_the_start_configuration(monkeypatch):
    seen = {}

    serve_behavior = library.behavior("serve")  # its steps by role

    def fake_plan_serve(burger, table_spot, q_start=None, **kw):
        seen.update(burger=burger, spot=table_spot, q=q_start, **kw)
        seg = [SimpleNamespace(name=n, T=t, q=np.full((21, 6), k))
               for k, (n, t) in enumerate([("go_to_burger", 0.7), ("scoop", 0.6),
                                           ("pickup", 0.3), ("carry", 1.0)])]
        starts = dict(zip([g.name for g in seg], np.cumsum([0.0] + [g.T for g in seg])))
        return SimpleNamespace(status="solved", segments=seg, behavior="serve",
                               duration=sum(g.T for g in seg),
                               step_span=lambda role: (starts[serve_behavior.step(role).name],
                                                       None))

    monkeypatch.setattr(motions, "plan_serve", fake_plan_serve)
    serve = motions.default_planners(("flip", "serve"), CELL, "sqp")["serve"]
    pm = serve(motions.MotionJob("serve", "b1", (0.7, -0.2, 0.072), (0.4, 0.6)), np.ones(6))
    assert seen["burger"] == (0.7, -0.2, 0.072) and seen["spot"] == (0.4, 0.6)
    assert np.array_equal(seen["q"], np.ones(6)) and seen["solver"] == "sqp"
    assert pm.ok and pm.event_s == pytest.approx(1.3) and pm.duration_s == pytest.approx(2.6)
    assert np.array_equal(pm.q_end, np.full(6, 3.0))


# ---------------------------------------------------------------- the cook order
def test_table_spots_do_not_overlap_and_lie_on_the_table():
    spots = np.array(cook.table_spots(CELL))
    d, t = CELL.burger.diameter, CELL.table
    assert len(spots) == 9
    gaps = [np.hypot(*(a - b)) for i, a in enumerate(spots) for b in spots[i + 1:]]
    assert min(gaps) >= d + cook.SPOT_GAP - 1e-12
    assert spots[:, 0].min() - d / 2 >= t.x_range[0] and spots[:, 0].max() + d / 2 <= t.x_range[1]
    assert spots[:, 1].min() - d / 2 >= t.y_range[0] and spots[:, 1].max() + d / 2 <= t.y_range[1]


BAD_CSVS = {
    "missing column": ("burger,t_drop,x\nb1,0,0.7\n", "missing column 'y'"),
    "wrong header": ("id,t,x,y\nb1,0,0.7,-0.2\n", "header must be burger,t_drop,x,y"),
    "negative time": ("burger,t_drop,x,y\nb1,-1,0.7,-0.2\n", "t_drop must be >= 0"),
    "nan": ("burger,t_drop,x,y\nb1,0,nan,-0.2\n", "finite"),
    "not a number": ("burger,t_drop,x,y\nb1,zero,0.7,-0.2\n", "line 2"),
    "off grill": ("burger,t_drop,x,y\nb1,0,1.2,-0.2\n", "off the grill"),
    "too close": ("burger,t_drop,x,y\nb1,0,0.70,-0.20\nb2,30,0.75,-0.17\n",
                  "one burger diameter"),
    "duplicate id": ("burger,t_drop,x,y\nb1,0,0.70,-0.20\nb1,5,0.70,0.0\n", "twice"),
    "short row": ("burger,t_drop,x,y\nb1,0,0.7\n", "expected 4 values"),
    "no rows": ("burger,t_drop,x,y\n", "no burgers"),
    "empty": ("", "empty"),
}


@pytest.mark.parametrize("name", BAD_CSVS)
def test_malformed_cook_orders_are_one_line_and_exit_2(name, tmp_path, capsys):
    text, message = BAD_CSVS[name]
    path = tmp_path / "order.csv"
    path.write_text(text)
    with pytest.raises(CookOrderError, match=message):
        read_cook_csv(path, CELL)
    out = tmp_path / "t.json"
    assert cli.main(["schedule", str(path), "--json", str(out), "--flip-only"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("flipkit: error:") and "\n" not in err and "Traceback" not in err
    assert not out.exists() and not (tmp_path / "t_plans").exists()


def test_same_spot_is_fine_once_the_first_burger_is_gone(tmp_path):
    path = tmp_path / "order.csv"
    path.write_text("# a comment\nburger,t_drop,x,y\nb2,160,0.7,-0.2\n\nb1,0,0.7,-0.2\n")
    assert [b.burger for b in read_cook_csv(path, CELL)] == ["b1", "b2"]
    with pytest.raises(CookOrderError):
        check_cook([CookBurger("a", 0, 0.7, -0.2), CookBurger("b", 149, 0.7, -0.25)], CELL)


# ---------------------------------------------------------------- real plan_flip, end to end
@pytest.mark.slow
def test_flip_only_schedule_with_the_real_planner(tmp_path, capsys):
    from flipkit.planning.plans.plan_file import Plan
    from flipkit.planning.plans.verify import verify_plan

    path = tmp_path / "order.csv"
    path.write_text("burger,t_drop,x,y\nb1,0,0.69,-0.16\n")
    out, fig = tmp_path / "t.json", tmp_path / "gantt.png"
    code = cli.main(["schedule", str(path), "--json", str(out), "--flip-only", "--figure",
                     str(fig), "--no-progress", "--policy", "greedy"])  # exact to the plan
    assert code == 0, capsys.readouterr().err
    doc = json.loads(out.read_text())
    (m,), (b,) = doc["motions"], doc["burgers"]
    assert m["kind"] == "flip" and m["status"] == "solved" and b["serve_time"] is None
    assert b["lateness_s"]["flip"] == pytest.approx(0.0, abs=1e-6)  # the arm was free
    plan = Plan.load(tmp_path / m["plan"])
    assert plan.status == "solved" and verify_plan(plan).ok
    segs = {s.name: s for s in plan.segments}
    landing = (sum(s.T for s in plan.segments[:3]) + segs["flip"].release["time"]
               + segs["flip"].landing["time_of_flight"])
    assert m["event"] - m["start"] == pytest.approx(landing, abs=1e-6)
    assert m["end"] - m["start"] == pytest.approx(sum(s.T for s in plan.segments), abs=1e-6)
    assert b["flip_time"] == pytest.approx(90.0, abs=1e-6)
    assert np.allclose(plan.segments[-1].q[-1], CELL.robot.q_home, atol=1e-6)
    # ready at planned_at (planning starts at the drop, t = 0; in a worker process by default,
    # so planned_at also counts the worker's start-up), started so that it lands at 90 s
    assert m["planning_time_s"] > 0 and m["planned_at"] >= m["planning_time_s"] - 1e-6
    assert m["slack_s"] == pytest.approx(90 - landing - m["planned_at"], abs=1e-3)
    assert fig.stat().st_size > 5000
    assert math.isclose(doc["planning_time_s"], m["planned_at"], abs_tol=1e-5)  # wall, from t = 0


def test_gantt_draws_every_motion_and_burger(tmp_path):
    import matplotlib.pyplot as plt

    from flipkit import figures
    from flipkit.figures.draw import plot_schedule

    doc = run([0, 5, 10], fail=[("flip", "b2")])[0].to_dict()
    with figures.style():
        fig, ax = plt.subplots()
        drawn = plot_schedule(ax, doc)
        labels = [t.get_text() for t in ax.get_yticklabels()]
        fig.savefig(tmp_path / "g.png")
        plt.close(fig)
    assert drawn == {"n_burgers": 3, "n_motions": 5,
                     "t_end_s": pytest.approx(max(m["end"] for m in doc["motions"]) + 5)}
    assert labels == ["planning", "arm", "burger b1", "burger b2", "burger b3"]
    assert (tmp_path / "g.png").stat().st_size > 5000


def test_cli_writes_the_timeline_and_exits_1_on_a_failed_plan(tmp_path, capsys, monkeypatch):
    fixed = Fixed(fail=[("flip", "b2")])
    monkeypatch.setattr(motions, "default_planners", lambda kinds, cell, solver, atlas=None,
                        caches=None: {
        k: v for k, v in fixed.planners().items() if k in kinds})
    path = tmp_path / "order.csv"
    path.write_text("burger,t_drop,x,y\nb1,0,0.64,-0.33\nb2,5,0.69,-0.16\nb3,10,0.75,0.0\n")
    out, fig = tmp_path / "t.json", tmp_path / "g.pdf"
    code = cli.main(["schedule", str(path), "--json", str(out), "--figure", str(fig),
                     "--no-progress", "--workers", "1",  # the stubbed planners, in-process
                     "--policy", "greedy"])  # they end away from rest: the greedy rule
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert code == 1 and err == ["flipkit: error: burger b2: flip: pickup: cone violated by 1 "
                                 "(test)"]
    # nothing about the windows or the other burgers is claimed for a failed schedule
    summary = captured.out.strip().splitlines()[-1]
    assert "failed" in summary and "met" not in summary and "not checked" in summary
    doc = json.loads(out.read_text())
    assert doc["status"] == "failed" and [m["kind"] for m in doc["motions"]] == [
        "flip", "flip", "flip", "serve", "serve"]
    assert doc["burgers"][0]["lateness_s"] == {"flip": 0.0, "serve": 0.0}
    assert fig.read_bytes().startswith(b"%PDF")
