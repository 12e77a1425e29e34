"""``flipkit atlas``: build or describe the warm-start atlas of ``plan flip``.

    flipkit atlas build [--grid NX NY] [--scheduler ADDRESS] [--workers K] [--out FILE]
    flipkit atlas info [FILE]

``build`` solves pickup-and-flip cold on an NX × NY grid over the grill (local worker
processes, or a Dask cluster with ``--scheduler``) and writes one compressed file (default:
the package's own, ``flipkit/data/atlas.npz``, which ``plan flip`` uses). NX and NY lie in
[1, 50], the output ends in ``.npz`` and its directory is writable (checked before solving).
Exit 0 written; 2 bad input or no location solved.
"""

from __future__ import annotations

import argparse
import sys


def register(subparsers) -> None:
    """Add the ``atlas`` sub-command to the parser."""
    p = subparsers.add_parser("atlas", help="build or describe the warm-start atlas",
                              description=__doc__.split("\n\n")[2].replace("\n", " "))
    sub = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    b = sub.add_parser("build", help="solve the grid and write the atlas")
    b.add_argument("--grid", nargs=2, type=int, metavar=("NX", "NY"), default=None,
                   help="grid over the grill area, each in [1, 50] (default 5 7)")
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
    """Build, write, summarise."""
    from flipkit.cli.common import MAX_GRID, MAX_WORKERS, check_int
    from flipkit.experiments.atlas import DEFAULT_GRID, build_atlas
    from flipkit.fileio import check_output
    from flipkit.planning.planners.atlas import default_path

    grid = tuple(args.grid) if args.grid else DEFAULT_GRID
    for n in grid:
        check_int("--grid", n, 1, MAX_GRID)
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    out = check_output(args.out or default_path(), "--out", (".npz",))
    atlas = build_atlas(grid=grid, scheduler=args.scheduler, workers=args.workers,
                        progress=not args.no_progress)
    out = atlas.save(out)
    m = atlas.meta
    print(f"flipkit atlas: {len(atlas)}/{grid[0] * grid[1]} locations solved "
          f"({len(m['failed'])} failed), cold median {m['median_wall_s']:.2f} s and "
          f"{m['median_iterations']:.0f} SQP iterations per chain, built in {m['build_s']:.0f} s;"
          f" wrote {out}")
    for loc, why in m["failed"]:
        print(f"  failed at ({loc[0]:.3f}, {loc[1]:.3f}): {why}", file=sys.stderr)
    return 0


def run_info(args: argparse.Namespace) -> int:
    """One paragraph about an atlas, and whether it serves today's default options."""
    from flipkit.behaviors.options import SegmentOptions
    from flipkit.config import CellConfig
    from flipkit.planning.planners.atlas import Atlas, default_path, options_hash

    path = args.file or default_path()
    atlas = Atlas.load(path)
    m = atlas.meta
    current = m.get("options_hash") == options_hash(CellConfig(), SegmentOptions())
    print(f"{path}: {len(atlas)} locations on a {m['grid'][0]} x {m['grid'][1]} grid, "
          f"{len(m['failed'])} failed; built at commit {m.get('flipkit_commit') or '?'}; "
          f"{'serves' if current else 'does NOT serve'} the default options")
    return 0
