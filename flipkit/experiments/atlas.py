"""Building the warm-start atlas (:mod:`flipkit.planning.planners.atlas`): pickup-and-flip solved on a
grid over the grill with the sweep executor (local processes or a Dask cluster).

    flipkit atlas build [--grid NX NY] [--scheduler ADDRESS] [--out FILE]

Each grid location (:func:`~flipkit.experiments.sweep.grill_grid`) is planned cold with the
SQP alone (the atlas serves the SQP's warm starts; with ``auto`` a location the SQP cannot
solve costs minutes of IPOPT, and a build with it does not finish in reasonable time); a
solved chain contributes every segment's solution vector, a failed
one is listed in the file's ``failed`` record and left out. Every entry's segments are rebuilt from
their start states to record the NLP structure keys, which must agree over the grid.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors.models import models_for
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.transcribe import transcribe
from flipkit.config import CellConfig
from flipkit.errors import AtlasError
from flipkit.experiments.sweep import grill_grid, make_executor, run_sweep
from flipkit.planning.planners.atlas import FORMAT, Atlas, options_hash
from flipkit.planning.planners.planner import plan_flip
from flipkit.provenance import git_commit

DEFAULT_GRID = (5, 7)  # 35 locations, 5.6 cm × 9.4 cm apart over the grill area


def solve_entry(item) -> dict:
    """Plan the chain at one location (sweep worker): ``{"location", "status", "failure",
    "x": {segment: Z}, "structure": {segment: key}, "wall_s", "iterations"}``."""
    location, cell, options = item
    plan = plan_flip(location, cell=cell, options=options, solver="sqp")
    out = {"location": list(location), "status": plan.status, "failure": plan.failure,
           "wall_s": plan.wall_time_s, "iterations": sum(s.solver.iterations for s in plan.segments),
           "x": {}, "structure": {}}
    if plan.status != "solved":
        return out
    models, q, qd = models_for(cell), None, None
    for seg in plan.segments:
        q0 = seg.q[0] if q is None else q
        landing = seg.landing or {}  # a robust flip's scenario rows are part of its NLP
        nlp = transcribe(seg.name, models, q0, seg.qd[0] if qd is None else qd,
                            location=location, options=options,
                            on_blade=landing.get("burger_on_blade", (0.0, 0.0)),
                            scenarios=[r["burger_on_blade"] for r in landing.get("scenarios", [])])
        out["structure"][seg.name] = nlp.structure_key
        out["x"][seg.name] = nlp.layout.pack(seg.q, seg.qd, seg.qdd, seg.u, seg.alpha, seg.T).tolist()
        q, qd = seg.q[-1], seg.qd[-1]
    return out


def build_atlas(cell: CellConfig | None = None, options: SegmentOptions = SegmentOptions(),
                grid=DEFAULT_GRID, scheduler: str | None = None, workers: int | None = None,
                progress: bool = True) -> Atlas:
    """Solve the grid and assemble the atlas.

    Args:
        cell: The cell (default :class:`~flipkit.config.CellConfig`). options: Transcription
            options the atlas serves. grid: (nx, ny) locations over the grill area.
        scheduler: Dask scheduler address; ``None`` for local worker processes (``workers``,
            default the CPU count). progress: Progress bar on stderr.

    Raises:
        AtlasError: No location solved, or the entries' NLP structures disagree.
    """
    cell = cell or CellConfig()
    nx, ny = grid
    locations = grill_grid(cell, nx, ny)
    t0 = time.perf_counter()
    executor = make_executor(scheduler, workers)
    try:
        results = run_sweep(solve_entry, [(loc, cell, options) for loc in locations], executor,
                            progress=progress, key_fn=lambda item: list(item[0]),
                            desc="atlas")
    finally:
        executor.shutdown()
    solved = [r for r in results if r["status"] == "solved"]
    if not solved:
        raise AtlasError(f"no location of the {nx} x {ny} grid was solved; no atlas")
    structure = solved[0]["structure"]
    for r in solved[1:]:
        if r["structure"] != structure:
            raise AtlasError(f"the NLP structure at {r['location']} differs from that at "
                             f"{solved[0]['location']}: an atlas needs one structure per segment")
    meta = {"options_hash": options_hash(cell, options), "options": dataclasses.asdict(options),
            "grid": [nx, ny], "failed": [[r["location"], r["failure"]] for r in results
                                         if r["status"] != "solved"],
            "build_s": time.perf_counter() - t0,
            "median_wall_s": float(np.median([r["wall_s"] for r in solved])),
            "median_iterations": float(np.median([r["iterations"] for r in solved])),
            "flipkit_commit": git_commit(), "format": FORMAT}
    return Atlas([r["location"] for r in solved],
                 {name: np.array([r["x"][name] for r in solved]) for name in FLIP_NAMES},
                 structure, meta)


__all__ = ["DEFAULT_GRID", "build_atlas", "solve_entry"]
