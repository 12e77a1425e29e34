"""``flipkit compare-ik`` once its arguments passed :mod:`flipkit.cli.compare_ik`: run both
methods at every location on the executor (cached in ``--cache`` or the run cache,
:mod:`flipkit.cli.run_cache`), write the JSON, print the summary."""

from __future__ import annotations

import argparse

from flipkit.cli.common import write_json
from flipkit.cli.run_cache import sweep_cache
from flipkit.config import LOCATION_SETS
from flipkit.experiments.compare_ik import check_locations, compare_ik, format_summary
from flipkit.experiments.sweep import grill_grid, make_executor


def run(args: argparse.Namespace) -> int:
    """Run the comparison on the executor, write the JSON, print the summary."""
    locations = list(LOCATION_SETS[args.locations]) if args.locations else []
    if args.grid is not None:
        locations += grill_grid(nx=args.grid[0], ny=args.grid[1])
    locations += [tuple(b) for b in args.burger or ()]
    check_locations(locations)  # refused before the run cache is named
    with make_executor(args.scheduler, args.workers) as executor, \
            sweep_cache(args.cache, args.json, "compare-ik") as cache:
        out = compare_ik(locations, args.solver, executor, cache, args.plans,
                         progress=not args.no_progress)
        write_json(args.json, out)
    print(format_summary(out["summary"]))
    print(f"flipkit compare-ik: wrote {len(out['locations'])} locations to {args.json}")
    return 0
