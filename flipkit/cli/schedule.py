"""``flipkit schedule``: order, time and plan one arm's flips and serves for a cook order, or
measure a stream of drops (``--stream RATE --minutes M``).

Exit status: 0 every motion planned, solved and verified, every event within its window;
1 a motion's plan failed — one line per failure on stderr; the timeline and the plan files
(the failed one with ``"status": "failed"``) are still written — or no schedule keeps every
event in its window — one line naming the worst burger, its event and by how much; for a
cook nothing is written and nothing runs, for a modelled stream its report is still
written; 2 bad input (unreadable or malformed CSV, wrong
header, a non-finite number, a drop time outside [0, 86400] s, a burger off the grill,
duplicate ids, two burgers closer than one diameter on the grill at once, more burgers to
a malformed ``--window``, ``--dwell``, ``--time-limit``, ``--stream`` or ``--minutes``, a
stream whose grill fills up), an output that is not writable, of an unknown format or the
cook order itself, or a motion kind without a planner (``flipkit.planning.planners.planner.plan_serve``
missing) — one line on stderr, nothing planned, nothing written.

With ``--simulate`` a cook that was planned, solved and kept its windows is then run in
MuJoCo, every motion on one cell holding every burger (:mod:`flipkit.simulation.cook`), and
``--film`` renders it: one line per burger and a summary; exit 0 when every burger was
flipped and served, 1 otherwise (one line naming the first burger that was not and why). A
refused or failed schedule is never simulated (exit 1 as above).
"""

from __future__ import annotations

import argparse
import importlib.util
import os

from pathlib import Path

from flipkit.cli.common import MAX_WORKERS, check_float, check_int, deferred
from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.fileio import check_output, check_output_dir
from flipkit.planning.kitchen.cook import read_cook_csv
from flipkit.planning.kitchen.random_cook import random_order
from flipkit.planning.kitchen.stream import check_stream
from flipkit.planning.kitchen.table import DWELL_S, check_dwell
from flipkit.planning.kitchen.windows import parse_windows
from flipkit.solvers.names import SOLVERS

FIGURE_FORMATS = (".pdf", ".png", ".svg")  # --figure, by suffix
FILM_FORMATS = (".gif", ".mp4")  # --film, by suffix
SIM_MODES = ("position", "feedforward")  # flipkit.simulation.modes.MODES, position first
POLICIES = ("cpsat", "greedy")
MAX_TIME_LIMIT_S = 3600.0
DESCRIPTION = (
    "Flip every burger of a cook order at its 90 s mark and serve it to a table spot 60 s "
    "after it landed, with one arm, each event within its window. Every motion is planned "
    "from rest at home; --policy cpsat (default) then orders and times them with OR-Tools "
    "CP-SAT for the least largest, then least total, deviation from the marks; --policy "
    "greedy takes them earliest deadline first. Writes the timeline (JSON), one plan file "
    "per motion, and optionally a Gantt chart. With --stream RATE --minutes M, a stream of "
    "drops at random places is scheduled on the durations of a few representative plans "
    "(--plan: every motion planned) and its throughput reported. Exit 0: all solved, every "
    "event in its window. Exit 1: a plan failed (everything still written) or the windows "
    "cannot be met (one line; for a cook nothing written). Exit 2: bad input or a missing "
    "planner; nothing written.")


def register(subparsers) -> None:
    """Add the ``schedule`` sub-command to the parser."""
    p = subparsers.add_parser("schedule", help="schedule and plan the flips and serves of a "
                                                "cook (one arm)", description=DESCRIPTION)
    p.add_argument("burgers", metavar="BURGERS.csv", nargs="?",
                   help="cook order: header burger,t_drop,x,y (in any order, no other "
                        "column: id, drop time s in [0, 86400], grill position m); lines "
                        "starting with # skipped; omitted with --stream or --random")
    p.add_argument("--json", required=True, metavar="TIMELINE.json",
                   help="timeline output (.json; not the cook order)")
    p.add_argument("--figure", metavar="PATH", help="Gantt chart (.pdf, .png or .svg)")
    p.add_argument("--plans", metavar="DIR",
                   help="directory for the motions' plan files (default: TIMELINE_plans/ "
                        "beside the timeline); the timeline names them relative to its own "
                        "directory")
    p.add_argument("--flip-only", action="store_true",
                   help="plan the flips alone (no serves; serve_time stays null)")
    p.add_argument("--solver", choices=SOLVERS, default="auto",
                   help="NLP solver (default auto: the SQP, then IPOPT where it fails)")
    p.add_argument("--workers", type=int, default=None, metavar="K",
                   help="plan the motions ahead in K worker processes, in [1, 256] "
                        "(default: the CPU count; 1: one after another in this process)")
    p.add_argument("--no-atlas", action="store_true",
                   help="flips from cold starts (default: warm-started from the package's "
                        "atlas, `flipkit atlas build`, when it serves the default options)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--policy", choices=POLICIES, default="cpsat",
                   help="cpsat (default): CP-SAT over orders and start times; greedy: "
                        "earliest deadline first, no motion before its mark (the baseline)")
    p.add_argument("--window", action="append", metavar="EVENT=EARLY,LATE",
                   help="an event's window, s before and after its mark, each in [0, 30]: "
                        "flip=EARLY,LATE (mark: drop + 90 s) or serve=EARLY,LATE (mark: "
                        "landing + 60 s); repeat for both; default flip=0,2 and serve=0,2")
    p.add_argument("--dwell", type=float, default=DWELL_S, metavar="S",
                   help=f"s a served plate stays on the table before its spot is free "
                        f"again, in [0, 3600] (default {DWELL_S:g})")
    p.add_argument("--time-limit", type=float, default=10.0, metavar="S",
                   help="CP-SAT's limit in its deterministic time (about seconds on one "
                        "worker), in (0, 3600] (default 10); one search worker and a fixed "
                        "seed: the same schedule on every run")
    p.add_argument("--stream", type=float, metavar="RATE",
                   help="instead of BURGERS.csv, a stream of drops: RATE burgers per hour, "
                        "evenly spaced from t = 0, each at a random free place on the grill")
    p.add_argument("--random", type=int, metavar="N",
                   help="instead of BURGERS.csv, N burgers (1 to 12) dropped 4-5 s apart at "
                        "random places on the grill, at least a diameter apart (--seed)")
    p.add_argument("--gap", type=float, default=None, metavar="M",
                   help="with --random: the least distance between two burgers' edges, m, in "
                        "[0.001, 0.2] (default 0.001: they may all but touch)")
    p.add_argument("--minutes", type=float, metavar="M",
                   help="the stream's length, min (with --stream)")
    p.add_argument("--seed", type=int, default=0, metavar="N",
                   help="seed of the stream's or --random's places and of CP-SAT, in "
                        "[0, 2**31-1] (default 0)")
    p.add_argument("--plan", action="store_true",
                   help="with --stream: plan every motion (minutes for hundreds) instead of "
                        "scheduling on the durations of six representative plans")
    p.add_argument("--simulate", action="store_true",
                   help="run the planned cook in MuJoCo: every motion in order on one cell "
                        "with all the burgers; judge each burger's flip and serve (exit 1 "
                        "unless all are flipped and served)")
    p.add_argument("--mode", choices=SIM_MODES, default="position",
                   help="with --simulate: the joint controller, position (default: the "
                        "robot's servo on the plans' own commands) or feedforward")
    p.add_argument("--sense", action="store_true",
                   help="with --simulate: sense-plan-act serves: each serve is re-planned for "
                        "where a camera (error 5 mm per axis, seeded by --seed) sees its "
                        "burger on the grill, and the re-plan runs if verified and no longer "
                        "than the scheduled serve; 0.5 s before the carry ends, place and "
                        "return home are re-planned, while the carry runs on, for where it "
                        "sees the burger on the blade, if the serve still ends before the "
                        "next motion")
    p.add_argument("--film", metavar="FILE",
                   help="with --simulate: a film of the motions (.gif, or .mp4 with "
                        "imageio-ffmpeg), 320x240 at 15 fps, idle intervals cut")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the options and the outputs, read the cook order (``args.order``), then plan,
    write and report (:mod:`flipkit.cli.commands.schedule`). Everything here runs before the
    planners, MuJoCo and matplotlib are imported, so a refusal takes a fraction of a second."""
    given = [what for what, value in (("BURGERS.csv", args.burgers), ("--stream", args.stream),
                                      ("--random", args.random)) if value is not None]
    if len(given) != 1:
        raise ConfigError("give one of a cook order BURGERS.csv, --stream RATE or --random N"
                          + (f", not {' and '.join(given)}" if given else ""))
    if args.stream is not None:
        if args.minutes is None:
            raise ConfigError("--stream RATE needs --minutes M")
        check_stream(args.stream, args.minutes)
        if args.flip_only and not args.plan:
            raise ConfigError("--flip-only with --stream needs --plan (a modelled stream "
                              "flips and serves)")
        if args.figure and not args.plan:
            raise ConfigError("--figure draws a planned cook: add --plan (the throughput of "
                              "streams: notebooks/throughput.ipynb)")
    elif args.minutes is not None or args.plan:
        raise ConfigError("--minutes and --plan go with --stream")
    if args.simulate and args.stream is not None:
        raise ConfigError("--simulate runs a cook order (BURGERS.csv or --random), not a stream")
    if (args.film or args.sense or args.mode != "position") and not args.simulate:
        raise ConfigError("--film, --mode and --sense go with --simulate")
    inputs = [args.burgers] if args.burgers else []
    check_output(args.json, "--json", (".json",), inputs=inputs)
    if args.film:
        check_output(args.film, "--film", FILM_FORMATS, inputs=inputs,
                     outputs=[args.json] + ([args.figure] if args.figure else []))
        if args.film.lower().endswith(".mp4") and importlib.util.find_spec(
                "imageio_ffmpeg") is None:
            raise ConfigError("--film .mp4 needs imageio-ffmpeg, which is not installed; "
                              "write a .gif instead")
    if args.simulate:
        os.environ.setdefault("MUJOCO_GL", "osmesa")  # before anything imports mujoco
    if args.figure:
        check_output(args.figure, "--figure", FIGURE_FORMATS, inputs=inputs,
                     outputs=[args.json])
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    args.windows = parse_windows(args.window)
    check_dwell(args.dwell, "--dwell")
    if args.time_limit is None or not args.time_limit > 0:
        raise ConfigError(f"--time-limit must be a number in (0, {MAX_TIME_LIMIT_S:g}] s, "
                          f"got {args.time_limit!r}")
    check_float("--time-limit", args.time_limit, 0.0, MAX_TIME_LIMIT_S, "s")
    check_int("--seed", args.seed, 0, 2**31 - 1)
    args.order = read_cook_csv(args.burgers, CellConfig()) if args.burgers else None
    if args.gap is not None and args.random is None:
        raise ConfigError("--gap goes with --random")
    if args.random is not None:
        args.order = random_order(args.random, args.seed, CellConfig(),
                                  **({} if args.gap is None else {"gap": args.gap}))
    if args.plans is None:  # TIMELINE_plans/ beside the timeline
        args.plans = str(Path(args.json).with_name(Path(args.json).stem + "_plans"))
    if args.order is not None or args.plan:
        check_output_dir(args.plans, "--plans", inputs=inputs + [args.json, args.figure,
                                                                  args.film])
    return deferred("schedule")(args)
