"""``flipkit export``: verify a plan, resample it at a controller rate and write it as CSV.

Exit status: 0 written; 2 refused, nothing written — one line on stderr: an unreadable or
malformed plan, a plan that fails verification (the line names the failed check), a rate
outside [1, 10000] Hz or one that gives fewer than two rows, an output that is not a
writable ``.csv`` file or is the plan itself.
"""

from __future__ import annotations

import argparse

from flipkit.cli.common import check_float, deferred, precheck_plan
from flipkit.fileio import check_output

RATE_RANGE = (1.0, 10_000.0)  # Hz, --rate (flipkit.planning.plans.export.RATE_RANGE)


def register(subparsers) -> None:
    """Add the ``export`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "export", help="resample a plan at a controller rate and write t, q, qd as CSV",
        description="Verify the plan (as flipkit verify; exit 2 and write nothing if it "
                    "fails), then resample the concatenated segments of a plan at the controller rate "
                    "(cubic Hermite interpolation between nodes, as the collocation) and "
                    "write the columns t,q1..q6,qd1..qd6 (s, rad, rad/s).")
    parser.add_argument("plan", metavar="PLAN.json", help="plan file (flipkit-plan/2; /1 is read too)")
    parser.add_argument("--rate", type=float, required=True, metavar="HZ",
                        help="controller rate (Hz) in [1, 10000], e.g. 125 or 500; at least two "
                             "rows over the plan's duration")
    parser.add_argument("--csv", required=True, metavar="OUT.csv",
                        help="output CSV file (.csv; not the plan)")
    parser.add_argument("--force", action="store_true",
                        help="export even a plan whose status is not 'solved' (it must still "
                             "pass verification)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the output, the rate and the file cheaply, then load, verify, resample and write
    (:mod:`flipkit.cli.commands.export`)."""
    check_output(args.csv, "--csv", (".csv",), inputs=[args.plan])
    check_float("--rate", args.rate, RATE_RANGE[0], RATE_RANGE[1], "Hz")
    precheck_plan(args.plan)
    return deferred("export")(args)
