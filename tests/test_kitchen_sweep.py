"""A cook's motions against the other burgers on the grill (flipkit.planning.kitchen.sweep and
.clearance): the blade's section within a lying burger's height, distances to it, who meets
whom and when, and the landing spot that keeps clear. Hand-built geometry with known answers;
no planner runs."""

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from flipkit.config import CellConfig
from flipkit.planning.kitchen.clearance import (CookConflictError, clear_cook, free_landing,
                                               landing_candidates,
                                               lying_burgers)
from flipkit.planning.kitchen.cook import CookBurger
from flipkit.planning.kitchen.heading_model import MODEL_MARGIN
from flipkit.planning.kitchen.turns import MAX_TRIES
from flipkit.planning.kitchen.sweep import (Footprint, Lying, approach_height,
                                           blade_rectangle, blade_section, blade_sections, default_margin, meetings,
                                           point_polygon_distance, point_segment_distance,
                                           points_polygon_distance, slab_section)

CELL = CellConfig()
L, W = CELL.spatula.length, CELL.spatula.width
R = CELL.burger.diameter / 2
H, T = CELL.grill.height, CELL.burger.thickness
M = default_margin()


def pitched(theta):
    """Rotation about the world y axis by ``theta`` (tip down for theta > 0)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def yawed(psi):
    c, s = math.cos(psi), math.sin(psi)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_the_blade_rectangle_follows_the_spatula_frame():
    flat = blade_rectangle(np.eye(3), (0.7, -0.2, H), CELL)
    assert sorted(np.round(flat[:, 0] - 0.7, 9)) == sorted([L / 2, -L / 2] * 2)
    assert sorted(np.round(flat[:, 1] + 0.2, 9)) == sorted([W / 2, -W / 2] * 2)
    assert np.allclose(flat[:, 2], H)
    turned = blade_rectangle(yawed(math.pi / 2), (0, 0, 0), CELL)
    assert np.isclose(np.abs(turned[:, 0]).max(), W / 2)  # its length now along world y
    assert np.isclose(np.abs(turned[:, 1]).max(), L / 2)


def test_the_section_of_a_pitched_blade_is_its_part_within_the_slab():
    theta = 0.314  # the scoop's pitch: the tip (its +x end) low
    rect = blade_rectangle(pitched(theta), (0, 0, 0), CELL)
    # the blade plane: z = -x tan(theta); the slab [-h, 0] cuts x in [0, h / tan(theta)]
    h = 0.015
    sec = slab_section(rect, -h, 0.0)
    assert sec[:, 0].min() == pytest.approx(0.0, abs=1e-12)
    assert sec[:, 0].max() == pytest.approx(min(h / math.sin(theta), L / 2) * math.cos(theta),
                                            rel=1e-9)
    assert np.abs(sec[:, 1]).max() == pytest.approx(W / 2)
    assert (sec[:, 2] >= -h - 1e-12).all() and (sec[:, 2] <= 1e-12).all()
    assert slab_section(rect + [0, 0, 1.0], -h, 0.0).shape == (0, 3)  # all above
    flat = blade_rectangle(np.eye(3), (0, 0, 0), CELL)
    assert len(slab_section(flat, -h, h)) == 4  # all within: unchanged


def test_a_blade_pressed_into_the_grill_counts_whole_and_a_raised_one_not_at_all():
    pressed = blade_section(np.eye(3), (0.7, -0.2, H - 0.003), CELL)  # the scoop's press
    assert len(pressed) == 4 and np.allclose(pressed, blade_rectangle(np.eye(3),
                                                                      (0.7, -0.2, H - 0.003), CELL))
    assert blade_section(np.eye(3), (0.7, -0.2, H + T + 0.001), CELL).shape == (0, 3)
    theta = 0.314  # pitched, the tip 3 mm into the grill: the part below the burger's top
    tip_down = blade_section(pitched(theta), (0.7, -0.2, H - 0.003 + L / 2 * math.sin(theta)),
                             CELL)
    assert tip_down[:, 2].max() == pytest.approx(H + T) and tip_down[:, 2].min() < H


def test_the_sections_of_many_poses_at_once_are_each_pose_s_section():
    """blade_sections (every sample of a footprint at once) against blade_section per pose:
    random pitches, rolls and heights around the burger's top, so that the plane cuts the
    blade through two, three or no corners (fixed seed)."""
    rng = np.random.default_rng(5)
    Rs, ps = [], []
    for _ in range(300):
        a, b, c = rng.uniform(-0.5, 0.5, 3)
        Rs.append(yawed(c) @ pitched(a) @ np.array([[1, 0, 0], [0, math.cos(b), -math.sin(b)],
                                                    [0, math.sin(b), math.cos(b)]]))
        ps.append((0.7, -0.2, H + T + rng.uniform(-0.06, 0.06)))
    polys, counts = blade_sections(np.array(Rs), np.array(ps), CELL)
    seen = set()
    for R, p, poly, n in zip(Rs, ps, polys, counts):
        one = blade_section(R, p, CELL)
        assert n == len(one)
        assert np.allclose(poly[:n], one, rtol=0, atol=1e-15)
        assert np.all(poly[n:] == poly[0])  # padded with the first vertex
        seen.add(int(n))
    assert seen == {0, 3, 4, 5}  # no section, a corner, half the blade, all but a corner


def test_distances_to_a_polygon_inside_along_an_edge_and_at_a_corner():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    assert point_polygon_distance((0.3, 0.6), square) == 0.0
    assert point_polygon_distance((1.5, 0.5), square) == pytest.approx(0.5)
    assert point_polygon_distance((2, 2), square) == pytest.approx(math.sqrt(2))
    assert point_polygon_distance((0.5, -0.25), square[::-1]) == pytest.approx(0.25)
    assert point_segment_distance((0.5, 1.0), (0, 0), (1, 0)) == pytest.approx(1.0)
    assert point_segment_distance((3, 0), (0, 0), (1, 0)) == pytest.approx(2.0)
    pts = np.random.default_rng(0).uniform(-1, 2, (200, 2))
    assert np.allclose(points_polygon_distance(pts, square),
                       [point_polygon_distance(p, square) for p in pts])


def blade_at(x, y, t=1.0, seg="scoop"):
    """A footprint whose blade section is the flat blade at (x, y) at time t."""
    return Footprint(blade=[(t, seg, blade_rectangle(np.eye(3), (x, y, H), CELL)[:, :2])])


def test_a_lying_burger_is_met_within_its_radius_and_the_margin_and_only_while_it_lies():
    fp = blade_at(0.7, -0.2)
    edge = -0.2 + W / 2  # the blade's side edge
    near = Lying("b2", (0.7, edge + R + M - 0.003), 0.0, 1e9)
    clear = Lying("b3", (0.7, edge + R + M + 0.003), 0.0, 1e9)
    (meet,) = meetings(fp, "flip:b1", 100.0, [near, clear], CELL)
    assert (meet.burger, meet.part, meet.segment) == ("b2", "blade", "scoop")
    assert meet.overlap_m == pytest.approx(0.003)
    assert meet.t == pytest.approx(101.0)
    assert "flip:b1" in meet.describe() and "b2" in meet.describe()
    gone = Lying("b2", near.xy, 0.0, 100.5)  # served before the blade comes
    assert meetings(fp, "flip:b1", 100.0, [gone], CELL) == []
    assert meetings(fp, "flip:b1", 100.0, [near], CELL, margin=0.0) == []


def test_the_carried_burger_and_the_landing_disc():
    fp = Footprint(carried=[(0.5, "scoop", (0.70, -0.2), (0.74, -0.2))],
                   landing=(2.0, (0.70, -0.2), R + 0.02))
    ahead = Lying("b2", (0.74 + 2 * R + M - 0.002, -0.2), 0.0, 1e9)  # pushed into
    beside = Lying("b3", (0.70, -0.2 + (R + 0.02) + R + M - 0.004), 0.0, 1e9)  # landed on
    found = {(m.burger, m.part): m for m in meetings(fp, "flip:b1", 0.0, [ahead, beside], CELL)}
    assert set(found) == {("b2", "carried burger"), ("b3", "landing")}
    assert found["b2", "carried burger"].overlap_m == pytest.approx(0.002)
    assert found["b3", "landing"].overlap_m == pytest.approx(0.004)
    assert found["b3", "landing"].t == pytest.approx(2.0)


def test_the_approach_clears_a_lying_burger_by_the_margin():
    assert approach_height(CELL) == pytest.approx(T + M)
    assert M == pytest.approx(0.01)  # the robust flips' placement spread, 2 x 5 mm


# ---------------------------------------------------------------- a cook's timeline
def fake_timeline(landing_b1=(0.64, -0.33), drop_b1=(0.64, -0.33), blade_b2=(0.64, -0.33)):
    """b1 dropped at ``drop_b1`` and flipped at 90 s (landed at ``landing_b1``), b2's flip at
    105 s scoops with its blade at ``blade_b2`` (by default over (0.56..0.72, -0.33 +- W/2));
    serves later."""
    b1, b2 = CookBurger("b1", 0, *drop_b1), CookBurger("b2", 15, 0.75, -0.45)
    plans = {k: object() for k in ("f1", "f2", "s1", "s2")}
    mk = SimpleNamespace
    motions = [mk(kind="flip", burger="b1", key="flip:b1", start=87.0, end=91.0, event=90.0,
                  ok=True, plan=plans["f1"]),
               mk(kind="flip", burger="b2", key="flip:b2", start=102.0, end=106.0,
                  event=105.0, ok=True, plan=plans["f2"]),
               mk(kind="serve", burger="b1", key="serve:b1", start=148.0, end=154.0,
                  event=150.0, ok=True, plan=plans["s1"]),
               mk(kind="serve", burger="b2", key="serve:b2", start=163.0, end=169.0,
                  event=165.0, ok=True, plan=plans["s2"])]
    burgers = [mk(burger=b1, landing=landing_b1), mk(burger=b2, landing=(0.75, -0.45))]
    fps = {plans["f1"]: Footprint(landing=(3.0, landing_b1, R + 0.015)),
           plans["f2"]: blade_at(*blade_b2, t=1.0),
           plans["s1"]: Footprint(), plans["s2"]: Footprint()}
    return SimpleNamespace(burgers=burgers, motions=motions, ok=True), fps


def test_where_each_burger_lies_and_when():
    tl, fps = fake_timeline()
    lying = lying_burgers(tl)
    assert [(lie.burger, lie.landed, lie.t0, lie.t1) for lie in lying] == [
        ("b1", False, 0, 87.0), ("b1", True, 90.0, 148.0),
        ("b2", False, 15, 102.0), ("b2", True, 105.0, 163.0)]
    assert all(lie.spread == 0.0 for lie in lying)
    # with the plans' footprints, a landed burger lies within its flip's landing spread
    spreads = [lie.spread for lie in lying_burgers(tl, CELL, fps.__getitem__)]
    assert spreads == [0.0, pytest.approx(0.015), 0.0, 0.0]  # b2's flip has no landing disc


def test_a_landed_burger_is_kept_clear_by_its_landing_spread_too():
    fp = blade_at(0.7, -0.2)
    edge = -0.2 + W / 2
    at = (0.7, edge + R + M + 0.005)  # clear of the blade by 5 mm beyond the margin ...
    assert meetings(fp, "flip:b1", 0.0, [Lying("b2", at, 0.0, 1e9)], CELL) == []
    landed = Lying("b2", at, 0.0, 1e9, landed=True, spread=0.02)  # ... unless it may lie 2 cm off
    (meet,) = meetings(fp, "flip:b1", 0.0, [landed], CELL)
    assert meet.overlap_m == pytest.approx(0.015)


def test_a_met_burger_is_landed_clear_of_the_blade_nearest_its_drop():
    tl, fps = fake_timeline()
    spot = free_landing("b1", tl, CELL, fps.__getitem__)
    blade = blade_at(0.64, -0.33).blade[0][2]
    radius = R + 0.015  # b1's landing disc

    def clear(c):  # b2's blade at 103 s, b2 lying (dropped, then landed) over b1's stay;
        # b1 lies within its landing disc of the spot
        return (point_polygon_distance(c, blade) >= radius + M
                and np.hypot(c[0] - 0.75, c[1] + 0.45) >= radius + R + M)

    spread = radius - R  # the spot lies this far inside the grill area's edges
    grid = [(x, y) for x in np.arange(0.60, 0.88 + 1e-9, M / 2)
            for y in np.arange(-0.50, 0.16 + 1e-9, M / 2)
            if 0.60 + spread - 1e-9 <= x <= 0.88 - spread + 1e-9
            and -0.50 + spread - 1e-9 <= y <= 0.16 - spread + 1e-9]
    best = min((c for c in grid if clear(c)), key=lambda c: np.hypot(c[0] - 0.64, c[1] + 0.33))
    assert spot == pytest.approx(best) and clear(spot) and CELL.grill.contains(spot)
    assert free_landing("b1", tl, CELL, fps.__getitem__, exclude=[spot]) != pytest.approx(spot)


def test_a_moved_landing_keeps_the_landed_burger_inside_the_grill_area():
    """b1 dropped at the grill area's back edge with b2's blade over it: the nearest clear spot
    lies on the edge, but b1 may land its spread (1.5 cm) beyond its spot, so the spot offered
    lies that far inside."""
    back = CELL.grill.x_range[1]
    tl, fps = fake_timeline((back, -0.20), (back, -0.20), (back, -0.20))
    spot = free_landing("b1", tl, CELL, fps.__getitem__)
    spread = 0.015
    blade = blade_at(back, -0.20).blade[0][2]
    assert spot is not None and spot[0] <= back - spread + 1e-9
    assert CELL.grill.contains((spot[0] + spread, spot[1]))
    assert point_polygon_distance(spot, blade) >= R + spread + M - 1e-9
    # on the edge itself a clear spot lies nearer the drop place than the one offered
    edge = [y for y in np.arange(-0.50, 0.16 + 1e-9, M / 2)
            if point_polygon_distance((back, y), blade) >= R + spread + M
            and np.hypot(back - 0.75, y + 0.45) >= R + spread + R + M]
    assert min(np.hypot(0.0, y + 0.20) for y in edge) < np.hypot(spot[0] - back, spot[1] + 0.20)


def test_no_spot_is_offered_where_the_burger_could_land_off_the_grill_area():
    """A grill area 2.5 cm deep has no spot 1.5 cm (the landing spread) inside both its
    edges: no spot is offered, though clear spots lie on its edges (a burger landed from one
    could lie where no serve may be planned), and the 3 cm deep area offers one."""
    back = CELL.grill.x_range[1]
    blade = blade_at(back, -0.20).blade[0][2]
    for depth, offered in ((0.025, False), (0.030, True)):
        cell = dataclasses.replace(CELL, grill=dataclasses.replace(CELL.grill,
                                                                   x_range=(back - depth, back)))
        tl, fps = fake_timeline((back, -0.20), (back, -0.20), (back, -0.20))
        spot = free_landing("b1", tl, cell, fps.__getitem__)
        edge = [(x, y) for x, y in landing_candidates(cell, M / 2)
                if point_polygon_distance((x, y), blade) >= R + 0.015 + M]
        assert edge  # clear spots exist on the edges either way
        assert (spot is not None) == offered
        if offered:
            assert spot[0] == pytest.approx(back - 0.015)
            assert point_polygon_distance(spot, blade) >= R + 0.015 + M - 1e-9


def test_clear_cook_moves_a_landing_then_refuses_what_no_landing_avoids(monkeypatch):
    import flipkit.planning.kitchen.clearance as clearance

    tl, fps = fake_timeline()
    calls = []

    def schedule(lands, headings):
        calls.append(dict(lands))
        moved = lands.get("b1")
        t, f = fake_timeline(moved if moved else (0.64, -0.33))
        fps.clear()
        fps.update(f)
        return t

    monkeypatch.setattr(clearance, "Footprints", lambda cell: fps.__getitem__)
    timeline, lands, headings = clear_cook(schedule, CELL)
    assert set(lands) == {"b1"} and calls[0] == {} and calls[-1] == lands and headings == {}
    blade = blade_at(0.64, -0.33).blade[0][2]
    assert point_polygon_distance(lands["b1"], blade) >= R + M - 1e-9

    def unflipped(lands, headings):  # b1 still lies where it was dropped when b2's blade comes
        t, f = fake_timeline()
        t.motions = [m for m in t.motions if m.burger != "b1"]
        fps.clear()
        fps.update(f)
        return t

    with pytest.raises(CookConflictError, match="flip:b2.*b1.*where it was dropped"):
        clear_cook(unflipped, CELL)


def b1_unflipped(fps: dict, b2_footprint=None):
    """:func:`fake_timeline` with b1 not flipped yet (it lies where it was dropped) and b2's
    flip given ``b2_footprint`` (default: its blade over b1); ``fps`` takes the footprints."""
    t, f = fake_timeline()
    t.motions = [m for m in t.motions if m.burger != "b1"]
    if b2_footprint is not None:
        f[t.motions[0].plan] = b2_footprint
    fps.clear()
    fps.update(f)
    return t


def test_a_toss_that_meets_a_dropped_burger_lands_its_own_burger_elsewhere(monkeypatch):
    """b2's flip segment (its toss, which follows its landing spot) passes over b1 while b1
    still lies where it was dropped: the cook lands b2 elsewhere and plans again; a toss that
    meets b1 from every spot tried (two) is refused."""
    import flipkit.planning.kitchen.clearance as clearance

    calls = []

    def schedule(lands, headings, moves=True):
        calls.append(dict(lands))
        toss = (0.64, -0.33) if "b2" not in lands or not moves else (0.80, -0.10)
        return b1_unflipped(fps, blade_at(*toss, t=1.0, seg="flip"))

    fps = {}
    monkeypatch.setattr(clearance, "Footprints", lambda cell: fps.__getitem__)
    timeline, lands, headings = clear_cook(schedule, CELL)
    assert set(lands) == {"b2"} and calls[0] == {} and len(calls) == 2 and headings == {}
    calls.clear()
    with pytest.raises(CookConflictError, match="flip:b2.*b1.*where it was dropped.*every "
                                                "scoop heading tried") as err:
        clear_cook(lambda lands, headings: schedule(lands, headings, moves=False), CELL)
    assert err.value.kind == "heading"
    # two other landing spots, then MAX_TRIES turned headings (the toss is fixed here)
    assert len(calls) == 3 + MAX_TRIES and len({tuple(c.get("b2", ())) for c in calls}) == 3


def test_a_scoop_that_meets_a_dropped_burger_is_turned_to_the_smallest_clear_turn(monkeypatch):
    """b2's scoop passes 1 cm inside b1's clearance while b1 still lies where it was
    dropped: the cook ranks b2's headings by its footprint turned about b2 and plans the
    smallest turn predicted clear by the margin plus the model's error; here the fake plans'
    footprints are exactly the turned ones, so that plan keeps clear, while every smaller
    turn comes within the widened clearance."""
    import math

    import flipkit.planning.kitchen.clearance as clearance
    from flipkit.behaviors.targets import default_heading
    from flipkit.planning.kitchen.heading_model import turned_footprint
    from flipkit.planning.kitchen.turns import Turns

    b1, b2 = np.array([0.64, -0.33]), np.array([0.75, -0.45])
    u = (b2 - b1) / np.linalg.norm(b2 - b1)
    n = np.array([-u[1], u[0]])
    tip = b1 + (R + M - 0.01) * (u + n) / math.sqrt(2)  # 1 cm inside b1's clearance
    square = tip + 0.005 * np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]])
    base = Footprint(blade=[(1.0, "scoop", square)])
    psi0 = default_heading(CELL, (*b2, 0.0))
    seen = []

    def schedule(lands, headings):
        seen.append(dict(headings))
        turn = headings.get("b2", psi0) - psi0
        return b1_unflipped(fps, turned_footprint(base, b2, turn))

    def clear(turn, widen=MODEL_MARGIN):  # the ranking widens the margin by the model's error
        return not meetings(turned_footprint(base, b2, turn), "flip:b2", 102.0,
                            [Lying("b1", tuple(b1), 0.0, 1e9)], CELL, M + widen)

    fps = {}
    monkeypatch.setattr(clearance, "Footprints", lambda cell: fps.__getitem__)
    timeline, lands, headings = clear_cook(schedule, CELL)
    turns = [p - psi0 for p in Turns(CELL).candidates(b2)]
    expected = next(t for t in turns if clear(t))
    assert not clear(0.0, 0.0) and lands == {} and seen[0] == {} and len(seen) == 2
    assert headings == {"b2": pytest.approx(psi0 + expected)}
    assert all(not clear(t) for t in turns if abs(t) < abs(expected) - 1e-9)
    # a smaller turn clears by the margin alone: the model's error margin skipped it
    assert any(clear(t, 0.0) for t in turns if abs(t) < abs(expected) - 1e-9)


def test_the_go_to_burger_comes_in_above_the_burgers_when_the_task_says_so():
    from flipkit.behaviors.approach import descent_node
    from flipkit.behaviors.spec import Task
    from flipkit.behaviors.transcribe import blade_floor
    from flipkit.errors import ConfigError
    from flipkit.planning.planners.inputs import check_approach_height

    N, h = 20, approach_height(CELL)
    plain = blade_floor("go_to_burger", CELL, N)
    raised = blade_floor("go_to_burger", CELL, N, Task(approach_height=h))
    d = descent_node(N)  # raised until the descent, the approach's own floor after it
    assert np.allclose(raised[:d], np.maximum(H + h, plain[:d]))
    assert np.all(raised[:d] >= H + h) and np.array_equal(raised[d:], plain[d:])
    assert np.array_equal(blade_floor("go_to_burger", CELL, N, Task()), plain)
    for other in ("scoop", "pickup", "turn_back"):  # only the approach is raised
        assert np.array_equal(blade_floor(other, CELL, N, Task(approach_height=h)),
                              blade_floor(other, CELL, N))
    assert check_approach_height(None) is None and check_approach_height(0.02) == 0.02
    for bad in (-0.01, math.nan, "x"):
        with pytest.raises(ConfigError, match="approach_height"):
            check_approach_height(bad)


def test_a_landing_that_meets_a_landed_burger_moves_its_own_when_that_one_cannot(monkeypatch):
    """b2's flip lands its burger on b1, which its flip landed there: b1's landing moves
    first; when no spot is free for b1, b2's own landing moves instead; when neither has one,
    the cook is refused naming both."""
    import flipkit.planning.kitchen.clearance as clearance

    def schedule(lands, headings):
        t, f = fake_timeline()
        f[t.motions[1].plan] = Footprint(landing=(3.0, lands.get("b2", (0.66, -0.35)),
                                                  R + 0.015))
        fps.clear()
        fps.update(f)
        return t

    fps, free = {}, {}
    monkeypatch.setattr(clearance, "Footprints", lambda cell: fps.__getitem__)
    monkeypatch.setattr(clearance, "free_landing",
                        lambda who, *a, **k: free.get(who))
    free.update(b1=None, b2=(0.80, 0.05))
    timeline, lands, headings = clear_cook(schedule, CELL)
    assert lands == {"b2": (0.80, 0.05)} and headings == {}
    free.update(b2=None)
    with pytest.raises(CookConflictError, match="flip:b2: the landing .* burger b1 or b2") as err:
        clear_cook(schedule, CELL)
    assert err.value.kind == "landing"


def test_a_scoop_that_meets_a_landed_burger_that_cannot_move_is_turned(monkeypatch):
    """b2's scoop passes over b1 where b1's flip landed it, and no spot is free for b1: the
    cook turns b2's scoop instead of refusing; with no heading left it refuses."""
    import flipkit.planning.kitchen.clearance as clearance

    def schedule(lands, headings, clears=True):
        t, f = fake_timeline()
        if "b2" in headings and clears:
            f[t.motions[1].plan] = blade_at(0.80, -0.10, t=1.0)
        fps.clear()
        fps.update(f)
        return t

    fps = {}
    monkeypatch.setattr(clearance, "Footprints", lambda cell: fps.__getitem__)
    monkeypatch.setattr(clearance, "free_landing", lambda *a, **k: None)
    timeline, lands, headings = clear_cook(schedule, CELL)
    assert lands == {} and set(headings) == {"b2"}
    with pytest.raises(CookConflictError, match="flip:b2: the blade .* every scoop heading") as err:
        clear_cook(lambda lands, headings: schedule(lands, headings, clears=False), CELL)
    assert err.value.kind == "heading"


def test_a_spot_keeps_clear_of_the_landings_given_in_the_same_round():
    """Two landings moved in one round are chosen against the same timeline: the second keeps
    clear of the first's landing disc (``taken``), which the timeline does not hold yet."""
    tl, fps = fake_timeline()
    first = free_landing("b1", tl, CELL, fps.__getitem__)
    taken = (first, R + 0.015)
    second = free_landing("b1", tl, CELL, fps.__getitem__, taken=[taken])
    assert first is not None and second is not None
    assert np.hypot(second[0] - first[0], second[1] - first[1]) >= 2 * (R + 0.015) + M - 1e-9
    alone = free_landing("b1", tl, CELL, fps.__getitem__, exclude=[first])
    assert np.hypot(alone[0] - first[0], alone[1] - first[1]) < 2 * (R + 0.015) + M


def test_turns_beyond_those_the_atlas_solved_near_the_burger_are_tried_last():
    """With the turns solved near the burger (-15..30 deg here), a turn more than half the
    atlas's step beyond them (-25, -30) comes after every other, whatever their order by
    size; without them the order is by size alone. The package atlas solved its near corner
    at -15, 0, 15 and 30 deg."""
    import math

    from flipkit.planning.kitchen.turns import Turns
    from flipkit.planning.planners.atlas import default_atlas

    b = CookBurger("b", 0.0, 0.70, -0.20)
    tl = SimpleNamespace(burgers=[SimpleNamespace(burger=b, landing=None)])

    def order(turns):
        psi0, out = turns.default((b.x, b.y)), []
        for _ in range(len(turns.candidates((b.x, b.y)))):
            out.append(round(math.degrees(turns.next("b", None, tl, overlap=lambda t: 0.0)
                                          - psi0)))
        return out

    solved = np.radians([-15.0, 0.0, 15.0, 30.0])
    near = order(Turns(CELL, max_tries=20, solved=lambda xy: solved))
    plain = order(Turns(CELL, max_tries=20))
    assert plain == [-5, 5, -10, 10, -15, 15, -20, 20, -25, 25, -30, 30]
    assert near == [-5, 5, -10, 10, -15, 15, -20, 20, 25, 30, -25, -30]
    turns = default_atlas(CELL).solved_turns((0.63, -0.45), CELL)
    assert np.allclose(np.degrees(turns), [-15.0, 0.0, 15.0, 30.0], atol=1e-6)
