"""OSQP's unconditional C print ("Polishing not needed ...") never reaches flipkit's stdout."""

import numpy as np
import osqp
import scipy.sparse as sp

from flipkit.solvers.osqp_driver import _LIBC, c_stdout_silenced

MESSAGE = "Polishing not needed"


def _solve_without_active_rows():
    """min ½‖x‖² s.t. −1 ≤ x ≤ 1: optimum 0, no active row, so the polish step prints."""
    solver = osqp.OSQP()
    solver.setup(sp.csc_matrix(np.eye(2)), np.zeros(2), sp.csc_matrix(np.eye(2)),
                 -np.ones(2), np.ones(2), polishing=True, verbose=False)
    return solver.solve(raise_error=False)


def test_osqp_prints_without_the_guard(capfd):
    _solve_without_active_rows()
    _LIBC.fflush(None)
    assert MESSAGE in capfd.readouterr().out  # the guard below has something to silence


def test_the_guard_silences_c_but_not_python(capfd):
    with c_stdout_silenced():
        res = _solve_without_active_rows()
    print("python output")
    _LIBC.fflush(None)
    out = capfd.readouterr().out
    assert MESSAGE not in out and "python output" in out
    assert np.allclose(res.x, 0.0)
