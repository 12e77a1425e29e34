"""Termination signals as exceptions, so that a command ends the same way whichever signal
stops it.

Python turns SIGINT into :class:`KeyboardInterrupt`, and everything a command started —
worker pools (:class:`~flipkit.experiments.worker_pool.WorkerPool` terminates its workers when an
exception leaves it), the CP-SAT child (closed at exit) — is stopped on the way out. SIGTERM
and SIGHUP would kill the process at once, leaving those children running with the
caller's standard output and error open. :func:`signals_raise` makes them raise
:class:`Terminated`, a KeyboardInterrupt, so they take the same way out; :func:`farewell`
is the one line and exit status ``128 + signal`` the command line ends with.
"""

from __future__ import annotations

import contextlib
import signal
import threading

HANDLED = (signal.SIGTERM, signal.SIGHUP)
WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated", signal.SIGHUP: "hung up"}


class Terminated(KeyboardInterrupt):
    """A termination signal (SIGTERM, SIGHUP) received by the command.

    Attributes:
        signum: The signal's number.
    """

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = int(signum)


def _raise(signum, frame):
    raise Terminated(signum)


@contextlib.contextmanager
def signals_raise():
    """Within the block, SIGTERM and SIGHUP raise :class:`Terminated` (in the main thread;
    elsewhere, where Python cannot set handlers, nothing changes). The previous handlers
    are restored after it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _raise) for s in HANDLED}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


def farewell(exc: KeyboardInterrupt) -> tuple[str, int]:
    """The line (``flipkit: interrupted``, ``terminated`` or ``hung up``) and exit status
    (128 + the signal's number) of a command stopped by ``exc``."""
    signum = getattr(exc, "signum", signal.SIGINT)
    return f"flipkit: {WORDS.get(signum, 'stopped')}", 128 + int(signum)


__all__ = ["HANDLED", "Terminated", "farewell", "signals_raise"]
