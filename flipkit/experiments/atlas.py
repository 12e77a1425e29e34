"""Building the warm-start atlas (:mod:`flipkit.planning.planners.atlas`): pickup-and-flip solved on a
grid over the grill with the sweep executor (local processes or a Dask cluster).

    flipkit atlas build [--grid NX NY] [--scheduler ADDRESS] [--out FILE]

Each grid location (:func:`~flipkit.experiments.sweep.grill_grid`) is planned cold with the
SQP alone at its default scoop heading (the atlas serves the SQP's warm starts; with ``auto``
a location the SQP cannot solve costs minutes of IPOPT, and a build with it does not finish
in reasonable time). Then each location is planned again at its default heading turned by
each of ``turns`` (within ±:data:`~flipkit.config.task.HEADING_LIMIT`), seeded from the
default headings' entries: a turned scoop from cold starts takes the SQP minutes where a
seeded one takes seconds. A solved chain contributes every segment's solution vector, a
failed one is listed in the file's ``failed`` record and left out. Every entry's segments are
rebuilt from their start states to record the NLP structure keys, which must agree over the
grid.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.targets import default_heading
from flipkit.behaviors.transcribe import transcribe
from flipkit.config import CellConfig
from flipkit.config.task import HEADING_LIMIT, HEADING_STEPS
from flipkit.errors import AtlasError
from flipkit.experiments.sweep import grill_grid, make_executor, run_sweep
from flipkit.planning.planners.atlas import FORMAT, Atlas, options_hash
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import plan_flip
from flipkit.provenance import git_commit

DEFAULT_GRID = (5, 7)  # 35 locations, 5.6 cm × 9.4 cm apart over the grill area
# rad, from each location's default heading: the kitchen's turns (flipkit.planning.kitchen.turns)
DEFAULT_TURNS = tuple(sorted({0.0, *(s * t for t in HEADING_STEPS for s in (-1.0, 1.0))}))


def solve_entry(item) -> dict:
    """Plan the chain at one location and heading (sweep worker): ``{"location", "heading",
    "status", "failure", "x": {segment: Z}, "structure": {segment: key}, "wall_s",
    "iterations"}``. ``item``: (location, heading (rad), cell, options, seed atlas or
    ``None``)."""
    location, heading, cell, options, seed = item
    caches = PlannerCaches()  # the plan's and the rebuilt segments'
    plan = plan_flip(location, cell=cell, options=options, solver="sqp", heading=heading,
                     atlas=seed, caches=caches)
    out = {"location": list(location), "heading": float(heading), "status": plan.status,
           "failure": plan.failure,
           "wall_s": plan.wall_time_s, "iterations": sum(s.solver.iterations for s in plan.segments),
           "x": {}, "structure": {}}
    if plan.status != "solved":
        return out
    models, q, qd = caches.models(cell), None, None
    for seg in plan.segments:
        q0 = seg.q[0] if q is None else q
        landing = seg.landing or {}  # a robust flip's scenario rows are part of its NLP
        nlp = transcribe(seg.name, models, q0, seg.qd[0] if qd is None else qd,
                            location=location, options=options,
                            on_blade=landing.get("burger_on_blade", (0.0, 0.0)),
                            scenarios=[r["burger_on_blade"] for r in landing.get("scenarios", [])],
                            patterns=caches.patterns)
        out["structure"][seg.name] = nlp.structure_key
        out["x"][seg.name] = nlp.layout.pack(seg.q, seg.qd, seg.qdd, seg.u, seg.alpha, seg.T).tolist()
        q, qd = seg.q[-1], seg.qd[-1]
    return out


def turned_headings(cell: CellConfig, location, turns) -> list[float]:
    """The default heading at ``location`` turned by each of ``turns`` (rad), those within
    the heading limit."""
    psi = default_heading(cell, location)
    return [psi + t for t in turns if abs(psi + t) <= HEADING_LIMIT + 1e-12]


def _assemble(results, cell, options, meta) -> Atlas:
    solved = [r for r in results if r["status"] == "solved"]
    if not solved:
        raise AtlasError(f"no location of the {meta['grid'][0]} x {meta['grid'][1]} grid was "
                         "solved; no atlas")
    structure = solved[0]["structure"]
    for r in solved[1:]:
        if r["structure"] != structure:
            raise AtlasError(f"the NLP structure at {r['location']} differs from that at "
                             f"{solved[0]['location']}: an atlas needs one structure per segment")
    meta = {**meta, "options_hash": options_hash(cell, options),
            "options": dataclasses.asdict(options), "flange": cell.spatula.handle,
            "failed": [[r["location"], r["heading"], r["failure"]] for r in results
                       if r["status"] != "solved"],
            "median_wall_s": float(np.median([r["wall_s"] for r in solved])),
            "median_iterations": float(np.median([r["iterations"] for r in solved])),
            "flipkit_commit": git_commit(), "format": FORMAT}
    return Atlas([r["location"] for r in solved], [r["heading"] for r in solved],
                 {name: np.array([r["x"][name] for r in solved]) for name in FLIP_NAMES},
                 structure, meta)


def build_atlas(cell: CellConfig | None = None, options: SegmentOptions = SegmentOptions(),
                grid=DEFAULT_GRID, turns=DEFAULT_TURNS, scheduler: str | None = None,
                workers: int | None = None, progress: bool = True) -> Atlas:
    """Solve the grid at the default headings, then at the turned ones, and assemble the atlas.

    Args:
        cell: The cell (default :class:`~flipkit.config.CellConfig`). options: Transcription
            options the atlas serves. grid: (nx, ny) locations over the grill area.
        turns: Turns (rad) of each location's default heading to solve at; 0 is always
            solved first (the turned entries are seeded from those).
        scheduler: Dask scheduler address; ``None`` for local worker processes (``workers``,
            default the CPU count). progress: Progress bar on stderr.

    Raises:
        AtlasError: No location solved, or the entries' NLP structures disagree.
    """
    cell = cell or CellConfig()
    nx, ny = grid
    turns = [float(t) for t in turns]
    locations = grill_grid(cell, nx, ny)
    meta = {"grid": [nx, ny], "turns": sorted({0.0, *turns})}
    t0 = time.perf_counter()
    executor = make_executor(scheduler, workers)
    try:
        key = lambda item: [*item[0], item[1]]  # noqa: E731
        radial = run_sweep(solve_entry, [(loc, default_heading(cell, loc), cell, options, None)
                                         for loc in locations], executor, progress=progress,
                           key_fn=key, desc="atlas, default headings")
        seed = _assemble(radial, cell, options, {**meta, "build_s": 0.0})
        jobs = [(loc, psi, cell, options, seed) for loc in locations
                for psi in turned_headings(cell, loc, [t for t in turns if t != 0.0])]
        turned = run_sweep(solve_entry, jobs, executor, progress=progress, key_fn=key,
                           desc="atlas, turned headings") if jobs else []
    finally:
        executor.shutdown()
    return _assemble(radial + turned, cell, options,
                     {**meta, "build_s": time.perf_counter() - t0})


__all__ = ["DEFAULT_GRID", "DEFAULT_TURNS", "build_atlas", "solve_entry", "turned_headings"]
