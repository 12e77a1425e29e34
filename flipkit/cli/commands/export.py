"""``flipkit export`` once its arguments passed :mod:`flipkit.cli.export`: load, verify,
resample and write the CSV."""

from __future__ import annotations

import argparse

from flipkit.planning.plans.export import write_csv
from flipkit.planning.plans.plan_file import Plan


def run(args: argparse.Namespace) -> int:
    """Load, verify, resample, write; one line with the row count."""
    plan = Plan.load(args.plan)
    rows = write_csv(plan, args.csv, args.rate, force=args.force, where=args.plan)
    total = sum(s.T for s in plan.segments)
    print(f"flipkit export: wrote {rows} rows ({total:.3f} s at {args.rate:g} Hz) to {args.csv}")
    return 0
