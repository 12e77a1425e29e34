"""Cooks as a camera sees them: flipkit schedule --random N --seed S
(flipkit.planning.kitchen.random_cook)."""

import json
import math

import numpy as np
import pytest

from flipkit.cli import main
from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.planning.kitchen.cook import check_cook
from flipkit.planning.kitchen.cook_plan import PlannedCook, first_random_cook
from flipkit.planning.kitchen.random_cook import MAX_RANDOM, random_order
from flipkit.planning.kitchen.turns import CookConflictError
from flipkit.planning.kitchen.windows import WindowBreak

CELL = CellConfig()


@pytest.mark.parametrize("seed", range(20))
def test_random_burgers_lie_apart_on_the_grill_and_drop_4_to_5_s_apart(seed):
    order = random_order(5, seed, CELL)
    assert [b.burger for b in order] == ["r1", "r2", "r3", "r4", "r5"]
    gaps = np.diff([b.t_drop for b in order])
    assert order[0].t_drop == 0.0 and np.all((gaps >= 4.0 - 1e-3) & (gaps <= 5.0 + 1e-3))
    g, d = CELL.grill, CELL.burger.diameter
    for b in order:  # the whole burger on the grill
        assert g.x_range[0] + d / 2 <= b.x <= g.x_range[1] - d / 2
        assert g.y_range[0] + d / 2 <= b.y <= g.y_range[1] - d / 2
    xy = np.array([(b.x, b.y) for b in order])
    dist = np.linalg.norm(xy[:, None] - xy[None], axis=2) + np.eye(len(xy))
    assert dist.min() >= d
    assert check_cook(order, CELL) == order  # a valid cook order, in drop order


def test_same_seed_same_cook_other_seed_other_places():
    assert random_order(5, 7, CELL) == random_order(5, 7, CELL)
    a, b = random_order(5, 7, CELL), random_order(5, 8, CELL)
    assert [(u.x, u.y) for u in a] != [(v.x, v.y) for v in b]


def test_the_places_are_spread_over_the_grill():
    """Over many seeds the places cover the grill's width, not lanes: every 10 cm band of y
    inside the burgers' range holds some."""
    ys = [b.y for s in range(40) for b in random_order(5, s, CELL)]
    lo, hi = CELL.grill.y_range[0] + 0.05, CELL.grill.y_range[1] - 0.05
    bands = np.histogram(ys, bins=np.arange(lo, hi, 0.1))[0]
    assert bands.min() > 0


@pytest.mark.parametrize("gap", [0.03, 0.04])
def test_a_gap_keeps_the_burgers_edges_that_far_apart(gap):
    """With ``gap`` the least edge-to-edge distance over 20 seeds is at least the gap, and
    below it with the default (1 mm): the default cooks have burgers closer than 3 cm."""
    def least(order):
        xy = np.array([(b.x, b.y) for b in order])
        return (np.linalg.norm(xy[:, None] - xy[None], axis=2) + np.eye(len(xy))).min()

    d = CELL.burger.diameter
    assert min(least(random_order(5, s, CELL, gap=gap)) for s in range(20)) >= d + gap - 1e-4
    assert min(least(random_order(5, s, CELL)) for s in range(20)) < d + 0.03


@pytest.mark.parametrize("gap", [0.0, -0.01, 0.25, math.nan, True, "5"])
def test_a_gap_out_of_range_is_refused(gap):
    with pytest.raises(ConfigError, match=r"--gap must be a distance in \[0.001, 0.2\] m"):
        random_order(5, 0, CELL, gap=gap)


def test_twelve_burgers_a_wide_gap_apart_do_not_fit():
    with pytest.raises(ConfigError, match=r"no free place on the grill for burger .* smaller "
                                          r"gap"):
        random_order(12, 0, CELL, gap=0.1)


@pytest.mark.parametrize("n", [0, MAX_RANDOM + 1, 2.5, True])
def test_a_count_out_of_range_is_refused(n):
    with pytest.raises(ConfigError, match=r"--random N must be a whole number"):
        random_order(n, 0, CELL)


@pytest.mark.parametrize("args, message", [
    (["--random", "13"], "in [1, 12]"),
    (["--random", "3", "--stream", "60", "--minutes", "1"], "not --stream and --random"),
    (["flipkit/data/cook_five.csv", "--random", "3"], "not BURGERS.csv and --random"),
    (["flipkit/data/cook_five.csv", "--gap", "0.03"], "--gap goes with --random"),
    (["--random", "3", "--gap", "0.5"], "--gap must be a distance"),
])
def test_the_cli_refuses_in_one_line(tmp_path, capsys, args, message):
    out = tmp_path / "t.json"
    code = main(["schedule", *args, "--json", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0]
    assert not out.exists()


def test_a_random_cook_is_scheduled(tmp_path, capsys):
    """Two random burgers, flips only, planned and scheduled end to end: the timeline holds
    the random order's places."""
    out = tmp_path / "t.json"
    code = main(["schedule", "--random", "2", "--seed", "4", "--flip-only", "--workers", "1",
                 "--no-progress", "--json", str(out)])
    assert code == 0, capsys.readouterr().err
    doc = json.loads(out.read_text())
    places = {tuple(b["position"]) for b in doc["burgers"]}
    assert places == {(b.x, b.y) for b in random_order(2, 4, CELL)}
    assert doc["status"] == "solved"
    assert all(m["status"] == "solved" and math.isfinite(m["start"]) for m in doc["motions"])


# ---------------------------------------------------- the first random cook that plans
class _Timeline:
    def __init__(self, ok=True, failed=()):
        self.ok = ok
        self.motions = [type("M", (), {"key": k, "ok": False})() for k in failed]


def _fake_plan(outcomes):
    """A cook planner that answers by the cook's places: ``outcomes`` maps the first burger's
    x (m, rounded to µm) to "conflict", "broken", "failed" or "ok"; records what it saw."""
    seen = []

    def plan(burgers):
        seen.append(burgers)
        what = outcomes[round(burgers[0].x, 6)]
        if what == "conflict":
            raise CookConflictError("flip:r1: no landing spot for burger r1", kind="landing")
        breach = WindowBreak("r2", "flip", 3.1, 1.1, (0.0, 2.0)) if what == "broken" else None
        timeline = _Timeline(ok=what != "failed", failed=("serve:r2",) if what == "failed" else ())
        return PlannedCook(burgers, timeline, {}, {}, breach, 0.1)
    return plan, seen


def test_first_random_cook_keeps_the_first_seed_planned_and_names_the_seeds_refused():
    x = {s: round(random_order(3, s, CELL)[0].x, 6) for s in range(5)}
    plan, seen = _fake_plan({x[0]: "conflict", x[1]: "broken", x[2]: "failed", x[3]: "ok",
                             x[4]: "ok"})
    drawn = first_random_cook(3, range(5), plan, CELL)
    assert drawn.seed == 3 and drawn.cook.burgers == random_order(3, 3, CELL)
    assert len(seen) == 4  # seed 4 is never planned
    assert [(s, kind) for s, kind, _ in drawn.refused] == [(0, "landing"), (1, "windows"),
                                                            (2, "other")]
    reasons = [why for _, _, why in drawn.refused]
    assert "no landing spot" in reasons[0]
    assert reasons[1].startswith("windows broken: burger r2")
    assert reasons[2] == "motions not planned: serve:r2"
    assert drawn.refusal_counts() == {"landing": 1, "heading": 0, "windows": 1, "other": 1}


def test_no_random_cook_planned_is_one_error_with_every_seed_reason():
    x = {s: round(random_order(2, s, CELL)[0].x, 6) for s in range(3)}
    plan, _ = _fake_plan({v: "conflict" for v in x.values()})
    with pytest.raises(ConfigError) as err:
        first_random_cook(2, range(3), plan, CELL)
    text = str(err.value)
    assert "\n" not in text and all(f"seed {s}: " in text for s in range(3))
