"""``flipkit validate`` once its arguments passed :mod:`flipkit.cli.validate`: verify the
plan, run the trials on the executor (cached in ``--cache`` or the run cache,
:mod:`flipkit.cli.run_cache`), write the JSON, print the table."""

from __future__ import annotations

import argparse

from flipkit.cli.common import write_json
from flipkit.cli.run_cache import sweep_cache
from flipkit.cli.validate import format_table
from flipkit.errors import ConfigError
from flipkit.config import LOCATION_SETS
from flipkit.experiments.pauses import format_pauses
from flipkit.experiments.ratios import format_intervals
from flipkit.experiments.slides import format_slides
from flipkit.experiments.sweep import make_executor
from flipkit.experiments.trial_jobs import format_safety
from flipkit.experiments.trials import validate_locations, validate_plan_file
from flipkit.planning.plans.verify import load_verified


def run(args: argparse.Namespace) -> int:
    """Verify the plan, run the trials, write the JSON, print the table."""
    if args.plan is not None:
        plan = load_verified(args.plan, ("flip", "serve"))  # refused before any worker starts
        if args.contingencies and plan.behavior != "flip":
            raise ConfigError(f"{args.plan}: --contingencies needs a flip plan, got a "
                              f"{plan.behavior} plan")
    common = dict(progress=not args.no_progress, rate_hz=args.rate, mode=args.mode,
                  replan=args.replan, command=args.command,
                  servo_lookahead_s=args.servo_lookahead, servo_form=args.servo_form,
                  **({"contingencies": True} if args.contingencies else {}))
    with make_executor(args.scheduler, args.workers) as executor, \
            sweep_cache(args.cache, args.json, "validate") as cache:
        if args.plan is not None:
            out = validate_plan_file(args.plan, args.trials, args.seed, executor=executor,
                                     cache_dir=cache, **common)
        else:
            out = validate_locations(LOCATION_SETS[args.locations], args.trials, args.solver,
                                     args.seed, executor=executor, cache_dir=cache,
                                     plans_dir=args.plans, atlas=not args.no_atlas,
                                     heading=args.heading, turn=args.turn, **common)
        write_json(args.json, out)
    print(format_table(out))
    total = out["summary"]
    print(f"flipkit validate ({out['mode']}): {total['trials']} trials at "
          f"{total['locations']} locations, "
          f"success {total['success']}; wrote {args.json}")
    print(format_intervals(total["interval_95"]))
    print(format_safety(total.get("safety")))
    if out.get("replan") and "pause" in total:  # a flip validation's re-plans
        print(format_pauses(total["pause"]))
    if total.get("slide"):  # a flip validation's landings
        print(format_slides(total["slide"]))
    return 0
