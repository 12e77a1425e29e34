"""A sweep's items on an executor, where a worker that dies costs a retry, not the sweep.

When a local worker process dies, its pool is broken: every item in flight fails with
``BrokenProcessPool``, whichever of them killed it. The pool is replaced
(:meth:`flipkit.experiments.executors.RenewablePool.renew`) and each item in flight is
charged one death. A charged item (a suspect) then runs alone, so that a death while it runs
is its own; innocent items caught in another's death pass alone once and the sweep goes on
at full width. An item charged ``1 + retries`` times is given up as ``worker died``. Local
items are handed out ``workers`` at a time, so that every item in flight is running.

A Dask cluster reschedules the tasks of a lost worker itself; a task whose workers kept dying
fails with ``KilledWorker`` and is charged like a dead local worker.
"""

from __future__ import annotations

import concurrent.futures as cf
import sys
from collections import Counter, deque
from concurrent.futures.process import BrokenProcessPool

from tqdm import tqdm

from flipkit.errors import SweepError
from flipkit.experiments.executors import worker_died

RETRIES = 2  # attempts of an item after the first whose worker died


def run_items(executor: cf.Executor, fn, items: list, todo: list[int], store, label,
              retries: int = RETRIES) -> list[int]:
    """Compute ``fn(items[i])`` for every ``i`` of ``todo`` on ``executor``.

    Args:
        executor: Where to run; with a ``renew()`` method (a local pool) a broken pool is
            replaced, and with a ``workers`` attribute at most that many items are submitted
            at once (otherwise all at once, as to a Dask cluster).
        fn, items: The function and its arguments (picklable).
        todo: Indices of the items to compute, in the order to submit them.
        store: ``store(i, result)``, called in this process as each result arrives.
        label: ``label(i)``: the item as a reader names it, for error messages.
        retries: Attempts of an item after the first whose worker died (≥ 0).

    Returns:
        The indices of the items given up: their worker died on each of ``1 + retries``
        attempts. Every other item of ``todo`` was stored.

    Raises:
        Whatever ``fn`` raises for an item (the items in flight are cancelled or dropped).
        SweepError: An item was cancelled under the sweep (its Dask cluster was lost), or a
            worker died in an executor that cannot be renewed.
    """
    renew = getattr(executor, "renew", None)
    width = getattr(executor, "workers", None)
    queue, suspects, deaths, failed, running = deque(todo), deque(), Counter(), [], {}

    def submit(waiting: deque) -> None:
        running[executor.submit(fn, items[waiting[0]])] = waiting[0]
        waiting.popleft()

    def charge(lost) -> None:
        again = []
        for i in lost:
            deaths[i] += 1
            (failed if deaths[i] > retries else again).append(i)
        suspects.extend(again)
        if again:  # one line on stderr, above the progress bar
            tqdm.write(f"flipkit: a worker died running {'; '.join(label(i) for i in lost)}; "
                       f"{len(again)} of them run again, one at a time", file=sys.stderr)

    def pool_broke() -> None:
        """Keep what finished before the break, charge the rest, start a fresh pool."""
        lost = []
        for future, i in running.items():
            if future.done() and not future.cancelled() and future.exception() is None:
                store(i, future.result())
            else:
                lost.append(i)
        running.clear()
        if renew is None:
            raise SweepError(f"a worker died running {', '.join(label(i) for i in lost)}, "
                             f"and its executor cannot be replaced")
        renew()
        charge(sorted(lost))

    try:
        while queue or suspects or running:
            try:
                if suspects:
                    if not running:
                        submit(suspects)
                else:
                    while queue and (width is None or len(running) < width):
                        submit(queue)
            except BrokenProcessPool:  # the pool broke since the last wait
                pool_broke()
                continue
            done, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            broken = False
            for future in done:
                i = running.pop(future)
                if future.cancelled():
                    raise SweepError(f"{label(i)}: cancelled by its executor (a lost Dask "
                                     f"scheduler?)")
                exc = future.exception()
                if exc is None:
                    store(i, future.result())
                elif isinstance(exc, BrokenProcessPool):
                    running[future], broken = i, True
                elif worker_died(exc):
                    charge([i])
                else:
                    raise exc
            if broken:
                pool_broke()
    finally:
        for future in running:
            future.cancel()
    return failed


__all__ = ["RETRIES", "run_items"]
