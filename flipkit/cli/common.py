"""Options and output helpers shared by the sweep commands (compare-ik, validate)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from flipkit.errors import FlipkitError

SOLVER_CHOICES = ("sqp", "ipopt", "auto")


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


def write_json(path, doc: dict) -> None:
    """Write ``doc`` as indented JSON (no NaN) to ``path``, or a one-line FlipkitError."""
    try:
        Path(path).write_text(json.dumps(doc, indent=1, allow_nan=False) + "\n")
    except OSError as exc:
        raise FlipkitError(f"cannot write {path}: {exc.strerror or exc}") from None
