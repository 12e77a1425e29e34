"""``flipkit figures``: execute the figure notebooks and write the figures and the manifest."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.figures import FIGURE_IDS, run_notebooks
from flipkit.fileio import check_output_dir


def register(subparsers) -> None:
    """Add the ``figures`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "figures", help="run the notebooks and write figures/*.pdf, *.png and manifest.json",
        description="Execute the figure notebooks with papermill (executed copies in "
                    "build/notebooks/) and write each figure as PDF and PNG with "
                    "manifest.json. A notebook runs only if the hash of its inputs (its "
                    "cells, the flipkit modules it imports, the package data, the "
                    "parameters, environment.lock) differs from the one recorded with its "
                    "figures, or a figure is missing; each notebook skipped is printed with "
                    "the reason. Figures whose notebook does not exist yet are reported "
                    "as missing.")
    parser.add_argument("--quick", action="store_true",
                        help="smaller runs (fewer trials and locations) for a fast check")
    parser.add_argument("--only", nargs="+", action="extend", metavar="ID",
                        help=f"make only these figures; ids: {', '.join(FIGURE_IDS)}")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="Dask scheduler address for sweeps (default: local processes)")
    parser.add_argument("--out", default="figures", metavar="DIR",
                        help="output directory (default: figures)")
    parser.add_argument("--force", action="store_true",
                        help="run every selected notebook, even if its figures are up to date")
    parser.add_argument("--notebooks", default="notebooks", metavar="DIR",
                        help="the repository's notebooks directory; they run in its parent, "
                             "whose environment.lock is hashed with them (default: notebooks)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Make the figures; print each notebook run or skipped and why (one line each), then a
    summary: what was made, how many were skipped, what is missing, the manifest path."""
    check_output_dir(args.out, "--out")  # before any notebook runs
    if not Path(args.notebooks).is_dir():
        raise ConfigError(f"--notebooks: no directory {args.notebooks!r} (run from the "
                          "repository's root, or name its notebooks directory)")
    for fig_id in args.only or ():
        if fig_id not in FIGURE_IDS:
            raise InvalidChoiceError("figure id", fig_id, FIGURE_IDS)
    report = run_notebooks(quick=args.quick, only=args.only, scheduler=args.scheduler,
                           out_dir=args.out, force=args.force, notebooks_dir=args.notebooks,
                           log=lambda line: print(f"flipkit figures: {line}", flush=True))
    made, ran = ", ".join(report.made) or "none", len(report.ran)
    print(f"flipkit figures: ran {ran} notebook{'s' * (ran != 1)}, skipped "
          f"{len(report.skipped)} up to date; made {made} in {report.wall_time_s:.1f} s; "
          f"manifest {report.manifest}")
    if report.missing:
        print(f"flipkit figures: no notebook yet for {', '.join(report.missing)} (skipped)",
              file=sys.stderr)
    return 0
