"""``flipkit atlas build`` and ``flipkit atlas info`` (arguments: :mod:`flipkit.cli.atlas`):
solve the grid and write the atlas, or describe one."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from flipkit.behaviors.options import SegmentOptions
from flipkit.config import CellConfig
from flipkit.experiments.atlas import DEFAULT_GRID, DEFAULT_TURNS, build_atlas
from flipkit.fileio import check_output
from flipkit.planning.planners.atlas import Atlas, default_path, options_hash


def run_build(args: argparse.Namespace) -> int:
    """Build, write, summarise."""
    grid = tuple(args.grid) if args.grid else DEFAULT_GRID  # a given one: flipkit.cli.atlas
    out = check_output(args.out or default_path(), "--out", (".npz",))
    turns = DEFAULT_TURNS if args.turns is None else args.turns  # checked: flipkit.cli.atlas
    atlas = build_atlas(grid=grid, turns=turns, scheduler=args.scheduler,
                        workers=args.workers, progress=not args.no_progress)
    out = atlas.save(out)
    m = atlas.meta
    print(f"flipkit atlas: {len(atlas)} entries solved at {grid[0] * grid[1]} locations and "
          f"{len(m['turns'])} headings each where within the limit ({len(m['failed'])} "
          f"failed), median {m['median_wall_s']:.2f} s and {m['median_iterations']:.0f} SQP "
          f"iterations per chain, built in {m['build_s']:.0f} s; wrote {out}")
    for loc, psi, why in m["failed"]:
        print(f"  failed at ({loc[0]:.3f}, {loc[1]:.3f}), heading {math.degrees(psi):.1f} deg:"
              f" {why}", file=sys.stderr)
    return 0


def run_info(args: argparse.Namespace) -> int:
    """One paragraph about an atlas, and whether it serves today's default options."""
    path = args.file or default_path()
    atlas = Atlas.load(path)
    m = atlas.meta
    current = m.get("options_hash") == options_hash(CellConfig(), SegmentOptions())
    print(f"{path}: {len(atlas)} entries, {len(np.unique(atlas.locations, axis=0))} locations "
          f"on a {m['grid'][0]} x {m['grid'][1]} grid at {len(m.get('turns', [0.0]))} "
          f"headings each (turns of the default), "
          f"{len(m['failed'])} failed; built at commit {m.get('flipkit_commit') or '?'}; "
          f"{'serves' if current else 'does NOT serve'} the default options")
    return 0
