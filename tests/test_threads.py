"""The solvers run BLAS on one thread and restore the process's setting afterwards."""

import numpy as np
from threadpoolctl import threadpool_info

import flipkit.solvers.sqp as sqp_module
from flipkit.solvers.threads import single_threaded_blas


def _blas_threads():
    return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]


def test_single_threaded_inside_and_restored_after():
    np.ones((2, 2)) @ np.ones((2, 2))  # BLAS loaded
    before = _blas_threads()
    assert before
    with single_threaded_blas():
        assert all(n == 1 for n in _blas_threads())
    assert _blas_threads() == before


def test_sqp_solves_inside_the_limit(monkeypatch):
    """solve_sqp's loop (SQPSolver's) runs with one BLAS thread (the limit is entered around
    it), and the previous setting is back after it."""
    from flipkit.solvers.sqp_solver import SQPSolver

    seen, before = [], _blas_threads()

    def probe(self, nlp, x0):
        seen.append(_blas_threads())
        raise RuntimeError("stop")

    monkeypatch.setattr(SQPSolver, "_run", probe)
    try:
        sqp_module.solve_sqp(object())
    except RuntimeError:
        pass
    assert seen and all(n == 1 for n in seen[0])
    assert _blas_threads() == before
