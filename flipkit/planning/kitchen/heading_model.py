"""A flip's footprint at another scoop heading, predicted from its plan at one heading.

The paper's constraints (22)–(26) hold in the task frame turned by the scoop heading ψ about
the burger p^b (:mod:`flipkit.model.task_frame`): the go to burger's end, the scoop, the
pickup and a toss that lands the burger where it lay are the same motion in that frame at
every heading. What reaches down among the other burgers (the blade's low section, the
carried burger) therefore turns with ψ about p^b. The approach from the rest configuration
changes with ψ, but a cook's approach comes in above the burgers
(:func:`~flipkit.planning.kitchen.sweep.approach_height`) until its descent onto the scoop's
start, which is in the task frame. So the footprint at ψ + Δ is, to that approximation, the
footprint at ψ turned by Δ about p^b. The landing disc stays where it is: it is the landing
spot's, chosen apart (:func:`~flipkit.planning.kitchen.clearance.free_landing`).

A cook ranks a flip's headings with it before planning any
(:class:`~flipkit.planning.kitchen.turns.Turns`); the plan made at the heading chosen is then
checked from its own footprint, as every plan is. ``tests/test_heading_model.py`` compares the
prediction with plans made at the turned headings.
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.config import CellConfig
from flipkit.planning.kitchen.planar import polygon_distances, segment_distances
from flipkit.planning.kitchen.sweep import SAMPLE_DT, Footprint, default_margin

PARTS = ("blade", "carried burger")  # what turns with the heading (not the landing disc)
# m added to the clearance when ranking headings: the prediction's error where the sweep
# passes (docs/history.md), so that a heading predicted clear is clear when planned
MODEL_MARGIN = 0.015


def _turn(points, pb, delta: float) -> np.ndarray:
    """``points`` (…×2, m) turned by ``delta`` (rad) about ``pb``."""
    c, s = math.cos(delta), math.sin(delta)
    R = np.array([[c, -s], [s, c]])
    pb = np.asarray(pb, float)[:2]
    return (np.asarray(points, float) - pb) @ R.T + pb


def mapped_footprint(fp: Footprint, f, landing: bool = True) -> Footprint:
    """``fp`` with every point moved by ``f`` (a rigid map of …×2 arrays, m): its blade
    sections and carried burger, and its landing disc's centre with ``landing``. Works on the
    footprint's arrays at once, and hands them on made."""
    out = Footprint(landing=fp.landing)
    if fp.blade:
        ts, segs, polys, counts = fp.blade_arrays()
        moved = f(polys)
        out.blade = [(t, seg, moved[i, :counts[i]]) for i, (t, seg) in enumerate(zip(ts, segs))]
        out._arrays["blade"] = (ts, segs, moved, counts)
    if fp.carried:
        ts, segs, a, b = fp.carried_arrays()
        fa, fb = f(a), f(b)
        out.carried = [(t, seg, tuple(fa[i]), tuple(fb[i])) for i, (t, seg) in
                       enumerate(zip(ts, segs))]
        out._arrays["carried"] = (ts, segs, fa, fb)
    if landing and fp.landing is not None:
        centre = f(np.asarray(fp.landing[1], float)[None])[0]
        out.landing = (fp.landing[0], tuple(float(v) for v in centre), fp.landing[2])
    return out


def turned_footprint(fp: Footprint, pb, delta: float, landing: bool = False) -> Footprint:
    """``fp`` (a flip's footprint at heading ψ, burger at ``pb`` (m)) predicted at ψ + ``delta``
    (rad): its blade sections and carried burger turned about ``pb``; its landing disc turned
    too with ``landing``, else left where it is (module docstring)."""
    if delta == 0.0:
        return fp
    return mapped_footprint(fp, lambda P: _turn(P, pb, delta), landing)


def predicted_overlap(fp: Footprint, pb, delta: float, motion: str, start: float, lying,
                      cell: CellConfig, margin: float | None = None) -> float:
    """How far (m·s) the flip of footprint ``fp``, turned by ``delta`` (rad) about ``pb`` and
    started at ``start`` (s, cook clock), would come inside the clearance of the ``lying``
    burgers (:class:`~flipkit.planning.kitchen.sweep.Lying`) with its blade or carried burger:
    each sample's depth inside a clearance, summed over the samples and burgers and times
    the sampling interval. 0 exactly when :func:`~flipkit.planning.kitchen.sweep.meetings`
    finds neither part meeting anyone; unlike the deepest meeting, which stops growing once a
    burger lies wholly under the sweep, it keeps ranking how much of the sweep passes over
    burgers."""
    margin = default_margin() if margin is None else margin
    lying = list(lying)
    if not lying:
        return 0.0
    turned = turned_footprint(fp, pb, delta)
    r = cell.burger.diameter / 2
    xy = np.array([b.xy for b in lying], float)
    since, until, spread = (np.array([getattr(b, f) for b in lying], float)
                            for f in ("t0", "t1", "spread"))
    total = 0.0
    if turned.blade:
        ts, _segs, polys, counts = turned.blade_arrays()
        depth = r + spread[None] + margin - polygon_distances(xy, polys, counts)
        total += _live_sum(depth, start + ts, since, until)
    if turned.carried:
        ts, _segs, a, b = turned.carried_arrays()
        depth = 2 * r + spread[None] + margin - segment_distances(xy, a, b)
        total += _live_sum(depth, start + ts, since, until)
    return total * SAMPLE_DT


def _live_sum(depth, when, since, until) -> float:
    """The positive ``depth`` (samples × burgers) summed where the burger lies at that time."""
    live = (since[None] <= when[:, None]) & (when[:, None] <= until[None])
    return float(np.where(live, np.clip(depth, 0.0, None), 0.0).sum())


__all__ = ["MODEL_MARGIN", "PARTS", "mapped_footprint", "predicted_overlap", "turned_footprint"]
