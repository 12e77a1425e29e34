"""One BLAS thread inside a solve.

The solvers' linear algebra is small: a 31 × 31 Cholesky, 547 × 31 products, sparse LU
factorisations of ~520 rows. OpenBLAS's thread pool (by default one thread per core) costs
more than it saves on such sizes, and when the cores are busy — a second solve in a sweep
worker, a notebook, another process — its threads wait for each other, and a condensed QP
update takes many times as long as with one thread (docs/history.md).
:func:`single_threaded_blas` limits every BLAS library loaded in the process to one thread
for the duration of a ``with`` block and restores the previous setting after it, through
threadpoolctl. Building a controller scans the loaded libraries, so a caller that enters the
block often keeps its own controller and passes it in
(:class:`~flipkit.solvers.sqp_solver.SQPSolver` does).
"""

from __future__ import annotations

from threadpoolctl import ThreadpoolController


def single_threaded_blas(controller: ThreadpoolController | None = None):
    """Context manager: BLAS limited to one thread inside the block.

    Args:
        controller: The threadpoolctl controller to limit through, built after numpy and
            scipy are loaded; default a new one.
    """
    return (ThreadpoolController() if controller is None else controller).limit(
        limits=1, user_api="blas")
