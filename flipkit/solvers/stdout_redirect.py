"""What a native solver writes to stdout, sent elsewhere for the length of a block.

A solver inside an extension prints with C's printf to fd 1, or through ``sys.stdout``
(CasADi sends its plugins' output there in Python). :func:`redirected_stdout` moves both:
fd 1 to another descriptor and ``sys.stdout`` to another stream, and flushes C's buffers
before fd 1 is restored (else the text lands later, in the middle of a command's output).
:func:`c_stdout_silenced` discards it (OSQP's polish note); :func:`captured_stdout` keeps it
to be read (FATROP's iteration table, :mod:`flipkit.solvers.step_profile`). fd 1 is
process-wide: not for threads that print meanwhile (flipkit's sweeps use processes).
"""

from __future__ import annotations

import contextlib
import ctypes
import io
import os
import sys
import tempfile

try:
    _LIBC = ctypes.CDLL(None)  # this process's C library, for fflush
except OSError:  # pragma: no cover - not a POSIX process
    _LIBC = None


@contextlib.contextmanager
def redirected_stdout(fd: int, stream):
    """fd 1 onto ``fd`` and ``sys.stdout`` onto ``stream`` meanwhile. Without an fd 1 (closed,
    say) only ``sys.stdout`` is moved."""
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError, AttributeError):  # no fd 1
        saved = None
    try:
        if saved is not None:
            os.dup2(fd, 1)
        with contextlib.redirect_stdout(stream):
            yield
    finally:
        if _LIBC is not None:
            _LIBC.fflush(None)
        if saved is not None:
            os.dup2(saved, 1)
            os.close(saved)


@contextlib.contextmanager
def c_stdout_silenced():
    """Discard what is written to stdout meanwhile, from C or through Python.

    OSQP 1.1's polish step prints "Polishing not needed - no active set detected at optimal
    point" whatever its ``verbose`` setting; nothing of flipkit prints inside a solve.
    """
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        with open(os.devnull, "w") as sink, redirected_stdout(devnull, sink):
            yield
    finally:
        os.close(devnull)


@contextlib.contextmanager
def captured_stdout():
    """Collect what is written to stdout meanwhile instead of showing it; yields a list that
    holds the text, fd 1's then Python's, once the block ends."""
    out: list[str] = []
    python = io.StringIO()
    with tempfile.TemporaryFile(mode="w+b") as sink:
        try:
            with redirected_stdout(sink.fileno(), python):
                yield out
        finally:
            sink.seek(0)
            out.append(sink.read().decode(errors="replace") + python.getvalue())


__all__ = ["c_stdout_silenced", "captured_stdout", "redirected_stdout"]
