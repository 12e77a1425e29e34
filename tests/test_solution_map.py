"""OSQP's solution reaches the cvxpy variables and duals through a precomputed signed selection
(flipkit.solvers.solution_map) exactly as through cvxpy's own unpacking."""

import types

import cvxpy as cp
import numpy as np
import osqp
import pytest
import scipy.sparse as sp

from flipkit.errors import SolverError
from flipkit.solvers.osqp_driver import OSQPDriver, run_osqp
from flipkit.solvers.param_map import osqp_form
from flipkit.solvers.solution_map import SolutionMap


def _problem():
    """A DPP QP with a matrix variable, equalities and one-sided rows of both signs."""
    x, Y = cp.Variable(3, name="x"), cp.Variable((2, 2), name="Y")
    G, b, e = cp.Parameter((4, 3)), cp.Parameter(4), cp.Parameter(2)
    cons = [G @ x <= b, x >= -1.0, cp.sum(Y, axis=0) == e, Y >= -b[:2, None] @ np.ones((1, 2))]
    obj = 0.5 * cp.sum_squares(x) + cp.sum_squares(Y) + cp.sum(x) - cp.sum(Y)
    rng = np.random.default_rng(5)
    for prm in (G, b, e):
        prm.value = rng.uniform(0.2, 2.0, prm.shape)
    return cp.Problem(cp.Minimize(obj), cons), (x, Y)


def _solve_osqp(problem):
    data, chain, inverse = problem.get_problem_data(cp.OSQP)
    P, A, q, l, u = osqp_form(data)
    P, A = (sp.csc_matrix((M.data, M.indices.astype(np.int32), M.indptr.astype(np.int32)),
                          shape=M.shape) for M in (P, A))  # OSQP takes 32-bit indices
    solver = osqp.OSQP(algebra="builtin")
    solver.setup(P, q, A, l, u, verbose=False, eps_abs=1e-9, eps_rel=1e-9, polishing=True)
    return solver.solve(raise_error=False), chain, inverse, A.shape


def test_the_map_stores_what_cvxpy_stores_bit_for_bit():
    problem, variables = _problem()
    res, chain, inverse, (m, n) = _solve_osqp(problem)
    assert res.info.status_val == 1
    smap = SolutionMap(problem, chain, inverse, n, m)
    assert smap.apply(res) == "optimal"
    mine = [v.value.copy() for v in variables] + [np.array(c.dual_value, float).copy()
                                                  for c in problem.constraints]
    problem.unpack_results(res, chain, inverse)
    ref = [v.value for v in variables] + [np.array(c.dual_value, float)
                                          for c in problem.constraints]
    assert problem.status == "optimal"
    for a, b in zip(mine, ref):
        assert a.shape == b.shape and np.array_equal(a, b)
    # the rows of both signs and the equalities are all in: some duals are nonzero
    assert sum(np.any(d != 0) for d in mine[len(variables):]) >= 2


def test_an_unsolved_result_is_refused():
    problem, _ = _problem()
    res, chain, inverse, (m, n) = _solve_osqp(problem)
    smap = SolutionMap(problem, chain, inverse, n, m)
    fake = types.SimpleNamespace(x=res.x, y=res.y, info=types.SimpleNamespace(
        status_val=3, status="primal infeasible"))
    with pytest.raises(SolverError, match="no solution to map"):
        smap.apply(fake)


def test_an_unpacking_that_is_not_a_selection_is_refused(monkeypatch):
    """If cvxpy ever scaled a value instead of selecting it, building the map says so."""
    problem, _ = _problem()
    res, chain, inverse, (m, n) = _solve_osqp(problem)
    real = cp.Problem.unpack_results

    def scaled(self, solution, chain, inverse):
        solution.x = 0.5 * solution.x
        return real(self, solution, chain, inverse)

    monkeypatch.setattr(cp.Problem, "unpack_results", scaled)
    with pytest.raises(SolverError, match="not a selection"):
        SolutionMap(problem, chain, inverse, n, m)


def test_the_compact_driver_reports_cvxpys_status_and_values():
    problem, (x, Y) = _problem()
    driver = OSQPDriver(problem, compact=True)
    res, _, status, solved = run_osqp(driver, problem, 1e-9, None)
    assert solved and status == driver.status == "optimal"
    got = x.value.copy(), Y.value.copy()
    problem.solve(solver=cp.OSQP, eps_abs=1e-9, eps_rel=1e-9)
    np.testing.assert_allclose(got[0], x.value, atol=1e-6)
    np.testing.assert_allclose(got[1], Y.value, atol=1e-6)


def test_the_driver_unpacks_through_cvxpy_when_the_map_cannot_be_built(monkeypatch):
    import flipkit.solvers.osqp_driver as driver_module

    def refuse(*args):
        raise SolverError("not a selection")

    monkeypatch.setattr(driver_module, "SolutionMap", refuse)
    problem, (x, Y) = _problem()
    driver = OSQPDriver(problem, compact=True)
    res, _, status, solved = run_osqp(driver, problem, 1e-9, None)
    assert solved and status == "optimal" and problem.status == "optimal"
    assert driver._solution_map is False
    # cvxpy unpacked it: the problem has a value (the map sets none)
    assert problem.value == pytest.approx(problem.objective.value, rel=1e-9)
