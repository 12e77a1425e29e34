"""Options, bounds and file helpers shared by the sub-commands: the sweep options
(compare-ik, validate), numeric options checked against their documented ranges, the cheap
first reading of a plan file, JSON written atomically, and the deferred import of a
sub-command's work (:func:`deferred`)."""

from __future__ import annotations

import argparse
import importlib
import json
import math

from flipkit.errors import ConfigError
from flipkit.fileio import write_text
from flipkit.planning.plans.plan_doc import read_plan_doc

LOCATION_SET_CHOICES = ("table1", "more")  # flipkit.config.LOCATION_SETS


def add_sweep_arguments(parser: argparse.ArgumentParser) -> None:
    """The executor and cache options shared by the sweep commands."""
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="Dask scheduler address (e.g. tcp://host:8786); default: local "
                             "worker processes")
    parser.add_argument("--workers", type=int, metavar="N",
                        help="local worker processes (default: the CPU count)")
    parser.add_argument("--cache", metavar="DIR",
                        help="cache directory: finished items are stored there and not "
                             "recomputed when the command is run again")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


MAX_WORKERS = 256  # local worker processes
MAX_GRID = 50  # points per axis of a grid over the grill (atlas build, compare-ik)


def check_int(flag: str, value, lo: int, hi: int) -> int:
    """``value`` of the option ``flag`` as an integer in [lo, hi].

    Raises:
        ConfigError: One line naming the flag, the range and the value.
    """
    if value is None or isinstance(value, bool) or int(value) != value or not lo <= value <= hi:
        raise ConfigError(f"{flag} must be an integer in [{lo}, {hi}], got {value!r}")
    return int(value)


def check_float(flag: str, value, lo: float, hi: float, unit: str) -> float:
    """``value`` of the option ``flag`` as a finite number in [lo, hi] (``unit``).

    Raises:
        ConfigError: One line naming the flag, the range and the value.
    """
    if value is None or not (math.isfinite(value) and lo <= value <= hi):
        raise ConfigError(f"{flag} must be a number in [{lo:g}, {hi:g}] {unit}, got {value!r}")
    return float(value)


def precheck_plan(path) -> None:
    """The cheap checks of a plan file (:func:`flipkit.planning.plans.plan_doc.read_plan_doc`),
    before a command imports the models: a malformed file is refused at once."""
    read_plan_doc(path)


def write_json(path, doc: dict) -> None:
    """Write ``doc`` as indented JSON (no NaN) to ``path`` atomically, or a one-line
    FlipkitError."""
    try:
        text = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    except ValueError as exc:
        raise ConfigError(f"cannot write {path}: {exc}") from None
    write_text(path, text)


def deferred(command: str, function: str = "run"):
    """The callable that runs ``flipkit.cli.commands.<command>.<function>(args)``.

    A sub-command is two modules: ``flipkit.cli.<command>`` (its arguments and their cheap
    checks, imported for every parse) and ``flipkit.cli.commands.<command>`` (its work, with
    the models it needs: pinocchio, CasADi, cvxpy, MuJoCo, slow to import). This is the
    one place the command line defers an import, so that ``flipkit --help`` and an input
    refused by the cheap checks never load the models.
    """
    def run(args: argparse.Namespace) -> int:
        return getattr(importlib.import_module(f"flipkit.cli.commands.{command}"), function)(args)
    return run
