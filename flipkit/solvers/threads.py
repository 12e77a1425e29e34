"""One BLAS thread inside a solve.

The solvers' linear algebra is small: a 31 × 31 Cholesky, 547 × 31 products, sparse LU
factorisations of ~520 rows. OpenBLAS's thread pool (two threads on the 2-core machine, by
default one per core) costs more than it saves on such sizes, and when the cores are busy —
a second solve in a sweep worker, a notebook, another process — its threads wait for each
other, and a condensed QP update takes over ten times as long as with one thread.
:func:`single_threaded_blas` limits every BLAS library loaded in the process to one thread
for the duration of a ``with`` block and restores the previous setting after it, through
threadpoolctl (a controller built once, so entering the block is cheap).
"""

from __future__ import annotations

from threadpoolctl import ThreadpoolController

_CONTROLLER: ThreadpoolController | None = None


def single_threaded_blas():
    """Context manager: BLAS limited to one thread inside the block."""
    global _CONTROLLER
    if _CONTROLLER is None:  # after numpy and scipy are loaded (they are, by the solvers)
        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER.limit(limits=1, user_api="blas")
