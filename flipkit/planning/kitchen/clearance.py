"""Keeping a cook's motions clear of the other burgers on the grill.

Each motion is planned for its own burger alone. :func:`cook_meetings` checks every motion
of a timeline against the burgers lying on the grill while it runs (known from the
schedule: dropped, not yet lifted by their own motions), with the geometry of
:mod:`flipkit.planning.kitchen.sweep`.

:func:`clear_cook` then uses two freedoms the planners leave. The first changes who lies where:
**where a flip lands its burger** (``plan_flip(..., land=...)``; by default where it was
picked up). A burger met where it landed is landed elsewhere; a serve that meets a burger
(or a flip whose landing does) moves its own burger's landing, which moves where the serve
scoops from; a flip whose toss meets a burger still lying where it was dropped lands its own
burger elsewhere, which changes the toss (up to two other spots). The new spot is the one
nearest the burger's drop place that keeps clear, over the burger's stay on its second side,
of every other motion's footprint and of every other burger, and from which its serve's
footprint (the present one, moved with it) meets nobody.
The cook is planned and scheduled again with the new spots and checked again.

The second freedom is **the scoop heading of a flip** (``plan_flip(..., heading=...)``;
by default radial from the base, :mod:`flipkit.model.task_frame`). A flip whose go to burger,
scoop or pickup meets a burger still lying where it was dropped, or whose toss still does
from two other landing spots, is turned (:class:`~flipkit.planning.kitchen.turns.Turns`): its
headings within 30° of radial are ranked by its footprint turned about its burger
(:mod:`flipkit.planning.kitchen.heading_model`) against the burgers lying while it runs, and
the smallest turn predicted clear is planned next. A flip whose blade meets a burger that
its own flip landed is turned too when no spot is free for that burger. A flip still meeting
a burger after the headings allowed, or whose plan fails at every heading tried, refuses the
cook (:class:`CookConflictError`, naming the burger, the headings tried and the one it meets).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from flipkit.behaviors.library import PICKUP_AND_FLIP, SERVE
from flipkit.config import CellConfig
from flipkit.model.robot import Robot
from flipkit.planning.kitchen.heading_model import MODEL_MARGIN, PARTS, predicted_overlap
from flipkit.planning.kitchen.planar import polygon_distances, segment_distances
from flipkit.planning.kitchen.sweep import Lying, Meeting, default_margin, footprint, meetings
from flipkit.planning.kitchen.turns import CookConflictError, Turns

MAX_ROUNDS = 8  # plan-schedule-check rounds before a cook with meetings left is refused

LOW_SEGMENTS = SERVE.before("carry")  # a serve's segments at the grill: they move with its burger
TOSS_SEGMENTS = PICKUP_AND_FLIP.since("release")  # a flip's that change with its landing spot
# Footprint samples tested at once against the candidate spots still in. Each test removes
# most of them, so small chunks keep the later tests small, while a chunk of one pays the
# call's overhead per sample (docs/history.md).
CHUNK = 4


def lying_burgers(timeline, cell: CellConfig | None = None,
                  footprints: Callable | None = None) -> list[Lying]:
    """Where each burger lies on the grill, when: at its drop place from its drop to the
    start of its flip (for good if the flip is not executed), then at its flip's predicted
    landing point from the landing to the start of its serve (for good without one), within
    the flip's landing spread of it (its footprint's landing disc beyond the burger's radius;
    with ``cell`` and ``footprints``, else 0)."""
    motions = {(m.kind, m.burger): m for m in timeline.motions if m.ok and m.event is not None}
    out = []
    for rec in timeline.burgers:
        b = rec.burger
        flip, serve = motions.get(("flip", b.burger)), motions.get(("serve", b.burger))
        out.append(Lying(b.burger, (b.x, b.y), b.t_drop, flip.start if flip else math.inf))
        if flip is not None:
            landed = rec.landing if rec.landing is not None else (b.x, b.y)
            out.append(Lying(b.burger, tuple(landed), flip.event,
                             serve.start if serve else math.inf, landed=True,
                             spread=_landing_spread(flip, cell, footprints)))
    return out


def _landing_radius(burger: str, timeline, cell: CellConfig, footprints) -> float:
    """The radius (m) within which ``burger``'s flip lands it: its landing disc."""
    flip = next((m for m in timeline.motions if m.key == f"flip:{burger}"), None)
    return cell.burger.diameter / 2 + (0.0 if flip is None else
                                       _landing_spread(flip, cell, footprints))


def _landing_spread(flip, cell, footprints) -> float:
    """How far (m) beyond the burger's radius a flip's landing disc reaches (0 unknown)."""
    if cell is None or footprints is None or flip.plan is None:
        return 0.0
    landing = footprints(flip.plan).landing
    return 0.0 if landing is None else max(landing[2] - cell.burger.diameter / 2, 0.0)


class Footprints:
    """Each plan's :func:`~flipkit.planning.kitchen.sweep.footprint`, computed once."""

    def __init__(self, cell: CellConfig):
        self.cell, self._done, self._robot = cell, {}, None

    def __call__(self, plan):
        key = id(plan)
        if key not in self._done:
            if self._robot is None:
                self._robot = Robot(self.cell, with_burger=False)
            self._done[key] = (plan, footprint(plan, self.cell, self._robot))
        return self._done[key][1]


def cook_meetings(timeline, cell: CellConfig, footprints: Footprints | None = None,
                  margin: float | None = None) -> list[tuple[Meeting, Lying]]:
    """Every meeting of an executed motion with a burger lying while it runs, with that
    burger's :class:`Lying` record, in time order."""
    footprints = footprints or Footprints(cell)
    lying = lying_burgers(timeline, cell, footprints)
    out = []
    for m in timeline.motions:
        if not m.ok or m.event is None or m.plan is None:
            continue
        others = [lie for lie in lying if lie.burger != m.burger]
        for meet in meetings(footprints(m.plan), m.key, m.start, others, cell, margin):
            lie = next(lie for lie in others if lie.burger == meet.burger
                       and lie.t0 <= meet.t <= lie.t1)
            out.append((meet, lie))
    return sorted(out, key=lambda ml: ml[0].t)


def _turned_overlap(burger: str, timeline, cell: CellConfig, footprints: Footprints,
                    margin: float | None) -> Callable[[float], float]:
    """``turn (rad) -> m·s``: how far ``burger``'s present flip, turned by that much about
    its burger, would sweep inside the clearance of the burgers lying while it runs, widened
    by the model's error (:data:`~flipkit.planning.kitchen.heading_model.MODEL_MARGIN`;
    :func:`~flipkit.planning.kitchen.heading_model.predicted_overlap`)."""
    flip = next(m for m in timeline.motions if m.key == f"flip:{burger}")
    fp = footprints(flip.plan)
    rec = next(r for r in timeline.burgers if r.burger.burger == burger)
    pb = (rec.burger.x, rec.burger.y)  # where the flip scoops it from: its drop place
    others = [lie for lie in lying_burgers(timeline, cell, footprints) if lie.burger != burger]
    wide = (default_margin() if margin is None else margin) + MODEL_MARGIN
    return lambda turn: predicted_overlap(fp, pb, turn, flip.key, flip.start, others, cell,
                                          wide)


def landing_candidates(cell: CellConfig, step: float) -> np.ndarray:
    """Centres (n×2, m) on the grill, ``step`` apart."""
    g = cell.grill
    xs = np.arange(g.x_range[0], g.x_range[1] + 1e-12, step)
    ys = np.arange(g.y_range[0], g.y_range[1] + 1e-12, step)
    return np.array([(x, y) for x in xs for y in ys])


def free_landing(burger: str, timeline, cell: CellConfig, footprints: Footprints,
                 margin: float | None = None, exclude=(), taken=()) -> tuple | None:
    """The landing spot (x, y) (m) for ``burger`` nearest its drop place that keeps clear of
    every other motion and burger over its stay, and whose serve (its present footprint,
    moved with the spot) meets nobody; ``None`` if there is none. ``exclude``: spots
    already tried (nothing within ``margin`` of them is offered again). ``taken``: landing
    discs ``(xy, radius)`` (m) just given to other burgers, which the timeline does not hold
    yet; the spot keeps clear of them.

    Only spots at least the flip's landing spread inside the grill area's edges are offered:
    the burger lands within that spread of its spot, so its centre stays in the area, where
    its serve (and the grill's re-plan) takes burgers from. A spot nearer an edge could land
    it where no serve may be planned."""
    margin = default_margin() if margin is None else margin
    r = cell.burger.diameter / 2
    motions = {m.key: m for m in timeline.motions if m.ok and m.event is not None}
    flip, serve = motions.get(f"flip:{burger}"), motions.get(f"serve:{burger}")
    if flip is None or flip.plan is None:
        return None
    rec = next(b for b in timeline.burgers if b.burger.burger == burger)
    own = footprints(flip.plan)
    radius = own.landing[2] if own.landing is not None else r  # it lies within this of P
    t0, t1 = flip.event, serve.start if serve is not None else math.inf
    lying = lying_burgers(timeline, cell, footprints)
    P = landing_candidates(cell, margin / 2)
    g, spread = cell.grill, radius - r  # the burger lands within its spread of the spot
    ok = ((P[:, 0] >= g.x_range[0] + spread - 1e-12) & (P[:, 0] <= g.x_range[1] - spread + 1e-12)
          & (P[:, 1] >= g.y_range[0] + spread - 1e-12) & (P[:, 1] <= g.y_range[1] - spread + 1e-12))

    def keep(passes):  # narrow the candidates still in to those ``passes(points)`` accepts
        idx = np.flatnonzero(ok)
        if idx.size:
            ok[idx] = passes(P[idx])

    for spot in exclude:
        keep(lambda Q: np.hypot(*(Q - np.asarray(spot)).T) > margin)
    for spot, other in taken:
        keep(lambda Q: np.hypot(*(Q - np.asarray(spot)).T) >= other + radius + margin)
    for lie in lying:
        if lie.burger != burger and lie.t0 <= t1 and lie.t1 >= t0:
            keep(lambda Q: np.hypot(*(Q - np.asarray(lie.xy)).T)
                 >= radius + r + lie.spread + margin)
    for m in motions.values():
        if m.burger == burger or m.plan is None or m.end < t0 or m.start > t1:
            continue
        fp = footprints(m.plan)
        for polys, counts in _blade_chunks(fp, m.start, t0, t1):
            keep(lambda Q: polygon_distances(Q, polys, counts).min(axis=0) >= radius + margin)
        for a, b in _carried_chunks(fp, m.start, t0, t1):
            keep(lambda Q: segment_distances(Q, a, b).min(axis=0) >= r + radius + margin)
        if fp.landing is not None and t0 <= m.start + fp.landing[0] <= t1:
            keep(lambda Q: np.hypot(*(Q - np.asarray(fp.landing[1])).T)
                 >= fp.landing[2] + radius + margin)
    if serve is not None and serve.plan is not None:  # the serve scoops from the new spot: its low part moves with it
        fp = footprints(serve.plan)
        old = np.asarray(rec.landing if rec.landing is not None else (rec.burger.x,
                                                                      rec.burger.y))
        there = [lie for lie in lying if lie.burger != burger
                 and lie.t0 <= serve.end and lie.t1 >= serve.start]
        for lie in there:
            seen = np.asarray(lie.xy) + old  # the lying burger seen from the serve: seen - Q
            for polys, counts in _blade_chunks(fp, serve.start, lie.t0, lie.t1, LOW_SEGMENTS):
                keep(lambda Q: polygon_distances(seen - Q, polys, counts).min(axis=0)
                     >= r + lie.spread + margin)
            for a, b in _carried_chunks(fp, serve.start, lie.t0, lie.t1, LOW_SEGMENTS):
                keep(lambda Q: segment_distances(seen - Q, a, b).min(axis=0)
                     >= 2 * r + lie.spread + margin)
    if not ok.any():
        return None
    drop = np.array([rec.burger.x, rec.burger.y])
    best = np.argmin(np.where(ok, np.hypot(*(P - drop).T), np.inf))
    return tuple(float(v) for v in P[best])


def _within(ts, segs, start, t0, t1, only) -> list[np.ndarray]:
    """Indices of the samples at ``start + ts`` within [t0, t1], of segments ``only`` if given,
    in chunks of at most :data:`CHUNK`."""
    keep = (t0 <= start + ts) & (start + ts <= t1)
    if only is not None:
        keep &= np.array([seg in only for seg in segs], bool)
    idx = np.flatnonzero(keep)
    return [idx[k:k + CHUNK] for k in range(0, len(idx), CHUNK)]


def _blade_chunks(fp, start, t0, t1, only=None):
    """The footprint's blade sections within [t0, t1] (cook clock, the motion started at
    ``start``), as padded polygon arrays in chunks."""
    if not fp.blade:
        return []
    ts, segs, polys, counts = fp.blade_arrays()
    return [(polys[i], counts[i]) for i in _within(ts, segs, start, t0, t1, only)]


def _carried_chunks(fp, start, t0, t1, only=None):
    """The footprint's carried-burger strokes within [t0, t1], as (starts, ends) in chunks."""
    if not fp.carried:
        return []
    ts, segs, a, b = fp.carried_arrays()
    return [(a[i], b[i]) for i in _within(ts, segs, start, t0, t1, only)]


def clear_cook(schedule: Callable[[dict], object], cell: CellConfig,
               margin: float | None = None, max_rounds: int = MAX_ROUNDS, atlas=None):
    """Schedule a cook whose motions meet no other burger.

    Args:
        schedule: ``(lands, headings) -> Timeline``: plans and schedules the cook with each
            burger of ``lands`` (id -> (x, y) m) landed there by its flip and each of
            ``headings`` (id -> rad) scooped along that heading (e.g.
            :func:`~flipkit.planning.kitchen.optimal.schedule_cook_cpsat`).
        cell: The cell. margin: As :func:`~flipkit.planning.kitchen.sweep.meetings`.
        max_rounds: Plan-schedule-check rounds at most.
        atlas: The planners' :class:`~flipkit.planning.planners.atlas.Atlas`, if any: turns
            it solved near a burger are tried before the others (:class:`Turns`).

    Returns:
        ``(timeline, lands, headings)``: the first timeline without meetings (or one with a
        failed plan, which the caller reports as such), the landing spots it moved and the
        scoop headings it turned.

    Raises:
        CookConflictError: A meeting that no landing spot or heading avoids (one line naming
            the motion, the burger it meets and why it cannot be moved).
    """
    lands: dict[str, tuple] = {}
    tried: dict[str, list] = {}
    turns = Turns(cell, solved=None if atlas is None else
                  (lambda xy: atlas.solved_turns(xy, cell)))
    fps = Footprints(cell)  # kept over the rounds: a plan made again is a new key
    for round_ in range(max_rounds + 1):
        timeline = schedule(dict(lands), dict(turns.headings))
        flops = {m.burger for m in timeline.motions if m.kind == "flip" and not m.ok}
        failed = [b for b in lands if b in flops]
        if failed:  # a flip that cannot land there: try the next spot
            for b in failed:
                tried.setdefault(b, []).append(lands.pop(b))
            continue
        unplanned = [b for b in turns.headings if b in flops]
        if unplanned:  # a flip that cannot be planned at that heading: the next one
            for b in unplanned:
                turns.next(b, None, timeline, failed=True)
            continue
        if not timeline.ok:
            return timeline, lands, turns.headings
        found = cook_meetings(timeline, cell, fps, margin)
        if not found:
            return timeline, lands, turns.headings
        if round_ == max_rounds:
            raise CookConflictError(f"{found[0][0].describe()}; still after {max_rounds} "
                                    f"rounds of moving landing spots")
        move, turn = {}, {}  # move: meeting -> the burgers whose landing may move, in turn
        for meet, lie in found:
            kind, owner = meet.motion.split(":", 1)
            follows = kind == "serve" or meet.part == "landing" or meet.segment in TOSS_SEGMENTS
            if lie.landed:  # the burger met moves, else the motion's own where it follows it
                move.setdefault(meet, [lie.burger] + ([owner] if follows else []))
            elif follows and (kind == "serve" or meet.part == "landing"
                              or len(tried.get(owner, ())) < 2):
                # a flip's toss goes where it lands its burger: a toss that meets a burger
                # still lying where it was dropped lands its own elsewhere (two spots tried)
                move.setdefault(meet, [owner])
            else:  # the scoop, or a toss moved twice: the flip is turned
                turn.setdefault(owner, (meet, lie))
        for owner, (meet, lie) in turn.items():
            turns.next(owner, lie, timeline, meet=meet,
                       overlap=_turned_overlap(owner, timeline, cell, fps, margin))
        moved: set[str] = set()
        for meet, whom in move.items():
            if moved & set(whom):
                continue  # one landing moved this round for this meeting already
            for who in whom:
                spot = free_landing(who, timeline, cell, fps, margin,
                                    exclude=tried.get(who, []) + ([lands[who]] if who in lands
                                                                   else []),
                                    taken=[(lands[b], _landing_radius(b, timeline, cell, fps))
                                           for b in moved])
                if spot is not None:
                    break
            else:
                kind, owner = meet.motion.split(":", 1)
                if kind == "flip" and meet.part in PARTS and meet.segment not in TOSS_SEGMENTS:
                    lie = next(lie for m, lie in found if m == meet)  # its scoop is turned
                    if owner not in turn:
                        turn[owner] = (meet, lie)
                        turns.next(owner, lie, timeline, meet=meet,
                                   overlap=_turned_overlap(owner, timeline, cell, fps,
                                                           margin))
                    continue
                raise CookConflictError(
                    f"{meet.describe()}; no landing spot for burger {' or '.join(whom)} keeps "
                    f"clear of the other burgers and motions", kind="landing")
            tried.setdefault(who, []).append(spot)
            lands[who] = spot
            moved.add(who)
    raise CookConflictError(f"no landing spot for burgers {', '.join(sorted(tried))} "
                            f"gives a flip that can be planned", kind="landing")


__all__ = ["MAX_ROUNDS", "CookConflictError", "Footprints", "clear_cook", "cook_meetings",
           "free_landing", "landing_candidates", "lying_burgers"]
