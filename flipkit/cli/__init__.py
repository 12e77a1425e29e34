"""The ``flipkit`` command line.

Each sub-command lives in :mod:`flipkit.cli` as a module with ``register(subparsers)``;
errors derived from :class:`~flipkit.errors.FlipkitError` print one line and exit with the
error's status (2: bad input; 1: work that could not be done, such as sweep items whose
worker died on every attempt). A worker process that dies outside a sweep (the executors
of ``plan batch`` and ``schedule``) ends the command the same way, one line and exit 1.
SIGINT, SIGTERM and SIGHUP stop a command with everything it started
(:mod:`flipkit.cli.signals`): one line (``flipkit: interrupted``, ``terminated``, ``hung
up``) and exit 130, 143 or 129. A command whose extra is not installed (``flipkit[sim]``,
...: :mod:`flipkit.extras`) says which, in one line, and exits 1.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import importlib
import sys

from flipkit.cli.signals import farewell, signals_raise
from flipkit.errors import FlipkitError
from flipkit.extras import missing_extra_message

COMMANDS = ("plan", "verify", "export", "figures", "compare-ik", "validate", "animate",
            "view", "schedule", "atlas")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="flipkit", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"flipkit.cli.{name.replace('-', '_')}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with signals_raise():  # SIGTERM and SIGHUP end the command as Ctrl-C does
            return int(args.run(args) or 0)
    except FlipkitError as exc:
        print(f"flipkit: error: {exc}", file=sys.stderr)
        return exc.exit_status
    except ModuleNotFoundError as exc:
        line = missing_extra_message(args.command, exc.name)
        if line is None:
            raise
        print(f"flipkit: error: {line}", file=sys.stderr)
        return 1
    except cf.BrokenExecutor as exc:
        print(f"flipkit: error: a worker process died ({exc})", file=sys.stderr)
        return 1
    except KeyboardInterrupt as exc:
        line, status = farewell(exc)
        print(line, file=sys.stderr)
        return status


if __name__ == "__main__":
    sys.exit(main())
