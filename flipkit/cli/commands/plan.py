"""``flipkit plan`` once its arguments are parsed (:mod:`flipkit.cli.plan`): check the
numbers, the burger, the start configuration and the outputs, plan, write and summarise."""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import math
import os
import sys
import warnings
from pathlib import Path

from flipkit.behaviors.models import models_for
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.serve import check_table_spot
from flipkit.behaviors.targets import check_burger_height
from flipkit.cli.common import MAX_WORKERS, check_int
from flipkit.config import CellConfig
from flipkit.config.task import R_LAND_RANGE
from flipkit.decimal_text import decimal
from flipkit.errors import ConfigError, FlipkitError, UnreachableError
from flipkit.experiments.sweep import make_executor
from flipkit.fileio import (InputFileError, check_output, check_output_dir, data_lines, read_text,
                            write_text)
from flipkit.planning.planners.atlas import Atlas, default_atlas
from flipkit.planning.planners.inputs import check_spacing, check_start
from flipkit.planning.planners.planner import (MAX_BATCH, SUMMARY_HEADER, format_summary, plan_batch,
                                      plan_flip, plan_translate, summary_table)
from flipkit.planning.planners.serve import plan_serve

CSV_COLUMNS = (("x", "y", "z"), ("px", "py", "pz"))


def _numbers(what: str, values, count: int | None = None) -> list[float]:
    """Command-line words as finite floats (exactly ``count`` of them if given)."""
    values = [values] if isinstance(values, str) else list(values)
    if count is not None and len(values) != count:
        raise ConfigError(f"{what} takes {count} numbers, got {len(values)}")
    try:
        out = [decimal(v) for v in values]
    except ValueError:
        raise ConfigError(f"{what}: not a decimal number in {' '.join(values)} (digits, an "
                          "optional point and exponent; no separators)") from None
    if not all(math.isfinite(v) for v in out):
        raise ConfigError(f"{what} must be finite, got {' '.join(values)}")
    return out


def _yaw(value) -> float:
    """``--yaw`` (rad) wrapped to (−π, π]: 2π plans as 0."""
    y = _numbers("--yaw", value)[0]
    return math.pi - (math.pi - y) % (2 * math.pi)


def _burger(values, cell) -> list[float]:
    """``--burger X Y Z`` (m), its height on the grill surface (checked before any model
    loads: :func:`~flipkit.behaviors.targets.check_burger_height`)."""
    loc = _numbers("--burger", values, 3)
    check_burger_height(cell, loc[2], "--burger")
    return loc


def _start_q(values, cell):
    """``--start-q Q1 .. Q6`` (rad) within the joint limits and on q_home's side of the elbow
    and wrist singularities, SINGULARITY_MARGIN from them (every plan from there would fail
    verify's ``singularity`` check); ``None`` if not given."""
    if values is None:
        return None
    q = _numbers("--start-q", values, 6)
    robot = models_for(cell).for_segment("go_to_burger")
    return check_start(robot, q, what="--start-q", branch_side=True)[0]


def _r_land(value) -> float:
    """``--r-land`` (m) within R_LAND_RANGE: a smaller disc is within the landing's spread
    (its prediction and verify's recomputation agree only to R_LAND_RANGE[0])."""
    r = _numbers("--r-land", value)[0]
    lo, hi = R_LAND_RANGE
    if not lo <= r <= hi:
        raise ConfigError(f"--r-land must be in [{lo:g}, {hi:g}] m, got {value}: "
                          + (f"the landing's spread (prediction against verify's check) is "
                             f"{lo:g} m, a smaller disc cannot be planned to"
                             if r < lo else "a wider disc is larger than the burger"))
    return r


def _json_out(args, inputs=()) -> None:
    """``--json``: a writable ``.json`` file, not an input (checked before planning)."""
    check_output(args.json, "--json", (".json",), inputs=[*inputs, getattr(args, "atlas", None)])


def read_locations(path) -> list[tuple[float, float, float]]:
    """Burger locations (m) from a CSV with columns x,y,z or px,py,pz (others ignored).

    Blank lines and lines starting with ``#`` are skipped; at most five rows.

    Raises:
        ConfigError: Unreadable file, missing columns, a non-numeric or non-finite value,
            no rows or more than five (one line naming the file and the line).
    """
    try:
        text = read_text(path, "--burgers", 2**20)
    except InputFileError as exc:
        raise ConfigError(f"--burgers {path}: cannot read burger CSV "
                          f"({str(exc).split(': ', 1)[-1]})") from None
    lines = data_lines(text)
    if not lines:
        raise ConfigError(f"{path}: no header and no burger rows")
    header = [h.strip().lower() for h in next(csv.reader([lines[0][1]]))]
    cols = next((c for c in CSV_COLUMNS if set(c) <= set(header)), None)
    if cols is None:
        raise ConfigError(f"{path}: line {lines[0][0]}: header must have columns x,y,z or "
                          f"px,py,pz, got {','.join(header)}")
    idx = [header.index(c) for c in cols]
    rows = lines[1:]
    if not 1 <= len(rows) <= MAX_BATCH:
        raise ConfigError(f"{path}: expected 1 to {MAX_BATCH} burger rows, got {len(rows)}")
    out = []
    for n, line in rows:
        cells = next(csv.reader([line]))
        if len(cells) != len(header):
            raise ConfigError(f"{path}: line {n}: expected {len(header)} values, got {len(cells)}")
        out.append(tuple(_numbers(f"{path}: line {n}", [cells[i].strip() for i in idx])))
    return out


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
    _json_out(args)
    start, goal = _numbers("--from", args.start, 3), _numbers("--to", args.goal, 3)
    plan = plan_translate(start, goal, solver=args.solver, yaw=_yaw(args.yaw))
    plan.to_json(args.json)
    return _report(plan, args.json)


def run_flip(args: argparse.Namespace) -> int:
    """Plan, write (solved or failed), summarise."""
    _quiet()
    _json_out(args)
    cell = CellConfig()
    location = _burger(args.burger, cell)
    land = None if args.land is None else _numbers("--land", args.land, 2)
    options = SegmentOptions() if args.r_land is None else SegmentOptions(
        r_land=_r_land(args.r_land))
    q_start = _start_q(args.start_q, cell)
    atlas = _atlas(args, options, cell)
    plan = plan_flip(location, q_start, cell=cell, solver=args.solver, land=land,
                     options=options, atlas=atlas)
    plan.to_json(args.json)
    if atlas is not None:
        print(f"  warm start: atlas of {len(atlas)} locations")
    return _report(plan, args.json)


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
    _json_out(args)
    cell = CellConfig()
    location = _burger(args.burger, cell)
    spot = _numbers("--table-spot", args.table_spot, 2)
    try:
        check_table_spot(cell, spot)
    except UnreachableError as exc:
        raise UnreachableError(f"--table-spot: {exc}") from None
    q_start = _start_q(args.start_q, cell)

    atlas = _atlas(args, SegmentOptions(), cell)
    plan = plan_serve(location, spot, q_start, cell=cell, solver=args.solver, atlas=atlas)
    plan.to_json(args.json)
    if atlas is not None:
        print(f"  warm start: atlas of {len(atlas)} locations (go to burger, scoop, pickup)")
    return _report(plan, args.json)


def run_batch(args: argparse.Namespace) -> int:
    """Plan the batch, write every plan and summary.csv, print the table."""
    _quiet()
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    locations = read_locations(args.burgers)
    cell = CellConfig()
    for k, loc in enumerate(locations, 1):
        check_burger_height(cell, loc[2], f"{args.burgers}: burger {k}")
    check_spacing(locations, cell.burger.diameter, str(args.burgers))  # as schedule does
    check_output_dir(args.out, "--out", inputs=[args.burgers, args.atlas],
                     names=[*(f"burger_{k}.json" for k in range(1, len(locations) + 1)),
                            "summary.csv"])
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
