"""``flipkit export``: verify a plan, resample it at a controller rate and write it as CSV.

Exit status: 0 written; 1 the plan fails verification (one line names the failed check; no
file is written); 2 bad input (unreadable or malformed plan, bad rate, unwritable output).
"""

from __future__ import annotations

import argparse
import sys


def register(subparsers) -> None:
    """Add the ``export`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "export", help="resample a plan at a controller rate and write t, q, qd as CSV",
        description="Verify the plan (as flipkit verify; exit 1 and write nothing if it "
                    "fails), then resample the concatenated segments of a plan at the controller rate "
                    "(cubic Hermite interpolation between nodes, as the collocation) and "
                    "write the columns t,q1..q6,qd1..qd6 (s, rad, rad/s).")
    parser.add_argument("plan", metavar="PLAN.json", help="plan file (flipkit-plan/2; /1 is read too)")
    parser.add_argument("--rate", type=float, required=True, metavar="HZ",
                        help="controller rate (Hz), e.g. 125 or 500")
    parser.add_argument("--csv", required=True, metavar="OUT.csv", help="output CSV file")
    parser.add_argument("--force", action="store_true",
                        help="export even a plan whose status is not 'solved' (it must still "
                             "pass verification)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Load, resample, write; print one line with the row count."""
    from flipkit.errors import VerificationError
    from flipkit.planning.export import write_csv
    from flipkit.planning.plan_file import Plan

    plan = Plan.load(args.plan)
    try:
        rows = write_csv(plan, args.csv, args.rate, force=args.force)
    except VerificationError as exc:
        print(f"flipkit export: {exc}; nothing written", file=sys.stderr)
        return 1
    total = sum(s.T for s in plan.segments)
    print(f"flipkit export: wrote {rows} rows ({total:.3f} s at {args.rate:g} Hz) to {args.csv}")
    return 0
