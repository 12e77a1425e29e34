"""``flipkit compare-ik``: joint-space collocation vs end-effector space + IK, per location.

Locations: a named set (``--locations table1``), a grid over the grill (``--grid NX NY``)
and single burgers (``--burger X Y Z``, repeatable), in that order; at least one is needed.

Exit status: 0 the comparison ran (whatever the methods' outcomes); 2 bad input (no location
given, a grid size below 1, a location off the grill, an unreachable scheduler, an unwritable
output) — one line on stderr; 1 a location whose worker died on every attempt (one line;
the finished locations stay in the cache).
"""

from __future__ import annotations

import argparse

from flipkit.cli.common import (LOCATION_SET_CHOICES, MAX_GRID, MAX_WORKERS,
                                add_sweep_arguments, check_int, deferred)
from flipkit.errors import ConfigError
from flipkit.fileio import check_output, check_output_dir
from flipkit.solvers.names import SOLVERS


def register(subparsers) -> None:
    """Add the ``compare-ik`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "compare-ik", help="collocation vs end-effector space + IK at many burger locations",
        description="At each burger location, plan pickup-and-flip with joint-space "
                    "collocation (checked by flipkit verify) and with the end-effector-space "
                    "+ IK baseline; write per-location status, failure reason and wall "
                    "times, and a summary (success fractions, IK failure reasons, median "
                    "time per subbehaviour).")
    parser.add_argument("--locations", choices=LOCATION_SET_CHOICES,
                        help="a named location set: table1 = the paper's ten Table I points, "
                             "more = five others over the grill")
    parser.add_argument("--grid", nargs=2, type=int, metavar=("NX", "NY"),
                        help="an NX x NY grid of cell centres over the grill area, each in [1, 50]")
    parser.add_argument("--burger", nargs=3, type=float, action="append", metavar=("X", "Y", "Z"),
                        help="one more burger location (m); may be repeated")
    parser.add_argument("--solver", choices=SOLVERS, default="sqp",
                        help="collocation NLP solver (default sqp)")
    parser.add_argument("--plans", metavar="DIR", help="also write the collocation plans here")
    add_sweep_arguments(parser)
    parser.add_argument("--json", required=True, metavar="OUT.json", help="output file")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the locations, the options and the outputs, then run the comparison
    (:mod:`flipkit.cli.commands.compare_ik`)."""
    if args.locations is None and args.grid is None and not args.burger:
        raise ConfigError("give --locations table1, --grid NX NY and/or --burger X Y Z")
    for n in args.grid or ():
        check_int("--grid", n, 1, MAX_GRID)
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    check_output(args.json, "--json", (".json",))
    for flag, directory in (("--plans", args.plans), ("--cache", args.cache)):
        if directory is not None:
            check_output_dir(directory, flag)
    return deferred("compare_ik")(args)
