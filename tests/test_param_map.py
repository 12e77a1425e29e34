"""cvxpy's parameter map applied directly (flipkit.solvers.param_map) gives cvxpy's own OSQP
data, and the driver's working set stays small."""

import cvxpy as cp
import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.errors import SolverError
from flipkit.solvers.osqp_driver import OSQPDriver, _capped, run_osqp
from flipkit.solvers.param_map import ParameterMap


def _problem():
    """A DPP QP with every kind of row: equalities, one-sided rows of both signs, a
    parametric quadratic weight and a constant."""
    x = cp.Variable(4, name="x")
    G, b, g, w, E, e = (cp.Parameter((5, 4)), cp.Parameter(5), cp.Parameter(4),
                        cp.Parameter(4, nonneg=True), cp.Parameter((2, 4)), cp.Parameter(2))
    cons = [G @ x <= b, x >= -b[:4] - 1.0, E @ x == e]
    obj = 0.5 * cp.sum(cp.multiply(w, cp.square(x))) + g @ x + 3.0
    return cp.Problem(cp.Minimize(obj), cons), (G, b, g, w, E, e), x


def _set(params, rng):
    for prm in params:
        prm.value = rng.uniform(0.2, 2.0, prm.shape)


def test_the_map_reproduces_cvxpys_data_at_new_values():
    problem, params, _ = _problem()
    rng = np.random.default_rng(7)
    _set(params, rng)
    pmap = ParameterMap(problem, problem.get_problem_data(cp.OSQP)[0])
    for _ in range(3):
        _set(params, rng)
        P, A, q, l, u = pmap.data()
        ref = problem.get_problem_data(cp.OSQP)[0]
        np.testing.assert_allclose(P.toarray(), sp.triu(ref["P"]).toarray(), atol=1e-12)
        np.testing.assert_allclose(A.toarray(), sp.vstack([ref["A"], ref["F"]]).toarray(),
                                   atol=1e-12)
        np.testing.assert_allclose(q, ref["q"], atol=1e-12)
        np.testing.assert_allclose(u, np.concatenate([ref["b"], ref["G"]]), atol=1e-12)
        assert np.all(np.isneginf(l[len(ref["b"]):]))
        np.testing.assert_allclose(l[:len(ref["b"])], ref["b"], atol=1e-12)


def test_the_pattern_is_fixed_whatever_the_values():
    """Zeros in the values keep their slots: ``osqp.update`` needs the setup's pattern."""
    problem, params, _ = _problem()
    _set(params, np.random.default_rng(0))
    pmap = ParameterMap(problem, problem.get_problem_data(cp.OSQP)[0])
    nnz = pmap.data()[1].nnz
    params[0].value = np.zeros((5, 4))
    assert pmap.data()[1].nnz == nnz


def test_the_driver_solves_as_cvxpy_does():
    problem, params, x = _problem()
    _set(params, np.random.default_rng(3))
    problem.solve(solver=cp.CLARABEL)
    reference = x.value.copy()
    driver = OSQPDriver(problem, compact=True)
    assert driver._map is not None
    _, _, status, solved = run_osqp(driver, problem, 1e-9, None)
    assert solved, status
    np.testing.assert_allclose(x.value, reference, atol=1e-6)


@pytest.mark.filterwarnings("ignore:Reading from a sparse")
def test_sparse_parameters_are_refused():
    x = cp.Variable(3)
    J = cp.Parameter((2, 3), sparsity=([0, 1], [0, 2]))
    J.value_sparse = sp.coo_array(([1.0, 2.0], ([0, 1], [0, 2])), shape=(2, 3))
    problem = cp.Problem(cp.Minimize(cp.sum_squares(x)), [J @ x <= 1])
    with pytest.raises(SolverError, match="dense parameters"):
        ParameterMap(problem, problem.get_problem_data(cp.OSQP)[0])


def test_the_working_set_is_capped_by_priority():
    rows = np.array([True, True, False, True, True])
    first = np.array([0.0, -2.0, -9.0, -1.0, 0.0])
    then = np.array([0.5, 0.0, 0.0, 0.0, 0.1])
    kept = _capped(rows, first, then, 3)
    assert kept.tolist() == [False, True, False, True, True]  # -2, -1, then the smaller `then`
    assert _capped(rows, first, then, 9) is rows


def test_assigned_values_take_the_place_of_dot_value():
    problem, params, _ = _problem()
    rng = np.random.default_rng(5)
    _set(params, rng)
    pmap = ParameterMap(problem, problem.get_problem_data(cp.OSQP)[0])
    new = {prm: rng.uniform(0.2, 2.0, prm.shape) for prm in params}
    for prm, value in new.items():
        pmap.assign(prm, value)
    assigned = pmap.data()
    for prm, value in new.items():
        prm.value = value
    expected = pmap.__class__(problem, problem.get_problem_data(cp.OSQP)[0]).data()
    for got, want in zip(assigned, expected):
        got = got.toarray() if sp.issparse(got) else got
        want = want.toarray() if sp.issparse(want) else want
        np.testing.assert_allclose(got, want, atol=1e-12)
    with pytest.raises(SolverError, match="cannot assign"):
        pmap.assign(params[0], np.zeros(3))
