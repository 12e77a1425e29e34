"""``flipkit animate``: render the simulated execution of a flip plan to a GIF or MP4.

Exit status: 0 written; 2 bad input (missing or malformed plan file, a plan that is not a
solved flip plan, an unknown extension, a bad size or rate, no offscreen GL) — one line on
stderr.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

MODES = ("feedforward", "position")  # flipkit.simulation.execute.MODES (checked in tests)


def register(subparsers) -> None:
    """Add the ``animate`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "animate", help="render the simulated execution of a flip plan (GIF or MP4)",
        description="Execute a solved flip plan closed-loop in the MuJoCo cell (nominal burger) "
                    "and render it offscreen in real time; optionally a filmstrip PNG of "
                    "release, mid-flight and landing.")
    parser.add_argument("plan", metavar="PLAN.json", help="a solved flip plan file")
    parser.add_argument("--out", required=True, metavar="FILE.gif|FILE.mp4",
                        help="output animation (.gif with Pillow; .mp4 needs imageio-ffmpeg)")
    parser.add_argument("--mode", choices=MODES, default="feedforward",
                        help="joint controller (default feedforward)")
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second (default 30)")
    parser.add_argument("--width", type=int, default=480, help="pixels (default 480)")
    parser.add_argument("--height", type=int, default=360, help="pixels (default 360)")
    parser.add_argument("--filmstrip", metavar="FILE.png",
                        help="also write the key frames (release, mid-flight, landing) as a PNG")
    parser.add_argument("--replan", action="store_true",
                        help="sense, plan, act: re-plan the flip for where the scoop left the "
                             "burger on the blade (as flipkit validate --replan)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the input, simulate, render, write."""
    os.environ.setdefault("MUJOCO_GL", "osmesa")  # before anything imports mujoco
    from flipkit.simulation.animate import FORMATS, write_animation, write_filmstrip
    from flipkit.errors import FlipkitError, InvalidChoiceError
    from flipkit.simulation.execute import execute_plan
    from flipkit.planning.plan_file import Plan

    ext = Path(args.out).suffix.lower()
    if ext not in FORMATS:
        raise InvalidChoiceError("animation format", ext or args.out, FORMATS)
    plan = Plan.load(args.plan)
    if plan.behavior != "flip" or plan.status != "solved":
        raise FlipkitError(f"{args.plan}: a {plan.status} {plan.behavior} plan; animate needs a "
                           f"solved flip plan")
    replan = None
    if args.replan:
        from flipkit.planning.planner import replan_flip

        replan = replan_flip
    ex = execute_plan(plan, args.mode, replan=replan)
    out = write_animation(ex, args.out, args.fps, args.width, args.height,
                          progress=not args.no_progress)
    if args.filmstrip:
        write_filmstrip(ex, args.filmstrip)
    print(f"flipkit animate: {args.mode} execution, {ex.run.t[-1]:.2f} s, wrote {out}"
          + (f" and {args.filmstrip}" if args.filmstrip else ""))
    return 0
