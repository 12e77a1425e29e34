"""``flipkit animate`` once its arguments passed :mod:`flipkit.cli.animate` (which sets
``MUJOCO_GL`` before this module imports MuJoCo): load and verify the plan, simulate, render,
write."""

from __future__ import annotations

import argparse

from flipkit.fileio import replace_with
from flipkit.planning.planners.planner import replan_flip
from flipkit.planning.plans.verify import load_verified
from flipkit.simulation.animate import write_animation, write_filmstrip
from flipkit.simulation.execute import execute_plan


def run(args: argparse.Namespace) -> int:
    """Load and verify the plan, simulate, render, write."""
    plan = load_verified(args.plan, ("flip",))
    replan = replan_flip if args.replan else None
    ex = execute_plan(plan, args.mode, replan=replan)
    out = replace_with(args.out, lambda tmp: write_animation(
        ex, tmp, args.fps, args.width, args.height, progress=not args.no_progress))
    if args.filmstrip:
        replace_with(args.filmstrip, lambda tmp: write_filmstrip(ex, tmp))
    print(f"flipkit animate: {args.mode} execution, {ex.run.t[-1]:.2f} s, wrote {out}"
          + (f" and {args.filmstrip}" if args.filmstrip else ""))
    return 0
