"""``flipkit schedule``: order, time and plan one arm's flips and serves for a cook order.

Exit status: 0 every motion planned, solved and verified; 1 a motion's plan failed — one
line per failure on stderr; the timeline and the plan files (the failed one with
``"status": "failed"``) are still written; 2 bad input (unreadable or malformed CSV, wrong
header, a non-finite number, a drop time outside [0, 86400] s, a burger off the grill,
duplicate ids, two burgers closer than one diameter on the grill at once, more burgers to
serve than table spots), an output that is not writable, of an unknown format or the cook
order itself, or a motion kind without a planner (``flipkit.planning.planners.planner.plan_serve``
missing) — one line on stderr, nothing planned, nothing written.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import warnings
from pathlib import Path

from flipkit.cli.common import SOLVER_CHOICES, write_json
from flipkit.errors import FlipkitError

FIGURE_FORMATS = (".pdf", ".png", ".svg")  # --figure, by suffix
DESCRIPTION = (
    "Flip every burger of a cook order at its 90 s mark and serve it to a table spot after "
    "60 s on its second side, with one arm: the motions are ordered earliest deadline "
    "first and each is planned from where the previous one ends, ahead of its start. "
    "Writes the timeline (JSON), one plan file per motion, and optionally a Gantt chart. "
    "Exit 0: all solved. Exit 1: a plan failed (everything still written). Exit 2: bad "
    "input or a missing planner; nothing written.")


def register(subparsers) -> None:
    """Add the ``schedule`` sub-command to the parser."""
    p = subparsers.add_parser("schedule", help="schedule and plan the flips and serves of a "
                                                "cook (one arm)", description=DESCRIPTION)
    p.add_argument("burgers", metavar="BURGERS.csv",
                   help="cook order: header burger,t_drop,x,y (id, drop time s in [0, "
                        "86400], grill position m); lines starting with # skipped")
    p.add_argument("--json", required=True, metavar="TIMELINE.json",
                   help="timeline output (.json; not the cook order)")
    p.add_argument("--figure", metavar="PATH", help="Gantt chart (.pdf, .png or .svg)")
    p.add_argument("--plans", metavar="DIR",
                   help="directory for the motions' plan files (default: TIMELINE_plans/ "
                        "beside the timeline); the timeline names them relative to its own "
                        "directory")
    p.add_argument("--flip-only", action="store_true",
                   help="plan the flips alone (no serves; serve_time stays null)")
    p.add_argument("--solver", choices=SOLVER_CHOICES, default="auto",
                   help="NLP solver (default auto: the SQP, then IPOPT where it fails)")
    p.add_argument("--workers", type=int, default=None, metavar="K",
                   help="plan the motions ahead in K worker processes, in [1, 256] "
                        "(default: the CPU count; 1: one after another in this process)")
    p.add_argument("--no-atlas", action="store_true",
                   help="flips from cold starts (default: warm-started from the package's "
                        "atlas, `flipkit atlas build`, when it serves the default options)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)[:40] or "burger"


def run(args: argparse.Namespace) -> int:
    """Read, check, plan, write, report."""
    from flipkit.config import CellConfig
    from flipkit.planning.kitchen.cook import read_cook_csv
    from flipkit.planning.planners.atlas import default_atlas
    from flipkit.planning.kitchen.motions import default_planners
    from flipkit.planning.kitchen.schedule import format_timeline, schedule_cook

    from flipkit.cli.common import MAX_WORKERS, check_int
    from flipkit.fileio import check_output, check_output_dir

    warnings.filterwarnings("ignore", message="Solution may be inaccurate")
    inputs = [args.burgers]
    check_output(args.json, "--json", (".json",), inputs=inputs)
    if args.figure:
        check_output(args.figure, "--figure", FIGURE_FORMATS, inputs=inputs,
                     outputs=[args.json])
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    cell = CellConfig()
    burgers = read_cook_csv(args.burgers, cell, serve=not args.flip_only)
    kinds = ("flip",) if args.flip_only else ("flip", "serve")
    atlas = None if args.no_atlas else default_atlas(cell)
    planners = default_planners(kinds, cell, args.solver, atlas)
    timeline_path = Path(args.json)
    plans = Path(args.plans) if args.plans else timeline_path.with_name(
        timeline_path.stem + "_plans")
    check_output_dir(plans, "--plans", inputs=inputs + [args.json, args.figure])
    q_home = cell.robot.q_home
    workers = (os.cpu_count() or 1) if args.workers is None else args.workers
    executor = None
    if workers > 1:
        from flipkit.experiments.sweep import make_executor
        from flipkit.planning.kitchen.cook import check_cook, table_spots
        from flipkit.planning.kitchen.prefetch import PrefetchPlanners

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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flipkit import figures
    from flipkit.figures.draw import plot_schedule
    from flipkit.fileio import replace_with

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
