"""``flipkit verify`` once its arguments passed :mod:`flipkit.cli.verify`: verify the plan,
print the table and the verdict."""

from __future__ import annotations

import argparse
import sys

from flipkit.planning.plans.cell_in_use import CellMismatchError
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify import TOL, verify_plan


def run(args: argparse.Namespace) -> int:
    """Verify in the cell in use (the defaults, or ``--cell``), print the table and the
    verdict; 0 pass, 1 fail (a plan for another cell included)."""
    plan = Plan.load(args.plan)
    try:
        report = verify_plan(plan, tol=TOL if args.tol is None else args.tol,
                             cell=args.cell_in_use, where=args.plan)
    except CellMismatchError as exc:
        print(f"flipkit: error: {exc}", file=sys.stderr)
        return 1
    print(report.table())
    if args.json:
        report.write_json(args.json)
    if report.ok:
        print(f"flipkit verify: {report.summary()}")
        return 0
    print(f"flipkit verify: {report.summary()}", file=sys.stderr)
    return 1
