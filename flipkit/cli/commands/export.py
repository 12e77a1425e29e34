"""``flipkit export`` once its arguments passed :mod:`flipkit.cli.export`: load, verify,
resample and write the CSV, the URScript program or the ROS 2 trajectory."""

from __future__ import annotations

import argparse

from flipkit.planning.plans.export import write_csv
from flipkit.planning.plans.export_ros2 import write_ros2
from flipkit.planning.plans.export_urscript import ServoOptions, write_urscript
from flipkit.planning.plans.plan_file import Plan


def run(args: argparse.Namespace) -> int:
    """Load, verify, resample, write; one line with the count written."""
    plan = Plan.load(args.plan)
    checks = []
    common = {"force": args.force, "where": args.plan, "on_check": checks.append}
    if args.format == "urscript":
        options = ServoOptions(**args.servo)
        count = write_urscript(plan, args.out, args.rate, options, **common)
        what = f"servoj samples (command {options.command})"
    elif args.format == "ros2":
        count, what = write_ros2(plan, args.out, args.rate, **common), "trajectory points"
    else:
        count, what = write_csv(plan, args.out, args.rate, **common), "rows"
    total = plan.duration
    print(f"flipkit export: wrote {count} {what} ({total:.3f} s at {args.rate:g} Hz) to "
          f"{args.out}; stream checked against the {plan.cell().robot.profile} profile: "
          f"{checks[0].summary()}")
    return 0
