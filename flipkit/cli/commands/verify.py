"""``flipkit verify`` once its arguments passed :mod:`flipkit.cli.verify`: verify the plan,
print the table and the verdict."""

from __future__ import annotations

import argparse
import sys

from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify import TOL, verify_plan


def run(args: argparse.Namespace) -> int:
    """Verify, print the table and the verdict; 0 pass, 1 fail."""
    report = verify_plan(Plan.load(args.plan), tol=TOL if args.tol is None else args.tol)
    print(report.table())
    if args.json:
        report.write_json(args.json)
    if report.ok:
        print(f"flipkit verify: {report.summary()}")
        return 0
    print(f"flipkit verify: {report.summary()}", file=sys.stderr)
    return 1
