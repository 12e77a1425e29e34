"""``flipkit export``: resample a plan at a controller rate and write it as CSV."""

from __future__ import annotations

import argparse


def register(subparsers) -> None:
    """Add the ``export`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "export", help="resample a plan at a controller rate and write t, q, qd as CSV",
        description="Resample the concatenated segments of a plan at the controller rate "
                    "(cubic Hermite interpolation between nodes, as the collocation) and "
                    "write the columns t,q1..q6,qd1..qd6 (s, rad, rad/s).")
    parser.add_argument("plan", metavar="PLAN.json", help="plan file (flipkit-plan/1)")
    parser.add_argument("--rate", type=float, required=True, metavar="HZ",
                        help="controller rate (Hz), e.g. 125 or 500")
    parser.add_argument("--csv", required=True, metavar="OUT.csv", help="output CSV file")
    parser.add_argument("--force", action="store_true",
                        help="export even a plan whose status is not 'solved'")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Load, resample, write; print one line with the row count."""
    from flipkit.planning.export import write_csv
    from flipkit.planning.plan_file import Plan

    plan = Plan.load(args.plan)
    rows = write_csv(plan, args.csv, args.rate, force=args.force)
    total = sum(s.T for s in plan.segments)
    print(f"flipkit export: wrote {rows} rows ({total:.3f} s at {args.rate:g} Hz) to {args.csv}")
    return 0
