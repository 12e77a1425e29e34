"""``flipkit plan`` once its arguments passed :mod:`flipkit.cli.plan` (numbers, burgers,
outputs): check the start configuration against the arm's model, plan, write and
summarise."""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import os
import sys
import warnings
from pathlib import Path

from flipkit.behaviors.options import SegmentOptions
from flipkit.config import CellConfig, with_parameter
from flipkit.errors import FlipkitError
from flipkit.experiments.sweep import make_executor
from flipkit.fileio import write_text
from flipkit.planning.planners.atlas import Atlas, default_atlas
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.inputs import check_start
from flipkit.planning.planners.planner import (SUMMARY_HEADER, format_summary, plan_batch,
                                               plan_flip, plan_translate, summary_table)
from flipkit.planning.planners.serve import plan_serve


def _start_q(values, models):
    """``--start-q`` (rad, six finite numbers: :mod:`flipkit.cli.plan`) within the joint
    limits and on q_home's side of the elbow and wrist singularities, SINGULARITY_MARGIN from
    them (every plan from there would fail verify's ``singularity`` check), with the cell's
    ``models``; ``None`` if not given."""
    if values is None:
        return None
    robot = models.for_segment("go_to_burger")
    return check_start(robot, values, what="--start-q", branch_side=True)[0]


def _quiet():
    """Silence cvxpy's 'Solution may be inaccurate' warnings (the SQP handles them)."""
    warnings.filterwarnings("ignore", message="Solution may be inaccurate")


def _report(plan, path: str | None) -> int:
    """Print the plan's summary (stdout) or its failure (one line, stderr); 0 or 1."""
    segs = plan.segments
    for s in segs:
        print(f"  {s.name:<13} T {s.T:5.3f} s  solve {s.solver.wall_time_s:7.2f} s  "
              f"{s.solver.iterations:4d} it  viol {s.solver.max_violation:.1e}  {s.solver.status}")
    where = f"; wrote {path}" if path else ""
    solve = sum(s.solver.wall_time_s for s in segs)
    print(f"flipkit plan: {plan.behavior} {plan.status}: {len(segs)} segment(s), "
          f"T {sum(s.T for s in segs):.3f} s, solve {solve:.2f} s "
          f"({segs[0].solver.name}), {sum(s.solver.iterations for s in segs)} iterations, "
          f"max violation {max(s.solver.max_violation for s in segs):.1e}{where}")
    for s in segs:
        if s.landing:
            land = s.landing
            print(f"  landing: release at node {s.release['node']} ({s.release['time']:.3f} s), "
                  f"flight {land['time_of_flight']:.3f} s, lands {1e3 * land['offset']:.1f} mm "
                  f"from ({land['target'][0]:.3f}, {land['target'][1]:.3f}) m, top face "
                  f"{land['tilt_deg']:.1f} deg from up")
    if plan.status == "solved":
        return 0
    print(f"flipkit: error: {plan.failure}", file=sys.stderr)
    return 1


def run_translate(args: argparse.Namespace) -> int:
    """Plan, write (solved or failed), summarise."""
    _quiet()
    plan = plan_translate(args.start, args.goal, solver=args.solver, yaw=args.yaw)
    plan.to_json(args.json)
    return _report(plan, args.json)


def run_flip(args: argparse.Namespace) -> int:
    """Plan, write (solved or failed), summarise."""
    _quiet()
    cell, caches = _cell(args), PlannerCaches()  # the start's check and the plan share them
    options = SegmentOptions() if args.r_land is None else SegmentOptions(r_land=args.r_land)
    q_start = _start_q(args.start_q, caches.models(cell))
    atlas = _atlas(args, options, cell)
    plan = plan_flip(args.burger, q_start, cell=cell, solver=args.solver, land=args.land,
                     options=options, atlas=atlas, heading=args.heading, caches=caches)
    plan.to_json(args.json)
    if atlas is not None:
        print(f"  warm start: atlas of {len(atlas)} entries")
    return _report(plan, args.json)


def _cell(args: argparse.Namespace) -> CellConfig:
    """The cell, its burger of ``--burger-diameter`` when given (a plan is made for the burger
    the camera sees; the plan file records its diameter, and verify checks it)."""
    cell = CellConfig()
    if getattr(args, "burger_diameter", None) is None:
        return cell
    return with_parameter(cell, "burger.diameter", args.burger_diameter)


def _atlas(args: argparse.Namespace, options, cell):
    """The atlas ``plan flip`` warm-starts from: ``--atlas FILE`` (refused if stale), else the
    package's when it exists and serves ``options`` in ``cell``, else ``None`` (cold
    starts)."""
    if args.no_atlas:
        return None
    if args.atlas:
        return Atlas.load(args.atlas, cell, options)
    return default_atlas(cell, options)  # else cold starts (e.g. another --r-land)


def run_serve(args: argparse.Namespace) -> int:
    """Plan, write (solved or failed), summarise."""
    _quiet()
    cell, caches = _cell(args), PlannerCaches()  # the start's check and the plan share them
    q_start = _start_q(args.start_q, caches.models(cell))
    atlas = _atlas(args, SegmentOptions(), cell)
    plan = plan_serve(args.burger, args.table_spot, q_start, cell=cell, solver=args.solver,
                      atlas=atlas, heading=args.heading, caches=caches)
    plan.to_json(args.json)
    if atlas is not None:
        print(f"  warm start: atlas of {len(atlas)} entries (go to burger, scoop, pickup)")
    return _report(plan, args.json)


def run_batch(args: argparse.Namespace) -> int:
    """Plan the batch, write every plan and summary.csv, print the table."""
    _quiet()
    locations, cell = args.locations, CellConfig()  # read and checked by flipkit.cli.plan
    atlas = _atlas(args, SegmentOptions(), cell)
    workers = (os.cpu_count() or 1) if args.workers is None else args.workers
    pool = (make_executor(workers=workers) if workers > 1 and len(locations) > 1
            else contextlib.nullcontext())
    with pool as executor:  # its workers end with the run, however it ends
        plans = plan_batch(locations, cell=cell, solver=args.solver,
                           progress=not args.no_progress, executor=executor, atlas=atlas)
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        rows = summary_table(plans)
        for k, plan in enumerate(plans, 1):
            plan.to_json(out / f"burger_{k}.json")
        text = io.StringIO(newline="")
        w = csv.writer(text)
        w.writerow(SUMMARY_HEADER[:1] + ("x", "y", "z") + SUMMARY_HEADER[2:])
        for k, loc, *rest in rows:
            w.writerow([k, *loc, *rest])
        write_text(out / "summary.csv", text.getvalue())
    except OSError as exc:
        raise FlipkitError(f"{out}: cannot write ({exc.strerror or exc})") from None
    print(format_summary(rows))
    total = sum(r[3] for r in rows)
    print(f"flipkit plan: batch of {len(plans)}: {sum(p.status == 'solved' for p in plans)} "
          f"solved, solve time {total:.1f} s ({args.solver}); wrote {out}/")
    for k, plan in enumerate(plans, 1):
        if plan.status != "solved":
            print(f"flipkit: error: burger {k}: {plan.failure}", file=sys.stderr)
    return 0 if all(p.status == "solved" for p in plans) else 1
