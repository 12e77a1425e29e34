"""Whether the motions of a modelled stream could run among the burgers on the grill.

A stream scheduled on the duration model (:mod:`flipkit.planning.kitchen.durations`) plans no
motion, so nothing says whether its flips and serves would keep clear of the other burgers.
Here each motion is given the footprint of the model's representative plan of its kind
(:func:`~flipkit.planning.kitchen.sweep.footprint`), carried into the burger's task frame
(the burger at the origin, the scoop heading along +x) and placed at its own burger turned
to a heading: the paper's constraints (22)–(26) are stated in that frame, so what reaches
down among the other burgers moves with the burger and turns with the heading
(:mod:`flipkit.planning.kitchen.heading_model` compares the turned footprint with turned
plans). A motion is clear when at some heading within
:data:`~flipkit.planning.kitchen.turns.MAX_TURN` of radial (the radial one first, then in
:data:`~flipkit.planning.kitchen.turns.TURN_STEP` steps) neither its blade, nor its carried
burger, nor a flip's landing disc (where it picked the burger up: a stream does not move
landings) comes within the margin of a burger lying while it runs, as
:func:`~flipkit.planning.kitchen.sweep.meetings` judges. A burger whose flip or serve is not
clear at any heading is **blocked**: a stream counts it as missed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from flipkit.config import CellConfig
from flipkit.planning.kitchen.clearance import lying_burgers
from flipkit.planning.kitchen.heading_model import mapped_footprint, turned_footprint
from flipkit.planning.kitchen.sweep import Footprint, default_margin, meetings
from flipkit.planning.kitchen.turns import Turns


def to_task_frame(fp: Footprint, pb, psi: float) -> Footprint:
    """``fp``, a plan's footprint for a burger at ``pb`` (m) scooped along ``psi`` (rad), in
    that burger's task frame: ``pb`` at the origin, the heading along +x."""
    return _moved(turned_footprint(fp, pb, -float(psi), landing=True),
                  -np.asarray(pb, float)[:2])


def placed(task_fp: Footprint, pb, psi: float) -> Footprint:
    """A task-frame footprint (:func:`to_task_frame`) placed at a burger at ``pb`` (m) and
    scooped along ``psi`` (rad)."""
    pb = np.asarray(pb, float)[:2]
    return turned_footprint(_moved(task_fp, pb), pb, float(psi), landing=True)


def _moved(fp: Footprint, d) -> Footprint:
    d = np.asarray(d, float)
    return mapped_footprint(fp, lambda P: P + d)


@dataclass(frozen=True)
class Blocked:
    """A burger whose ``kind`` motion meets ``met`` at every heading tried, ``overlap_m``
    (m) inside its clearance at the best of them."""

    burger: str
    kind: str
    met: str
    overlap_m: float

    def describe(self) -> str:
        """One line."""
        return (f"burger {self.burger}: its {self.kind} meets burger {self.met} at every "
                f"scoop heading tried, {1e3 * self.overlap_m:.0f} mm inside its clearance "
                f"at the best")


def blocked_burgers(timeline, footprints, cell: CellConfig,
                    margin: float | None = None) -> list[Blocked]:
    """The burgers of ``timeline`` whose flip or serve is clear at no heading (module
    docstring). ``footprints``: motion kind -> task-frame footprint (:func:`to_task_frame`)."""
    turns = Turns(cell)
    r = cell.burger.diameter / 2
    spread = {k: max(fp.landing[2] - r, 0.0) for k, fp in footprints.items()
              if fp.landing is not None}
    lying = [dataclasses.replace(lie, spread=spread.get("flip", 0.0)) if lie.landed else lie
             for lie in lying_burgers(timeline)]
    where = {rec.burger.burger: rec for rec in timeline.burgers}
    # how far from its burger a motion reaches a lying burger's clearance (m): no one farther
    # can be met, so the check looks at the burgers lying nearer while it runs
    margin_m = default_margin() if margin is None else margin
    reach = {k: _extent(fp) + r + margin_m + max([lie.spread for lie in lying], default=0.0)
             for k, fp in footprints.items()}
    xy = np.array([lie.xy for lie in lying], float).reshape(-1, 2)
    t0, t1 = (np.array([getattr(lie, f) for lie in lying], float) for f in ("t0", "t1"))
    out: dict[str, Blocked] = {}
    for m in timeline.motions:
        if not m.ok or m.event is None or m.kind not in footprints or m.burger in out:
            continue
        rec = where[m.burger]
        pb = ((rec.burger.x, rec.burger.y) if m.kind == "flip" or rec.landing is None
              else tuple(rec.landing))
        near = ((t0 <= m.end) & (t1 >= m.start)
                & (np.hypot(*(xy - np.asarray(pb)).T) <= reach[m.kind]))
        others = [lying[i] for i in np.flatnonzero(near) if lying[i].burger != m.burger]
        if not others:
            continue
        best = None
        for psi in [turns.default(pb), *turns.candidates(pb)]:
            met = meetings(placed(footprints[m.kind], pb, psi), m.key, m.start, others, cell,
                           margin)
            if not met:
                best = None
                break
            deepest = max(met, key=lambda x: x.overlap_m)
            if best is None or deepest.overlap_m < best.overlap_m:
                best = deepest
        if best is not None:
            out[m.burger] = Blocked(m.burger, m.kind, best.burger, best.overlap_m)
    return sorted(out.values(), key=lambda b: b.burger)


def _extent(fp: Footprint) -> float:
    """The farthest (m) a task-frame footprint reaches from its burger: its blade's corners,
    its carried burger's centre and its landing disc."""
    points = [np.asarray(p, float).reshape(-1, 2) for _t, _s, p in fp.blade]
    points += [np.asarray([a, b], float) for _t, _s, a, b in fp.carried]
    far = max([float(np.hypot(*P.T).max()) for P in points if len(P)], default=0.0)
    if fp.landing is not None:
        far = max(far, float(np.hypot(*fp.landing[1])) + fp.landing[2])
    return far


__all__ = ["Blocked", "blocked_burgers", "placed", "to_task_frame"]
