"""``flipkit export``: verify a plan, resample it at a controller rate and write it as CSV,
a URScript ``servoj`` program or a ROS 2 JointTrajectory (YAML).

Exit status: 0 written; 2 refused, nothing written — one line on stderr: an unreadable or
malformed plan, a plan that fails verification (the line names the failed check), an
unknown format or command, a rate the format does not take (csv and ros2: [100, 1000] Hz;
urscript: 125, 250 or 500 Hz), a servoj option outside its range or given for another
format, a stream that fails its check against the arm's published limits (the line names
the joint, the time and the amount), an output whose suffix is not the format's or that is
the plan itself.
"""

from __future__ import annotations

import argparse
import math

from flipkit.cli.common import deferred, precheck_plan
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.fileio import check_output

RATE_RANGE = (1.0, 10_000.0)  # Hz, --rate (flipkit.planning.plans.export.RATE_RANGE)
DEFAULT_RATE = 125.0  # Hz: a CB3's servo rate (an e-Series: 500)
# Output suffixes by format; csv first, the default.
FORMATS = {"csv": (".csv",), "urscript": (".script", ".urscript"), "ros2": (".yaml", ".yml")}
# The servoj options (flipkit.planning.plans.export_urscript: ServoOptions, its ranges) and
# the commands (flipkit.planning.plans.servo_command.COMMANDS), here without their imports.
SERVO = {"lookahead": ("--lookahead", (0.03, 0.2), "s", 0.1,
                       "servoj lookahead_time (compensated commands are made for its smoothing)"),
         "gain": ("--gain", (100.0, 2000.0), "", 300.0, "servoj gain (proportional)"),
         "start_tol": ("--start-tol", (1e-4, 0.1), "rad", 0.01,
                       "the start guard's tolerance per joint")}
COMMANDS = ("raw", "compensated")  # servo_command.COMMANDS; raw is DEFAULT_COMMAND
# The rates each format is written at (flipkit.planning.plans.export.STREAM_RATES and
# export_urscript.SERVO_RATES): a stream at another rate is refused before any work.
STREAM_RATES = {"csv": (100.0, 1000.0), "ros2": (100.0, 1000.0)}
SERVO_RATES = (125.0, 250.0, 500.0)


def register(subparsers) -> None:
    """Add the ``export`` sub-command to the ``flipkit`` parser."""
    parser = subparsers.add_parser(
        "export", help="write a verified plan for a controller: CSV, URScript or ROS 2 YAML",
        description="Verify the plan (as flipkit verify; exit 2 and write nothing if it "
                    "fails), resample its segments at the controller rate (cubic Hermite "
                    "interpolation between nodes, as the collocation) and write them: csv "
                    "(t,q1..q6,qd1..qd6 in s, rad, rad/s), urscript (a program that checks "
                    "the arm is at the plan's start, then sends one servoj per sample) or "
                    "ros2 (a trajectory_msgs/msg/JointTrajectory in YAML). docs/exports.md "
                    "says how each is run on a cell.")
    parser.add_argument("plan", metavar="PLAN.json", help="plan file (flipkit-plan/2; /1 is read too)")
    parser.add_argument("--format", default="csv", metavar="NAME",
                        help=f"one of {', '.join(FORMATS)} (default csv)")
    parser.add_argument("--out", metavar="FILE",
                        help="output file: .csv, .script (or .urscript), .yaml (or .yml) by "
                             "format; not the plan")
    parser.add_argument("--csv", metavar="OUT.csv", help="same as --format csv --out OUT.csv")
    parser.add_argument("--rate", default=str(DEFAULT_RATE), metavar="HZ",
                        help="controller rate (Hz), default 125 (CB3; e-Series 500): csv and "
                             "ros2 in [100, 1000]; urscript 125, 250 or 500 (servoj t = 1/rate)")
    parser.add_argument("--force", action="store_true",
                        help="export even a plan whose status is not 'solved' (it must still "
                             "pass verification)")
    servo = parser.add_argument_group("urscript only")
    for flag, (lo, hi), unit, default, what in SERVO.values():
        servo.add_argument(flag, metavar="X", help=f"{what} in [{lo:g}, {hi:g}]"
                                                   f"{' ' + unit if unit else ''}, default "
                                                   f"{default:g}")
    servo.add_argument("--command", metavar="KIND",
                       help="the positions streamed: raw (default; the plan's q, as the paper "
                            "sends them) or compensated (flipkit.planning.plans.servo_command; "
                            "refused where it breaks the arm's limits)")
    parser.set_defaults(run=run)


def number(flag: str, text, lo: float, hi: float, unit: str) -> float:
    """``text`` of the option ``flag`` as a finite number in [lo, hi] (``unit``, may be
    empty), or a one-line ConfigError naming the flag, the range and the value."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        value = None
    if value is None or not (math.isfinite(value) and lo <= value <= hi):
        raise ConfigError(f"{flag} must be a number in [{lo:g}, {hi:g}]"
                          f"{' ' + unit if unit else ''}, got {text!r}")
    return value


def servo_options(args: argparse.Namespace) -> dict:
    """The servoj options given (checked), or ConfigError if given for another format."""
    given = {k: getattr(args, k) for k in (*SERVO, "command") if getattr(args, k) is not None}
    if given and args.format != "urscript":
        flags = ", ".join(SERVO[k][0] if k in SERVO else "--command" for k in given)
        raise ConfigError(f"{flags}: for --format urscript only, not {args.format}")
    for key, (flag, (lo, hi), unit, _, _) in SERVO.items():
        if key in given:
            given[key] = number(flag, given[key], lo, hi, unit)
    if "command" in given and given["command"] not in COMMANDS:
        raise InvalidChoiceError("position command", given["command"], COMMANDS)
    return given


def run(args: argparse.Namespace) -> int:
    """Check the format, the output, the numbers and the file cheaply, then load, verify,
    resample and write (:mod:`flipkit.cli.commands.export`)."""
    if args.format not in FORMATS:
        raise InvalidChoiceError("export format", args.format, FORMATS)
    if args.csv is not None and (args.out is not None or args.format != "csv"):
        raise ConfigError("--csv OUT.csv is --format csv --out OUT.csv; give --out alone "
                          "with --format")
    flag, args.out = ("--csv", args.csv) if args.csv is not None else ("--out", args.out)
    if args.out is None:
        raise ConfigError(f"give --out FILE ({' or '.join(FORMATS[args.format])})")
    check_output(args.out, flag, FORMATS[args.format], inputs=[args.plan])
    args.rate = number("--rate", args.rate, *RATE_RANGE, "Hz")
    lo, hi = STREAM_RATES.get(args.format, (0.0, 0.0))
    if args.format == "urscript" and args.rate not in SERVO_RATES:
        raise ConfigError(f"--rate for urscript must be one of "
                          f"{', '.join(f'{r:g}' for r in SERVO_RATES)} Hz (servoj t a whole "
                          f"number of controller cycles: 8 ms on a CB3, 2 ms on an e-Series), "
                          f"got {args.rate:g}")
    if args.format != "urscript" and not lo <= args.rate <= hi:
        raise ConfigError(f"--rate for {args.format} must be in [{lo:g}, {hi:g}] Hz (a "
                          f"controller's rate), got {args.rate:g}")
    args.servo = servo_options(args)
    precheck_plan(args.plan)
    return deferred("export")(args)
