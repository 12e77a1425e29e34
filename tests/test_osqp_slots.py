"""The compact working set on row slots (flipkit.solvers.osqp_slots): OSQP set up once and
updated, the full QP's solution assembled from the slots, private columns included."""

import cvxpy as cp
import numpy as np
import osqp

from flipkit.solvers.osqp_driver import OSQPDriver, run_osqp
from flipkit.solvers.osqp_slots import MIN_SLOTS, RowSlots, _capacity
from flipkit.solvers.osqp_status import OSQPStatus


def _elastic(n_rows=60, r=4, seed=0):
    """A condensed-elastic-like QP: v (r, shared) and one slack per row (private), rows
    G v + s ≥ b, a box on v; ½‖v‖² + gᵀv + ½σ‖s‖²."""
    rng = np.random.default_rng(seed)
    v, s = cp.Variable(r, name="v"), cp.Variable(n_rows, name="s")
    G, b, g = cp.Parameter((n_rows, r)), cp.Parameter(n_rows), cp.Parameter(r)
    sigma = cp.Parameter(nonneg=True)
    G.value, g.value, sigma.value = rng.standard_normal((n_rows, r)), rng.standard_normal(r), 50.0
    b.value = rng.standard_normal(n_rows) - 1.0  # most rows slack at v = 0
    cons = [G @ v + s >= b, v <= 1.0, v >= -1.0]
    obj = 0.5 * cp.sum_squares(v) + g @ v + 0.5 * sigma * cp.sum_squares(s)
    return cp.Problem(cp.Minimize(obj), cons), (v, s), (G, b, g, sigma), rng


def test_capacity_is_a_power_of_two_from_the_minimum():
    assert _capacity(0) == _capacity(MIN_SLOTS) == MIN_SLOTS
    assert _capacity(MIN_SLOTS + 1) == 2 * MIN_SLOTS and _capacity(100) == 128


def test_slacks_are_private_and_v_shared():
    problem, _, _, _ = _elastic()
    driver = OSQPDriver(problem, compact=True)
    P, A, *_ = driver._data()
    slots = RowSlots(P, A)
    assert len(slots.shared) == 4 and len(slots.private) == 60 and slots.K == 1


def test_the_compact_driver_solves_as_cvxpy_and_sets_osqp_up_once(monkeypatch):
    """Five solves at new values, each in several working-set rounds: one OSQP setup per
    capacity used, and every solution (primal and the rows' duals) is cvxpy's own."""
    setups = []
    original = osqp.OSQP.setup
    monkeypatch.setattr(osqp.OSQP, "setup",
                        lambda self, *a, **k: setups.append(a[2].shape[0]) or original(self, *a, **k))
    problem, (v, s), (G, b, g, sigma), rng = _elastic()
    driver = OSQPDriver(problem, compact=True)
    for k in range(5):
        G.value = G.value + 0.1 * rng.standard_normal(G.shape)
        g.value = rng.standard_normal(4)
        res, iterations, status, solved = run_osqp(driver, problem, 1e-9, None)
        assert solved and status == "optimal"
        got = v.value.copy(), s.value.copy(), problem.constraints[0].dual_value.copy()
        monkeypatch.setattr(osqp.OSQP, "setup", original)
        problem.solve(solver=cp.OSQP, eps_abs=1e-10, eps_rel=1e-10, max_iter=100000)
        monkeypatch.setattr(osqp.OSQP, "setup", lambda self, *a, **kw: setups.append(
            a[2].shape[0]) or original(self, *a, **kw))
        np.testing.assert_allclose(got[0], v.value, atol=1e-6)
        np.testing.assert_allclose(got[1], s.value, atol=1e-6)
        np.testing.assert_allclose(got[2], problem.constraints[0].dual_value, atol=1e-5)
    assert len(setups) == len(set(setups)) >= 1  # one setup per capacity (slots), no more
    assert all(c in (16, 32, 64, 128) for c in setups)


def test_a_primal_infeasible_working_set_is_reported_by_name():
    x = cp.Variable(2)
    lo = cp.Parameter(2)
    lo.value = np.array([2.0, 0.0])
    problem = cp.Problem(cp.Minimize(cp.sum_squares(x)), [x >= lo, x <= 1.0])
    driver = OSQPDriver(problem, compact=True)
    res, _, status, solved = run_osqp(driver, problem, 1e-6, None)
    assert not solved and status == "infeasible"
    assert res.info.status_val == OSQPStatus.OSQP_PRIMAL_INFEASIBLE


def test_the_sqp_sets_osqp_up_once_per_form_and_capacity(monkeypatch):
    """A whole SQP solve: far fewer OSQP setups than QP solves (the working-set rounds
    update the solver set up on the solve's first QP)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from sqp_reference import reference_nlp

    from flipkit.solvers.sqp_solver import SQPSolver

    setups, solves = [], []
    setup, solve = osqp.OSQP.setup, osqp.OSQP.solve
    monkeypatch.setattr(osqp.OSQP, "setup", lambda self, *a, **k: setups.append(
        a[2].shape) or setup(self, *a, **k))
    monkeypatch.setattr(osqp.OSQP, "solve", lambda self, *a, **k: solves.append(1) or solve(
        self, *a, **k))
    solver = SQPSolver()
    res = solver.solve(reference_nlp())
    assert res.success
    assert len(solves) > 2 * res.iterations  # several rounds per QP
    assert len(setups) == len(set(setups)) <= 4  # one per form and capacity
