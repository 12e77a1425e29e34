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


def _constant_row_problem(u_shift=0.0):
    """A condensed turn-back QP (tests/data/qp_constant_row.npz: min ½‖v‖² + qᵀv s.t.
    A v ≤ u, 19 variables, 16 rows) whose row 9 is numerically zero (norm 1e-15) at its bound
    (u = −2e-32): a row the equality rows fix, left by round-off."""
    import cvxpy as cp
    from pathlib import Path

    data = np.load(Path(__file__).parent / "data" / "qp_constant_row.npz")
    v = cp.Variable(19)
    A, u, q = cp.Parameter((16, 19)), cp.Parameter(16), cp.Parameter(19)
    A.value, q.value = data["A"], data["q"]
    u.value = data["u"] + u_shift * (np.arange(16) == 9)
    problem = cp.Problem(cp.Minimize(0.5 * cp.sum_squares(v) + q @ v), [A @ v <= u])
    return problem, v, data


def test_a_constant_row_is_left_out_of_the_working_set():
    """With the constant row in its working set OSQP's ADMM blows up and reports the QP
    primal infeasible (at eps 1e-6; the zero step is feasible). Left out, the driver solves
    it, and its solution is OSQP's on the other rows."""
    from flipkit.solvers import osqp_driver as D

    problem, v, data = _constant_row_problem()
    assert np.linalg.norm(data["A"][9]) < 1e-14 and abs(data["u"][9]) < 1e-30
    driver = D.OSQPDriver(problem, compact=True)
    _, _, status, solved = D.run_osqp(driver, problem, 1e-6, None)
    assert solved, status
    keep = np.arange(16) != 9
    ref = osqp.OSQP(algebra="builtin")
    ref.setup(sp.csc_matrix(np.eye(19)), data["q"], sp.csc_matrix(data["A"][keep]),
              -np.inf * np.ones(15), data["u"][keep], eps_abs=1e-9, eps_rel=1e-9, verbose=False)
    np.testing.assert_allclose(v.value, ref.solve(raise_error=False).x, atol=1e-5)


def test_a_constant_row_that_fails_at_zero_stays_in():
    """A constant row whose bound no step can meet (0 ≤ −1) is not left out: the QP is
    infeasible, and the driver says so."""
    from flipkit.solvers import osqp_driver as D

    problem, _, _ = _constant_row_problem(u_shift=-1.0)
    driver = D.OSQPDriver(problem, compact=True)
    _, _, status, solved = D.run_osqp(driver, problem, 1e-6, None)
    assert not solved and "infeasible" in status, status
