"""``flipkit validate``: simulated trials of pickup-and-flip plans (the paper's Table I).

Exit status: 0 the trials ran (whatever their outcomes); 2 bad input (missing or malformed
plan file, a plan that is not a solved flip or serve plan or fails ``flipkit verify``,
``--contingencies`` without ``--replan`` or with a serve plan, trials outside [1, 10000], a
negative seed, a rate outside [10, 100000] Hz, a location off the grill, an unreachable
scheduler, an output that is not a writable ``.json`` file or is the plan) — one line on
stderr, checked before any trial runs, nothing written; 1 a sweep item whose worker died on
every attempt (one line; the finished items stay in the cache).
"""

from __future__ import annotations

import argparse
import math

from flipkit.cli.plan_inputs import heading, numbers
from flipkit.config.task import HEADING_LIMIT
from flipkit.cli.common import (LOCATION_SET_CHOICES, MAX_WORKERS, add_sweep_arguments,
                                check_float, check_int, deferred, precheck_plan)
from flipkit.config.checks import whole
from flipkit.config.physics import servo_lookahead
from flipkit.errors import ConfigError
from flipkit.experiments.perturbations import MAX_TRIALS
from flipkit.fileio import check_output, check_output_dir
from flipkit.solvers.names import SOLVERS

RATE_RANGE = (10.0, 100_000.0)  # Hz, --rate of the PD controller


def register(subparsers) -> None:
    """Add the ``validate`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "validate", help="simulate a plan's execution K times under perturbations",
        description="Execute the plan closed-loop in the MuJoCo cell (arm, spatula blade "
                    "colliding with the grill, burger) with a perturbed burger (placement "
                    "sigma 5 mm, grill height +-2 mm, friction x U(0.8, 1.2), mass x "
                    "U(0.9, 1.1)) under the chosen joint controller, and judge scoop, pickup "
                    "and flip with the paper's criteria.")
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--plan", metavar="PLAN.json",
                      help="a solved flip or serve plan file (serve: judged on the table)")
    what.add_argument("--locations", choices=LOCATION_SET_CHOICES,
                      help="plan every location of a named set (table1: the paper's ten; "
                           "more: five others over the grill), then simulate")
    parser.add_argument("--trials", type=int, required=True, metavar="K",
                        help=f"simulated trials per location, in [1, {MAX_TRIALS}]")
    parser.add_argument("--seed", type=int, default=0, metavar="S",
                        help="non-negative (default 0); trial i at each location draws from "
                             "a stream of its own, numpy SeedSequence([S, i, location])")
    parser.add_argument("--solver", choices=SOLVERS, default="auto",
                        help="collocation solver for --locations (default auto: the SQP, then IPOPT where it fails)")
    parser.add_argument("--plans", metavar="DIR", help="with --locations: keep the plans here")
    parser.add_argument("--no-atlas", action="store_true",
                        help="with --locations: plan from cold starts, not from the package's "
                             "atlas; the two reach different local optima of the same NLPs, "
                             "and comparing them shows how much a result owes to the one "
                             "found")
    turn = parser.add_mutually_exclusive_group()
    turn.add_argument("--heading", default=None, metavar="DEG",
                      help="with --locations: plan every location with this scoop heading "
                           "(degrees from the world's +x, within +-60; default: each "
                           "location's own, radial from the base; docs/heading.md)")
    turn.add_argument("--turn", default=None, metavar="DEG",
                      help="with --locations: plan every location with its own scoop heading "
                           "turned by DEG degrees, as a cook turns a scoop, stopping at +-60 "
                           "deg of +x")
    parser.add_argument("--rate", type=float, default=1000.0, metavar="HZ",
                        help="PD controller rate (Hz) in [10, 100000] (default 1000)")
    parser.add_argument("--mode", choices=("feedforward", "position"), default="feedforward",
                        help="joint controller: plan torques + PD (feedforward, default) or "
                             "the robot's PD position control on servo-rate, delayed commands "
                             "with its own gravity compensation (position)")
    parser.add_argument("--command", choices=("raw", "compensated"), default="raw",
                        help="position mode's commands, the stream flipkit export writes: the "
                             "plan's (q, qd) as they are (raw, default; the paper's) or "
                             "pre-compensated for a modelled servo (compensated; "
                             "docs/robust-flips.md)")
    parser.add_argument("--servo-lookahead", type=float, default=None, metavar="S",
                        help="with --mode position: the servo smooths its commands as UR's "
                             "servoj does with this lookahead_time, in [0.03, 0.2] s, and the "
                             "commands are made for it (default 0.1, servoj's default); 0: a "
                             "servo without smoothing (docs/robust-flips.md section 3)")
    parser.add_argument("--servo-form", choices=("pd_gravity", "model_based"), default=None,
                        help="with --mode position: how the simulated servo follows its "
                             "smoothed commands: PD plus gravity (pd_gravity, the default) or "
                             "its model's inverse dynamics (model_based); UR publishes neither "
                             "(docs/arm-profile.md)")
    parser.add_argument("--replan", action="store_true",
                        help="sense, plan, act: after the scoop, measure where the burger lies "
                             "on the blade and re-plan pickup, flip and turn back for it "
                             "(serve: 0.5 s before the carry ends, re-plan place and return "
                             "home while it finishes)")
    parser.add_argument("--contingencies", action="store_true",
                        help="with --replan, flips only: prepare each plan's contingency flips "
                             "once and let the re-plans hand them out (docs/robust-flips.md "
                             "section 4); the arm also waits for what the preparation took "
                             "beyond the scoop's end")
    add_sweep_arguments(parser)
    parser.add_argument("--json", required=True, metavar="OUT.json",
                        help="output file (.json; not the plan)")
    parser.set_defaults(run=run)


def format_table(out: dict) -> str:
    """Success counts and tracking errors per location as an aligned text table."""
    last = list(out["locations"][0]["success"])[-1] if out["locations"] else "flip"
    lines = [f"{'location (m)':<24}{'scoop':>7}{'pickup':>8}{last:>6}   "
             f"{'max err mm':>10}{'rms mm':>8}"]
    for e in out["locations"]:
        s, k = e["success"], e["trials"]
        errs = e["tracking"].values()
        mx = max((t["max_m"] for t in errs), default=float("nan")) * 1e3
        rms = max((t["rms_m"] for t in errs), default=float("nan")) * 1e3
        where = "(" + ", ".join(f"{v:.3f}" for v in e["location"]) + ")"
        lines.append(f"{where:<24}{s['scoop']:>4}/{k:<2}{s['pickup']:>5}/{k:<2}{s[last]:>3}/"
                     f"{k:<2}   {mx:>10.2f}{rms:>8.2f}")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Check the options, the outputs and the plan file cheaply, then verify the plan and run
    the trials (:mod:`flipkit.cli.commands.validate`)."""
    check_int("--trials", args.trials, 1, MAX_TRIALS)
    whole("seed", args.seed)
    if args.contingencies and not args.replan:
        raise ConfigError("--contingencies needs --replan: they are re-plans made ahead")
    check_float("--rate", args.rate, *RATE_RANGE, "Hz")
    if args.servo_lookahead is not None:
        servo_lookahead(args.servo_lookahead, "--servo-lookahead")
        if args.mode != "position":
            raise ConfigError("--servo-lookahead needs --mode position: it smooths position "
                              "commands")
    if args.workers is not None:
        check_int("--workers", args.workers, 1, MAX_WORKERS)
    inputs = [args.plan]
    check_output(args.json, "--json", (".json",), inputs=inputs)
    for flag, directory in (("--plans", args.plans), ("--cache", args.cache)):
        if directory is not None:
            check_output_dir(directory, flag, inputs=inputs)
    if args.plan is not None:
        precheck_plan(args.plan)
        for flag, given in (("--no-atlas", args.no_atlas), ("--heading", args.heading),
                            ("--turn", args.turn)):
            if given is not None and given is not False:
                raise ConfigError(f"{flag} needs --locations: a plan file is already planned")
    args.heading = heading(args.heading)
    if args.turn is not None:
        args.turn = math.radians(numbers("--turn", args.turn)[0])
        if abs(args.turn) > 2 * HEADING_LIMIT:
            raise ConfigError(f"--turn: {math.degrees(args.turn):g} deg turns every default "
                              "heading past +-60 deg of +x")
    return deferred("validate")(args)
