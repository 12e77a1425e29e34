"""Where a planned motion reaches down among the burgers on the grill, and whom it would meet.

A motion is planned for its own burger alone. On a grill with other burgers it may meet
them in three ways, each computed from the plan and the cell (no other numbers):

* **The blade.** A burger lying on the grill occupies the cylinder of its disc (diameter
  ``d``) from the grill surface ``h_g`` up to ``h_g + t`` (``t`` the patty's thickness).
  The blade is the rectangle ``length × width`` of the spatula frame's x-y plane (its
  thickness is inside the margin). At each sample of the plan the part of the rectangle
  below ``h_g + t`` (:func:`blade_section`; a blade pressed below ``h_g`` is on the grill,
  sliding under whatever lies there) is projected onto the grill; a
  lying burger whose disc comes within ``margin`` of that section is met. Only the go to
  burger, scoop and pickup reach that low; the test does not assume which segments do.
* **The carried burger.** During the scoop the motion's own burger is pushed from where it
  lay to where the scoop model leaves it on the blade (the plan's ``burger_on_blade``, else
  the blade centre): its footprint on the grill is the capsule swept by its disc between
  the two. From the scoop's end until it is released (flip) or placed (serve) it rides on
  the blade at that point, and while its underside is below ``h_g + t`` its disc meets any
  lying disc within ``d + margin`` of its centre.
* **The landing.** A flipped burger comes down at the plan's landing point; every scenario
  of its place on the blade lands within the plan's spread of it (``landing.offset`` and the
  scenarios' offsets). Its disc of radius ``d/2 + spread`` must stay ``margin`` clear of
  every burger lying there when it lands. The flight itself passes above the flip's height
  band and meets nobody lying.

``margin`` defaults to the placement spread the robust flips plan for
(:class:`~flipkit.config.ScoopUncertainty`: ``k_sigma × placement_sigma``): a burger may
lie that far from where it was recorded. A burger a flip landed may lie farther from the
landing point, by the flip's landing spread (``Lying.spread``: where the landing disc
reaches beyond the burger's radius); each distance above grows by it: a landed burger may lie
centimetres from its predicted point, where the next flip's blade would come down on its
rim.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.config import CellConfig, ScoopUncertainty
from flipkit.model.robot import Robot
from flipkit.planning.kitchen.planar import (pad_polygons, point_polygon_distance,  # noqa: F401
                                            point_segment_distance, points_polygon_distance,
                                            points_segment_distance, polygon_distances,
                                            segment_distances)

SAMPLE_DT = 0.005  # s between samples of a plan: the blade moves < 2 mm between them


@dataclass(frozen=True)
class Lying:
    """A burger lying still on the grill at ``xy`` (m) from ``t0`` to ``t1`` (s, cook clock);
    ``landed``: where its flip put it (else where it was dropped); ``spread`` (m): how much
    farther than the margin from ``xy`` it may lie (a landed burger: its flip's landing
    spread, the landing disc's radius beyond the burger's; 0 where it was dropped)."""

    burger: str
    xy: tuple
    t0: float
    t1: float
    landed: bool = False
    spread: float = 0.0


@dataclass(frozen=True)
class Meeting:
    """A motion meets a lying burger.

    Attributes:
        motion: ``kind:burger`` of the motion. burger: The lying burger met.
        part: ``"blade"``, ``"carried burger"`` or ``"landing"``. segment: The plan segment.
        t: When (s, cook clock). overlap_m: How far inside the clearance (m, > 0).
    """

    motion: str
    burger: str
    part: str
    segment: str
    t: float
    overlap_m: float

    def describe(self) -> str:
        """One line: who meets whom, where and by how much."""
        return (f"{self.motion}: the {self.part} ({self.segment}) meets burger {self.burger} "
                f"at t = {self.t:.2f} s, {1e3 * self.overlap_m:.0f} mm inside its clearance")


@dataclass
class Footprint:
    """What a plan puts near the grill, on times from the plan's start (s).

    Attributes:
        blade: ``(t, segment, polygon)``: the blade's section within the burger's height
            above the grill, projected (k×2, m), at every sample where it is not empty.
        carried: ``(t, segment, a, b)``: the own burger's disc swept from centre ``a`` to
            ``b`` (m) while its underside is below the top of a lying burger.
        landing: ``(t, point, radius)``: the flipped burger's landing disc, or ``None``.
    """

    blade: list = field(default_factory=list)
    carried: list = field(default_factory=list)
    landing: tuple | None = None
    _arrays: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def blade_arrays(self) -> tuple[np.ndarray, list, np.ndarray, np.ndarray]:
        """:attr:`blade` as arrays, made once: times (m,), segments, the sections padded
        (m×K×2) and their vertex counts (m,)
        (:func:`~flipkit.planning.kitchen.planar.pad_polygons`)."""
        if "blade" not in self._arrays:
            polys, counts = pad_polygons([poly for _t, _s, poly in self.blade])
            self._arrays["blade"] = (np.array([t for t, _s, _p in self.blade], float),
                                     [seg for _t, seg, _p in self.blade], polys, counts)
        return self._arrays["blade"]

    def carried_arrays(self) -> tuple[np.ndarray, list, np.ndarray, np.ndarray]:
        """:attr:`carried` as arrays, made once: times (m,), segments, starts and ends (m×2)."""
        if "carried" not in self._arrays:
            c = self.carried
            self._arrays["carried"] = (
                np.array([x[0] for x in c], float), [x[1] for x in c],
                np.array([x[2] for x in c], float).reshape(-1, 2),
                np.array([x[3] for x in c], float).reshape(-1, 2))
        return self._arrays["carried"]


def default_margin() -> float:
    """The clearance kept (m): the robust flips' placement spread (2 σ = 1 cm)."""
    return ScoopUncertainty().placement


def approach_height(cell: CellConfig, margin: float | None = None) -> float:
    """How high above the grill (m) a cook's motions come in to their burger: over a lying
    burger's top (its thickness) by the clearance ``margin``
    (:attr:`~flipkit.behaviors.spec.Task.approach_height`)."""
    return cell.burger.thickness + (default_margin() if margin is None else margin)


def blade_rectangle(R, p, cell: CellConfig) -> np.ndarray:
    """The blade's four corners (4×3, m, world) for the spatula frame at rotation ``R`` and
    position ``p`` (the blade centre): ``± length/2`` along its x axis, ``± width/2`` along y."""
    R, p = np.asarray(R, float), np.asarray(p, float)
    hl, hw = cell.spatula.length / 2, cell.spatula.width / 2
    local = np.array([[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw]])
    return p + local @ R[:, :2].T


def blade_section(R, p, cell: CellConfig) -> np.ndarray:
    """The part (k×3, m, world) of the blade at rotation ``R`` and centre ``p`` that is
    below the top of a burger lying on the grill (``h_g + t``): also where it is pressed
    below the grill's surface, since a pressed blade lies on the grill; (0, 3) when none."""
    top = cell.grill.height + cell.burger.thickness
    return slab_section(blade_rectangle(R, p, cell), -math.inf, top)


def blade_sections(Rs, ps, cell: CellConfig) -> tuple[np.ndarray, np.ndarray]:
    """:func:`blade_section` at m blade poses at once (rotations m×3×3, centres m×3): the
    sections padded (m×5×3, each after its own vertices with its first; a rectangle cut by a
    plane has at most five) and their vertex counts (m,), 0 where the blade is above."""
    Rs, ps = np.asarray(Rs, float), np.asarray(ps, float)
    top = cell.grill.height + cell.burger.thickness
    hl, hw = cell.spatula.length / 2, cell.spatula.width / 2
    local = np.array([[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw]])
    C = ps[:, None, :] + np.einsum("kj,mij->mki", local, Rs[:, :, :2])  # m×4 corners
    below = C[..., 2] <= top
    slots, keep = np.zeros((len(C), 8, 3)), np.zeros((len(C), 8), bool)
    for k in range(4):  # Sutherland-Hodgman on the plane z = top, every pose at once
        a, b, ia, ib = C[:, k], C[:, (k + 1) % 4], below[:, k], below[:, (k + 1) % 4]
        dz = np.where(ia != ib, b[:, 2] - a[:, 2], 1.0)
        slots[:, 2 * k], keep[:, 2 * k] = a, ia
        slots[:, 2 * k + 1] = a + ((top - a[:, 2]) / dz)[:, None] * (b - a)
        keep[:, 2 * k + 1] = ia != ib
    order = np.argsort(~keep, axis=1, kind="stable")[:, :5]
    polys, counts = np.take_along_axis(slots, order[..., None], axis=1), keep.sum(axis=1)
    pad = np.arange(5)[None, :] >= counts[:, None]
    polys[pad] = np.repeat(polys[:, :1], 5, axis=1)[pad]
    return polys, counts


def slab_section(polygon, z_lo: float, z_hi: float) -> np.ndarray:
    """The part of a planar convex polygon (k×3, in order) with ``z_lo <= z <= z_hi``,
    clipped edge by edge (Sutherland–Hodgman on the two planes); (0, 3) when empty."""
    poly = np.asarray(polygon, float)
    for sign, bound in ((1.0, z_lo), (-1.0, z_hi)):
        if len(poly) == 0:
            break
        inside = sign * (poly[:, 2] - bound) >= 0
        out = []
        for k in range(len(poly)):
            a, b = poly[k], poly[(k + 1) % len(poly)]
            ia, ib = inside[k], inside[(k + 1) % len(poly)]
            if ia:
                out.append(a)
            if ia != ib:
                s = (bound - a[2]) / (b[2] - a[2])
                out.append(a + s * (b - a))
        poly = np.array(out).reshape(-1, 3)
    return poly


def _samples(seg, dt: float):
    t = np.asarray(seg.t, float)
    n = max(2, int(math.ceil((t[-1] - t[0]) / dt)) + 1)
    ts = np.linspace(t[0], t[-1], n)
    return ts - t[0], CubicHermiteSpline(t, seg.q, seg.qd, axis=0)(ts)


def _on_blade(plan) -> np.ndarray:
    for seg in plan.segments:
        landing = getattr(seg, "landing", None) or {}
        if "burger_on_blade" in landing:
            return np.asarray(landing["burger_on_blade"], float)[:2]
        placing = getattr(seg, "placing", None) or {}
        if "on_blade" in placing:
            return np.asarray(placing["on_blade"], float)[:2]
    return np.zeros(2)


def footprint(plan, cell: CellConfig | None = None, robot=None, dt: float = SAMPLE_DT
              ) -> Footprint:
    """The :class:`Footprint` of a solved flip or serve plan (from its joint arrays)."""
    cell = cell or plan.cell()
    robot = robot or Robot(cell, with_burger=False)
    top = cell.grill.height + cell.burger.thickness
    on_blade = np.append(_on_blade(plan), 0.0)
    out, t0, carrying = Footprint(), 0.0, False
    location = np.asarray(plan.burger["location"], float)[:2]
    times, segs, polys, counts = [], [], [], []
    for seg in plan.segments:
        ts, qs = _samples(seg, dt)
        release = (getattr(seg, "release", None) or {}).get("time")
        Ms = [robot.placement(q) for q in qs]
        Rs, ps = np.array([M.rotation for M in Ms]), np.array([M.translation for M in Ms])
        sec, n = blade_sections(Rs, ps, cell)
        low = np.flatnonzero(n)
        out.blade += [(t0 + ts[i], seg.name, sec[i, :n[i], :2]) for i in low]
        times.append(t0 + ts[low])
        segs += [seg.name] * len(low)
        polys.append(sec[low, :, :2])
        counts.append(n[low])
        prev = None
        for t, R, p in zip(ts, Rs, ps):
            if carrying and (release is None or t <= release):
                centre = p + R @ on_blade
                if centre[2] < top:
                    out.carried.append((t0 + t, seg.name, (prev if prev is not None
                                                            else centre)[:2], centre[:2]))
                prev = centre
        if SUBBEHAVIORS[seg.name].role == "scoop":
            end = robot.placement(qs[-1])
            centre = end.translation + end.rotation @ on_blade
            out.carried.append((t0 + ts[-1], seg.name, location, centre[:2]))
            carrying = True
        if release is not None:
            carrying = False
        landing = getattr(seg, "landing", None)
        if landing and "point" in landing:
            spread = max([float(landing.get("offset", 0.0))]
                         + [float(np.hypot(*(np.asarray(s["point"][:2])
                                              - np.asarray(landing["point"][:2]))))
                            for s in landing.get("scenarios", [])])
            out.landing = (t0 + float(release) + float(landing["time_of_flight"]),
                           tuple(float(v) for v in landing["point"][:2]),
                           cell.burger.diameter / 2 + spread)
        t0 += float(seg.T)
    out._arrays["blade"] = (np.concatenate(times), segs, np.concatenate(polys),
                            np.concatenate(counts))
    return out


def meetings(fp: Footprint, motion: str, start: float, lying, cell: CellConfig,
             margin: float | None = None) -> list[Meeting]:
    """Where the motion of footprint ``fp``, started at ``start`` (s, cook clock), meets the
    ``lying`` burgers (:class:`Lying`; each counts only while it lies, ``t0 <= t <= t1``).
    One :class:`Meeting` per burger and part: the deepest."""
    margin = default_margin() if margin is None else margin
    r = cell.burger.diameter / 2
    worst: dict[tuple, Meeting] = {}

    def note(b: Lying, part, seg, t, overlap):
        key = (b.burger, part)
        if overlap > 0 and (key not in worst or overlap > worst[key].overlap_m):
            worst[key] = Meeting(motion, b.burger, part, seg, t, overlap)

    lying = list(lying)
    if not lying:
        return []
    xy = np.array([b.xy for b in lying], float)
    since, until, spread = (np.array([getattr(b, f) for b in lying], float)
                            for f in ("t0", "t1", "spread"))

    def check(ts, segs, part, depth_of):  # every sample and every burger lying then, at once
        when = start + ts[:, None]
        live = (since[None] <= when) & (when <= until[None])
        if not live.any():
            return
        depth = np.where(live, depth_of(), -np.inf)
        for name in dict.fromkeys(b.burger for b in lying):  # the deepest per burger: the first
            cols = np.flatnonzero([b.burger == name for b in lying])
            sub = depth[:, cols]
            i, j = np.unravel_index(np.argmax(sub), sub.shape)
            note(lying[cols[j]], part, segs[i], float(start + ts[i]), float(sub[i, j]))

    if fp.blade:
        ts, segs, polys, counts = fp.blade_arrays()
        check(ts, segs, "blade",
              lambda: r + spread + margin - polygon_distances(xy, polys, counts))
    if fp.carried:
        ts, segs, a, c = fp.carried_arrays()
        check(ts, segs, "carried burger",
              lambda: 2 * r + spread + margin - segment_distances(xy, a, c))
    if fp.landing is not None:
        t, point, radius = fp.landing
        check(np.array([t]), ["flip"], "landing",
              lambda: (radius + r + spread + margin - np.hypot(*(xy - np.asarray(point)).T))[None])
    return sorted(worst.values(), key=lambda m: (m.t, m.burger))


__all__ = ["SAMPLE_DT", "Footprint", "Lying", "Meeting", "approach_height", "blade_rectangle",
           "blade_section", "blade_sections",
           "default_margin",
           "footprint", "meetings", "point_polygon_distance", "point_segment_distance",
           "points_polygon_distance", "points_segment_distance", "slab_section"]
