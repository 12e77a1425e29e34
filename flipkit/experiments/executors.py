"""The sweep's executors: local worker processes that can be replaced when one dies, or a
Dask cluster.

A :class:`concurrent.futures.ProcessPoolExecutor` whose worker is killed (the kernel's OOM
killer, a crash in native code, a signal) is broken for good: every unfinished future fails
with ``BrokenProcessPool`` and no more work is accepted. :class:`RenewablePool` is an
executor that holds the recipe of its pool, so a sweep can swap the broken pool for a fresh
one and submit again (:func:`flipkit.experiments.sweep.run_sweep`). A Dask cluster
reschedules the tasks of a lost worker itself, and fails a task with ``KilledWorker`` only
after it was on several workers that died (``distributed.scheduler.allowed-failures``).
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import sys
from concurrent.futures.process import BrokenProcessPool

from flipkit.errors import ConfigError, FlipkitError
from flipkit.experiments.worker_pool import WorkerPool

SINGLE_THREAD_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _single_threaded() -> None:
    """Worker initializer: one BLAS/OpenMP thread per worker process (unless set)."""
    for name in SINGLE_THREAD_ENV:
        os.environ.setdefault(name, "1")


class RenewablePool(cf.Executor):
    """Local worker processes (forkserver start method, so no worker inherits a
    half-initialised solver by forking) whose pool can be replaced by a fresh one. Each pool
    is a :class:`~flipkit.experiments.worker_pool.WorkerPool`: leaving a ``with`` block by an
    exception (an error, Ctrl-C, a termination signal) terminates the workers at once.

    Args:
        workers: Number of worker processes.

    Attributes:
        workers: Number of worker processes: at most this many items run at once.
        pools: How many pools were started (1 + the renewals).
    """

    def __init__(self, workers: int):
        self.workers, self.pools = workers, 0
        methods = multiprocessing.get_all_start_methods()
        self._context = multiprocessing.get_context(
            "forkserver" if "forkserver" in methods else "spawn")
        self._pool = self._start()

    def _start(self) -> WorkerPool:
        self.pools += 1
        return WorkerPool(max_workers=self.workers, mp_context=self._context,
                          initializer=_single_threaded)

    def __exit__(self, exc_type, exc, tb):
        return self._pool.__exit__(exc_type, exc, tb)  # the current pool's: wait or terminate

    def terminate(self) -> None:
        """End the current pool's workers at once (:meth:`WorkerPool.terminate`)."""
        self._pool.terminate()

    def submit(self, fn, /, *args, **kwargs) -> cf.Future:
        return self._pool.submit(fn, *args, **kwargs)

    def renew(self) -> None:
        """Shut the current pool down without waiting (its unfinished work is dropped) and
        start a fresh one."""
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = self._start()

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        self._pool.shutdown(wait=wait, cancel_futures=cancel_futures)


def worker_died(exc: BaseException) -> bool:
    """Whether ``exc``, the error of one item's future, says the worker running it died
    rather than that the item's function raised: a broken process pool, or a Dask task
    whose workers kept dying (``KilledWorker``)."""
    if isinstance(exc, BrokenProcessPool):
        return True
    distributed = sys.modules.get("distributed")  # imported only when a scheduler is used
    return distributed is not None and isinstance(exc, distributed.KilledWorker)


def _dask_executor(scheduler: str) -> cf.Executor:
    """The executor of a Dask client connected to ``scheduler``; it closes the client when
    shut down."""
    import distributed.cfexecutor  # Dask is slow to import; only --scheduler needs it

    try:
        client = distributed.Client(scheduler, timeout="10s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FlipkitError(f"cannot connect to the Dask scheduler at {scheduler}: "
                           f"{msg}") from None

    class DaskExecutor(distributed.cfexecutor.ClientExecutor):
        """A Dask client's executor that also closes the client when shut down."""

        def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
            try:
                super().shutdown(wait=wait and not cancel_futures)
            finally:
                self._client.close()

    return DaskExecutor(client, pure=False)


def make_executor(scheduler: str | None = None, workers: int | None = None) -> cf.Executor:
    """The executor of a sweep.

    Args:
        scheduler: Address of a Dask scheduler (e.g. ``tcp://host:8786``); ``None`` for
            local worker processes.
        workers: Number of local worker processes (default: the CPU count). Ignored with a
            scheduler: the cluster decides.

    Returns:
        A :class:`RenewablePool`, or a Dask client's executor; call ``shutdown()`` (or use
        it in a ``with`` block) when done. A Dask executor closes its client on shutdown.

    Raises:
        ConfigError: ``workers`` is not a positive integer.
        FlipkitError: The scheduler cannot be reached (10 s timeout).
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise ConfigError(f"workers must be a positive integer, got {workers!r}")
    if scheduler:
        return _dask_executor(scheduler)
    return RenewablePool(workers or os.cpu_count() or 1)


__all__ = ["RenewablePool", "SINGLE_THREAD_ENV", "make_executor", "worker_died"]
