"""OSQP's unconditional C print ("Polishing not needed ...") never reaches flipkit's stdout."""

import numpy as np
import osqp
import scipy.sparse as sp

from flipkit.solvers.stdout_redirect import _LIBC, c_stdout_silenced

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


def test_the_persistent_solver_adds_every_violated_row_in_one_round(monkeypatch):
    """min ½‖x − 3‖² s.t. x ≤ 1 (30 rows, a sparse Parameter: the persistent solver). No row is
    near its bound at x = 0, so the first round holds none of them (only cvxpy's equality
    rows); its optimum violates all 30, and the second round holds them all (ten per round
    would take four rounds)."""
    import cvxpy as cp

    from flipkit.solvers import osqp_driver as D

    n = 30
    x = cp.Variable(n)
    A = cp.Parameter((n, n), sparsity=(np.arange(n), np.arange(n)))
    A.value_sparse = sp.coo_array((np.ones(n), (np.arange(n), np.arange(n))), shape=(n, n))
    problem = cp.Problem(cp.Minimize(0.5 * cp.sum_squares(x - 3.0)), [A @ x <= 1.0])
    driver = D.OSQPDriver(problem)
    assert not driver.compact and driver._map is None
    rounds = []
    original = D.OSQPDriver._solve_persistent
    monkeypatch.setattr(D.OSQPDriver, "_solve_persistent",
                        lambda self, *a: rounds.append(a[5].sum()) or original(self, *a))
    res, _, status, solved = D.run_osqp(driver, problem, 1e-8, None)
    assert solved and len(rounds) == 2 and rounds[1] - rounds[0] == n
    np.testing.assert_allclose(x.value, 1.0, atol=1e-6)
