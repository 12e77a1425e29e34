"""``flipkit schedule`` once its arguments passed :mod:`flipkit.cli.schedule`: read the cook
order, plan its motions, write the timeline, the plans and the Gantt chart, report."""

from __future__ import annotations

import argparse
import os
import re
import sys
import warnings
from pathlib import Path

import matplotlib

from flipkit import figures
from flipkit.cli.common import write_json
from flipkit.config import CellConfig
from flipkit.errors import FlipkitError
from flipkit.experiments.sweep import make_executor
from flipkit.figures.draw import plot_schedule
from flipkit.fileio import check_output_dir, replace_with
from flipkit.planning.kitchen import motions
from flipkit.planning.planners.atlas import default_atlas
from flipkit.planning.kitchen.cook import check_cook, read_cook_csv, table_spots
from flipkit.planning.kitchen.prefetch import PrefetchPlanners
from flipkit.planning.kitchen.schedule import format_timeline, schedule_cook


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)[:40] or "burger"


def run(args: argparse.Namespace) -> int:
    """Read, check, plan, write, report."""
    warnings.filterwarnings("ignore", message="Solution may be inaccurate")
    inputs = [args.burgers]
    cell = CellConfig()
    burgers = read_cook_csv(args.burgers, cell, serve=not args.flip_only)
    kinds = ("flip",) if args.flip_only else ("flip", "serve")
    atlas = None if args.no_atlas else default_atlas(cell)
    planners = motions.default_planners(kinds, cell, args.solver, atlas)
    timeline_path = Path(args.json)
    plans = Path(args.plans) if args.plans else timeline_path.with_name(
        timeline_path.stem + "_plans")
    check_output_dir(plans, "--plans", inputs=inputs + [args.json, args.figure])
    q_home = cell.robot.q_home
    workers = (os.cpu_count() or 1) if args.workers is None else args.workers
    executor = None
    if workers > 1:
        executor = make_executor(workers=workers)
        planners = PrefetchPlanners(check_cook(burgers, cell, serve=not args.flip_only),
                                    kinds, q_home,
                                    table_spots(cell), executor, cell, args.solver, atlas)
    try:
        timeline = schedule_cook(burgers, planners, q_home, kinds=kinds, cell=cell,
                                 progress=not args.no_progress)
    finally:
        if executor is not None:
            executor.shutdown(cancel_futures=True)
    try:
        plans.mkdir(parents=True, exist_ok=True)
        for k, m in enumerate(timeline.motions, 1):
            if m.plan is None:
                continue
            path = plans / f"{k:02d}_{m.kind}_{_safe(m.burger)}.json"
            m.plan.to_json(path)
            try:
                m.plan_file = str(path.resolve().relative_to(timeline_path.resolve().parent))
            except ValueError:
                m.plan_file = str(path.resolve())
    except OSError as exc:
        raise FlipkitError(f"{plans}: cannot write plans ({exc.strerror or exc})") from None
    doc = timeline.to_dict()
    write_json(timeline_path, doc)
    if args.figure:
        _figure(doc, args.figure)
    print(format_timeline(timeline))
    late = doc["max_lateness_s"]
    print(f"flipkit schedule: {len(timeline.burgers)} burgers, {len(timeline.motions)} "
          f"motions ({'+'.join(kinds)}), {doc['status']}; planning {doc['planning_time_s']:.1f}"
          f" s, min slack {doc['slack_s']['min']:.1f} s, max lateness flip "
          f"{_s(late['flip'])}, serve {_s(late['serve'])}; wrote {timeline_path}")
    for b in timeline.burgers:
        if b.failure:
            print(f"flipkit: error: burger {b.burger.burger}: {b.failure}", file=sys.stderr)
    return 0 if timeline.ok else 1


def _s(v) -> str:
    return "-" if v is None else f"{v:.2f} s"


def _figure(doc: dict, path) -> None:
    """Draw the Gantt chart of ``doc`` to ``path``."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # the figure is optional: pyplot only for --figure

    with figures.style():
        fig, ax = plt.subplots(figsize=(figures.PAGE_WIDTH, 0.35 * len(doc["burgers"]) + 1.6),
                               layout="constrained")
        plot_schedule(ax, doc)
        try:
            replace_with(path, lambda tmp: fig.savefig(
                tmp, metadata={"CreationDate": None} if str(path).endswith(".pdf") else None))
        except ValueError as exc:
            raise FlipkitError(f"cannot write figure {path}: {exc}") from None
        finally:
            plt.close(fig)
