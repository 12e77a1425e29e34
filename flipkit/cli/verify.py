"""``flipkit verify``: independent residual check of a plan file.

Exit status: 0 the plan passes, 1 it fails (one line names the worst group and amount),
2 the file is unreadable or malformed (printed by :mod:`flipkit.cli`).
"""

from __future__ import annotations

import argparse

from flipkit.cli.common import check_float, deferred, precheck_plan
from flipkit.fileio import check_output


def register(subparsers) -> None:
    """Add the ``verify`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "verify", help="recompute dynamics, defects, limits, endpoints, continuity and cone",
        description="Check a plan from its arrays alone: dynamics residual, Hermite-Simpson "
                    "defects, time grid, joint limits, behaviour endpoints, continuity "
                    "between segments, friction cone and grill clearance. Exit 0 if the plan "
                    "passes, 1 if it fails, 2 if the file is unreadable or malformed.")
    parser.add_argument("plan", metavar="PLAN.json", help="plan file (flipkit-plan/2; /1 is read too)")
    parser.add_argument("--json", metavar="OUT", help="also write the report as JSON to OUT (.json; not the plan)")
    parser.add_argument("--tol", type=float, metavar="TOL",
                        help="tolerance in the solver's scaled units, in [1e-12, 1] (default: "
                             "flipkit.planning.plans.verify.TOL, 10x the SQP feasibility tolerance)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the options and the file cheaply, then verify (:mod:`flipkit.cli.commands.verify`);
    0 pass, 1 fail."""
    if args.json:
        check_output(args.json, "--json", (".json",), inputs=[args.plan])
    if args.tol is not None:
        check_float("--tol", args.tol, 1e-12, 1.0, "(scaled units)")
    precheck_plan(args.plan)
    return deferred("verify")(args)
