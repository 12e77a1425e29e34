"""The cache of a sweep command: ``--cache DIR`` when given, else a run cache beside the
output, so that a run that stops half-way (a worker lost for good, the machine rebooted,
Ctrl-C) loses nothing that finished.

The run cache of ``OUT.json`` is the directory ``OUT.run-cache`` in the same folder. The
command names it in one line on stderr when it starts, and removes it when it succeeds; a
run that stops leaves it, and the same command, run again, reads back every item that
finished there (:func:`flipkit.experiments.sweep.run_sweep`'s cache), so its results are
those of an uninterrupted run.
"""

from __future__ import annotations

import contextlib
import shutil
import sys
from pathlib import Path
from typing import Iterator

from flipkit.fileio import check_output_dir


def run_cache_dir(output) -> Path:
    """The run cache of the output file ``output``: ``OUT.run-cache`` beside ``OUT.json``."""
    out = Path(output)
    return out.with_name(out.stem + ".run-cache")


@contextlib.contextmanager
def sweep_cache(cache, output, command: str) -> Iterator[Path]:
    """The cache directory a sweep command runs with.

    Args:
        cache: The ``--cache`` directory, or ``None``.
        output: The command's output file; without ``cache`` its run cache
            (:func:`run_cache_dir`) is used, named on stderr, and removed once the block
            finishes without an error.
        command: The command's name in the line on stderr (e.g. ``"validate"``).

    Yields:
        The directory to pass to the sweep as its cache.

    Raises:
        OutputPathError: The run cache's path is a file or not writable.
    """
    if cache is not None:
        yield Path(cache)
        return
    where = check_output_dir(run_cache_dir(output), "run cache")
    resumes = "resuming from" if where.is_dir() else "keeping finished items in"
    print(f"flipkit {command}: {resumes} the run cache {where}/ (removed when the command "
          f"succeeds; if it stops, run the same command again to resume)", file=sys.stderr)
    yield where
    shutil.rmtree(where, ignore_errors=True)


__all__ = ["run_cache_dir", "sweep_cache"]
