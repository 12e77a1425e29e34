"""``flipkit atlas``: build or describe the warm-start atlas of ``plan flip``.

    flipkit atlas build [--grid NX NY] [--turns DEG ...] [--scheduler ADDRESS] [--workers K]
                        [--out FILE]
    flipkit atlas info [FILE]

``build`` solves pickup-and-flip cold on an NX × NY grid over the grill at each location's
default scoop heading, then at that heading turned by each of the turns, seeded from the
first (local worker processes, or a Dask cluster with ``--scheduler``), and writes one
compressed file (default: the package's own, ``flipkit/data/atlas.npz``, which ``plan flip``
uses). NX and NY lie in [1, 50], the turns in [-60, 60] degrees, the output ends in ``.npz``
and its directory is writable (checked before solving). Exit 0 written; 2 bad input or no
location solved.
"""

from __future__ import annotations

import argparse
import math

from flipkit.cli.common import MAX_GRID, MAX_WORKERS, check_int, deferred
from flipkit.cli.plan_inputs import numbers
from flipkit.errors import ConfigError
from flipkit.fileio import check_output
from flipkit.planning.planners.inputs import check_atlas_file


def register(subparsers) -> None:
    """Add the ``atlas`` sub-command to the parser."""
    p = subparsers.add_parser("atlas", help="build or describe the warm-start atlas",
                              description=__doc__.split("\n\n")[2].replace("\n", " "))
    sub = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    b = sub.add_parser("build", help="solve the grid and write the atlas")
    b.add_argument("--grid", nargs=2, type=int, metavar=("NX", "NY"), default=None,
                   help="grid over the grill area, each in [1, 50] (default 5 7)")
    b.add_argument("--turns", nargs="*", default=None, metavar="DEG",
                   help="turns of each location's default scoop heading to solve at too, "
                        "degrees in [-60, 60] (default -30 -15 15 30, the turns a cook tries; "
                        "none: the default headings alone)")
    b.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler (default: local "
                                                          "worker processes)")
    b.add_argument("--workers", type=int, metavar="K", help="local worker processes, in "
                                                            "[1, 256] (default: the CPU count)")
    b.add_argument("--out", metavar="FILE.npz",
                   help="output, .npz (default: the package's atlas)")
    b.add_argument("--no-progress", action="store_true", help="no progress bar")
    b.set_defaults(run=run_build)
    i = sub.add_parser("info", help="describe an atlas")
    i.add_argument("file", nargs="?", metavar="FILE", help="atlas (default: the package's)")
    i.set_defaults(run=run_info)


def run_build(args: argparse.Namespace) -> int:
    """Check the grid, the workers and a given output, then build
    (:mod:`flipkit.cli.commands.atlas`)."""
    for n in args.grid or ():
        check_int("--grid", n, 1, MAX_GRID)
    if args.turns is not None:
        turns = numbers("--turns", args.turns, len(args.turns)) if args.turns else []
        if any(abs(t) > 60.0 for t in turns):
            raise ConfigError(f"--turns: each turn must lie in [-60, 60] degrees, got "
                              f"{', '.join(f'{t:g}' for t in turns)}")
        args.turns = [math.radians(t) for t in turns]
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    if args.out is not None:  # the package's own atlas is checked where it is known
        check_output(args.out, "--out", (".npz",))
    return deferred("atlas", "run_build")(args)


def run_info(args: argparse.Namespace) -> int:
    """Check a given file is a readable ``.npz`` archive, then describe it."""
    if args.file is not None:
        check_atlas_file(args.file)
    return deferred("atlas", "run_info")(args)
