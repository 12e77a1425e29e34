"""Local worker processes that end with the run: :class:`WorkerPool`, the process pool
(:class:`~concurrent.futures.ProcessPoolExecutor`) that
:func:`flipkit.experiments.sweep.make_executor` makes. A run that fails or is stopped
(Ctrl-C, or SIGTERM and SIGHUP turned into exceptions by :mod:`flipkit.cli.signals`)
terminates its workers instead of waiting for them, so that none goes on computing, or holds
the caller's standard output open, after it; the forkserver and the resource tracker then
end with the main process."""

from __future__ import annotations

import concurrent.futures as cf


def _sparing_cancelled(manager):
    """``manager.terminate_broken`` (the pool's manager thread marks the work left failed)
    that first drops the work the caller cancelled: Python 3.11 would raise
    InvalidStateError on it in that thread, and print the traceback."""
    broken = manager.terminate_broken

    def terminate_broken(cause):
        for work_id, item in list(manager.pending_work_items.items()):
            if item.future.cancelled():
                del manager.pending_work_items[work_id]
        broken(cause)
    return terminate_broken


class WorkerPool(cf.ProcessPoolExecutor):
    """Local worker processes that stop at once when the run fails or is interrupted.

    Leaving a ``with`` block normally waits for the submitted work, as the standard pool
    does; leaving it by an exception (an error, Ctrl-C, a termination signal turned into
    one by :mod:`flipkit.cli.signals`) terminates the workers instead (:meth:`terminate`),
    so that none goes on computing, or holds the caller's output open, after the run.
    """

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.shutdown(wait=True)
        else:
            self.terminate()
        return False

    def terminate(self, grace_s: float = 5.0) -> None:
        """Cancel the pending work, end the workers (SIGTERM, then SIGKILL after
        ``grace_s`` s) and release the pool's queues."""
        manager = self._executor_manager_thread
        if manager is not None:  # it fails the work left when the workers end
            manager.terminate_broken = _sparing_cancelled(manager)
        processes = list((self._processes or {}).values())
        for proc in processes:
            if proc.is_alive():
                proc.terminate()
        for proc in processes:
            proc.join(grace_s)
            if proc.is_alive():
                proc.kill()
                proc.join()
        self.shutdown(wait=True, cancel_futures=True)


__all__ = ["WorkerPool"]
