"""``flipkit validate``: simulated trials of pickup-and-flip plans (the paper's Table I).

Exit status: 0 the trials ran (whatever their outcomes); 2 bad input (missing or malformed
plan file, a plan that is not a solved flip plan, trials ≤ 0, a location off the grill, an
unreachable scheduler, an unwritable output) — one line on stderr.
"""

from __future__ import annotations

import argparse
import math

from flipkit.cli.common import SOLVER_CHOICES, add_sweep_arguments, write_json


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
    what.add_argument("--locations", choices=("table1",),
                      help="plan every location of a named set (table1: the paper's ten), "
                           "then simulate")
    parser.add_argument("--trials", type=int, required=True, metavar="K",
                        help="simulated trials per location (>= 1)")
    parser.add_argument("--seed", type=int, default=0, metavar="S",
                        help="trial i draws from numpy default_rng(S + i) (default 0)")
    parser.add_argument("--solver", choices=SOLVER_CHOICES, default="auto",
                        help="collocation solver for --locations (default auto: the SQP, then IPOPT where it fails)")
    parser.add_argument("--plans", metavar="DIR", help="with --locations: keep the plans here")
    parser.add_argument("--rate", type=float, default=1000.0, metavar="HZ",
                        help="PD controller rate (Hz, default 1000)")
    parser.add_argument("--mode", choices=("feedforward", "position"), default="feedforward",
                        help="joint controller: plan torques + PD (feedforward, default) or "
                             "the robot's PD position control on servo-rate, delayed desired "
                             "states with its own gravity compensation (position)")
    parser.add_argument("--replan", action="store_true",
                        help="sense, plan, act: after the scoop, measure where the burger lies "
                             "on the blade and re-plan pickup, flip and turn back for it "
                             "(serve: at the end of the carry, re-plan place and return home)")
    add_sweep_arguments(parser)
    parser.add_argument("--json", required=True, metavar="OUT.json", help="output file")
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
    """Check the input, run the trials on the executor, write the JSON, print the table."""
    from flipkit.experiments.compare_ik import LOCATION_SETS
    from flipkit.errors import ConfigError
    from flipkit.experiments.sweep import make_executor
    from flipkit.experiments.trials import validate_locations, validate_plan_file

    if args.trials < 1:
        raise ConfigError(f"--trials must be at least 1, got {args.trials}")
    if not (math.isfinite(args.rate) and args.rate > 0):
        raise ConfigError(f"--rate must be a positive number of Hz, got {args.rate}")
    common = dict(progress=not args.no_progress, rate_hz=args.rate, mode=args.mode,
                  replan=args.replan)
    with make_executor(args.scheduler, args.workers) as executor:
        if args.plan is not None:
            out = validate_plan_file(args.plan, args.trials, args.seed, executor=executor,
                                     cache_dir=args.cache, **common)
        else:
            out = validate_locations(LOCATION_SETS[args.locations], args.trials, args.solver,
                                     args.seed, executor=executor, cache_dir=args.cache,
                                     plans_dir=args.plans, **common)
    write_json(args.json, out)
    print(format_table(out))
    total = out["summary"]
    print(f"flipkit validate ({out['mode']}): {total['trials']} trials at "
          f"{total['locations']} locations, "
          f"success {total['success']}; wrote {args.json}")
    return 0
