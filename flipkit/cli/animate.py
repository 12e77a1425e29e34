"""``flipkit animate``: render the simulated execution of a flip plan to a GIF or MP4.

Exit status: 0 written; 2 bad input (missing or malformed plan file, a plan that is not a
solved flip plan or fails ``flipkit verify``, an unknown extension, an output that is the
plan, a size or frame rate out of range, no offscreen GL) — one line on stderr, nothing
written.
"""

from __future__ import annotations

import argparse
import os

from flipkit.cli.common import check_float, check_int, deferred, precheck_plan
from flipkit.fileio import check_output

MODES = ("feedforward", "position")  # flipkit.simulation.execute.MODES (checked in tests)
FORMATS = (".gif", ".mp4")  # flipkit.simulation.animate.FORMATS (checked in tests)
FPS_RANGE = (1.0, 120.0)  # frames/s
SIZE_RANGE = (16, 4096)  # pixels, width and height


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
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second in [1, 120] (default 30)")
    parser.add_argument("--width", type=int, default=480, help="pixels in [16, 4096] (default 480)")
    parser.add_argument("--height", type=int, default=360, help="pixels in [16, 4096] (default 360)")
    parser.add_argument("--filmstrip", metavar="FILE.png",
                        help="also write the key frames (release, mid-flight, landing) as a PNG")
    parser.add_argument("--replan", action="store_true",
                        help="sense, plan, act: re-plan the flip for where the scoop left the "
                             "burger on the blade (as flipkit validate --replan)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the outputs, the options and the file cheaply, then load and verify the plan,
    simulate, render and write (:mod:`flipkit.cli.commands.animate`)."""
    check_output(args.out, "--out", FORMATS, inputs=[args.plan])
    if args.filmstrip:
        check_output(args.filmstrip, "--filmstrip", (".png",), inputs=[args.plan],
                     outputs=[args.out])
    check_float("--fps", args.fps, *FPS_RANGE, "frames/s")
    check_int("--width", args.width, *SIZE_RANGE)
    check_int("--height", args.height, *SIZE_RANGE)
    precheck_plan(args.plan)
    os.environ.setdefault("MUJOCO_GL", "osmesa")  # before anything imports mujoco
    return deferred("animate")(args)
