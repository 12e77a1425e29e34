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

from flipkit.cli.common import MAX_WORKERS, SOLVER_CHOICES, check_int, deferred
from flipkit.fileio import check_output

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


def run(args: argparse.Namespace) -> int:
    """Check the outputs and the options, then read, plan, write and report
    (:mod:`flipkit.cli.commands.schedule`)."""
    check_output(args.json, "--json", (".json",), inputs=[args.burgers])
    if args.figure:
        check_output(args.figure, "--figure", FIGURE_FORMATS, inputs=[args.burgers],
                     outputs=[args.json])
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    return deferred("schedule")(args)
