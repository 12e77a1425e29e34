"""``flipkit verify``: independent residual check of a plan file.

Exit status: 0 the plan passes, 1 it fails (one line names the worst group and amount) or
was planned for another cell than the one checked (one line names the fields that differ),
2 the file is unreadable or malformed (printed by :mod:`flipkit.cli`).
"""

from __future__ import annotations

import argparse

from flipkit.cli.common import check_float, deferred, precheck_plan
from flipkit.config import CellConfig
from flipkit.fileio import check_output
from flipkit.planning.plans.cell_in_use import read_cell_file
from flipkit.planning.plans.verify_report import TOL, TOL_RANGE


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
                        help=f"tolerance in the solver's scaled units, in [{TOL_RANGE[0]:g}, "
                             f"{TOL_RANGE[1]:g}] (default: {TOL:g}, 10x the SQP feasibility "
                             "tolerance; at most 10x looser, so that no pose centimetres off "
                             "passes)")
    parser.add_argument("--cell", metavar="CELL.json",
                        help="the cell the plan will run in: a JSON object with the plan "
                             "file's cell_geometry (and optionally arm) layout (default: "
                             "flipkit's default cell); the plan's own record of its cell must "
                             "match it")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the options, read the cell file (``args.cell_in_use``) and check the plan file
    cheaply, then verify (:mod:`flipkit.cli.commands.verify`); 0 pass, 1 fail."""
    if args.json:
        check_output(args.json, "--json", (".json",), inputs=[args.plan])
    if args.tol is not None:
        check_float("--tol", args.tol, *TOL_RANGE, "(scaled units)")
    args.cell_in_use = read_cell_file(args.cell) if args.cell is not None else CellConfig()
    precheck_plan(args.plan)
    return deferred("verify")(args)
