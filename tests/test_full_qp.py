"""The SQP subproblem: DPP, compiled once per structure, exact multipliers, the working set
returns the full QP's solution, warm starts cut OSQP iterations."""

import warnings

import cvxpy as cp
import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.behaviors.models import Models
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.config import CellConfig
from flipkit.model.ik import solve_pose
from flipkit.solvers.compiled import SQPWorkspace
from flipkit.solvers.full_qp import QPSubproblem


@pytest.fixture(scope="module")
def setup():
    models = Models(CellConfig())
    qs = solve_pose(models.loaded, (0.64, -0.33, 0.15), (0, 0, 0))
    a = transcribe("translate", models, qs, goal=flat_pose((0.75, 0.0, 0.15)))
    b = transcribe("translate", models, qs, goal=flat_pose((0.70, -0.1, 0.16)))
    return a, b


def _scaled(nlp, x):
    """Scaled c, Jacobian entries (pattern order), J, cost gradient and Hessian diagonal."""
    D = nlp.x_scale
    c, jac = nlp.evaluate(x)
    entries = jac * nlp.c_scale[nlp.jac_rows] * D[nlp.jac_cols]
    J = sp.csr_matrix((entries, (nlp.jac_rows, nlp.jac_cols)), shape=(nlp.m, nlp.n))
    return nlp.c_scale * c, entries, J, nlp.gradient(x) * nlp.obj_scale * D, \
        nlp.hessian_diagonal() * nlp.obj_scale * D**2 + 1e-4


def _load(qp, nlp, x, grad_scale=1.0, box=0.5):
    c, entries, J, g, h = _scaled(nlp, x)
    D = nlp.x_scale
    qp.update(nlp, c, entries, grad_scale * g, h,
              np.maximum((nlp.x_lb - x) / D, -box), np.minimum((nlp.x_ub - x) / D, box))
    return c, J, g, h


def test_shared_structure_shares_one_compiled_problem(setup):
    a, b = setup
    assert a.structure_key == b.structure_key
    ws = SQPWorkspace()
    assert ws.get(a) is ws.get(b)
    assert ws.get(a).problem.is_dpp()
    assert SQPWorkspace().get(a) is not ws.get(a)  # a workspace's compiled problems are its own


def test_step_satisfies_linearised_constraints_and_kkt(setup):
    """Hard rows hold to OSQP's tolerance and the multipliers close the KKT system:
    g + H d + Jᵀy = 0 on the variables whose box is inactive."""
    a, _ = setup
    qp = QPSubproblem(a)
    x = a.project(a.x0)
    c, J, g, h = _load(qp, a, x, box=10.0)
    # eps 1e-9 on the full-space QP of a translate (with the arm's clearance and pitch rows)
    # takes OSQP ~10⁴ ADMM iterations: more than its default cap
    sol = qp.solve(eps=1e-9, max_iter=100_000)
    assert sol.status == "optimal"
    lin = c + J @ sol.d
    lo, hi = a.c_scale * a.c_lo, a.c_scale * a.c_hi
    assert np.all(lin >= lo - 1e-7) and np.all(lin <= hi + 1e-7)
    d_lo, d_hi = qp.d_lo.value, qp.d_hi.value
    free = (sol.d > d_lo + 1e-6) & (sol.d < d_hi - 1e-6)
    stationarity = g + h * sol.d + J.T @ sol.multipliers
    assert free.sum() > a.n / 2
    assert np.abs(stationarity[free]).max() < 1e-6 * max(1.0, np.abs(g).max())
    y = sol.multipliers  # signs: ≥ 0 at upper bounds, ≤ 0 at lower bounds, 0 when inactive
    ineq = a.c_lo != a.c_hi
    assert np.all(y[ineq & (lin > lo + 1e-6) & (lin < hi - 1e-6)] == pytest.approx(0, abs=1e-8))


def test_working_set_solution_is_the_full_qp_solution(setup):
    """The driver hands OSQP only a working set of inequality rows after the first solve;
    the result must equal cvxpy's own OSQP solve of the whole problem."""
    a, _ = setup
    qp = QPSubproblem(a)
    x = a.project(a.x0)
    _load(qp, a, x)
    qp.solve(eps=1e-9)  # first solve fixes a working set
    x2 = a.project(x + 0.02 * a.x_scale * np.sin(np.arange(a.n)))  # a nearby linearisation
    _load(qp, a, x2)
    sol = qp.solve(eps=1e-9)
    assert qp._driver._active.sum() < 0.1 * len(qp._driver._active)  # a small working set
    with warnings.catch_warnings():  # cvxpy reads sparse parameters through `.value`
        warnings.filterwarnings("ignore", "Reading from a sparse", RuntimeWarning)
        qp.problem.solve(solver=cp.OSQP, eps_abs=1e-9, eps_rel=1e-9, max_iter=200000)
    ref = qp.problem.value
    _, _, J, g, h = _scaled(a, x2)
    value = g @ sol.d + 0.5 * sol.d @ (h * sol.d)
    assert value == pytest.approx(ref, rel=1e-5, abs=1e-9)


def test_warm_start_cuts_iterations(setup):
    a, _ = setup
    warm = QPSubproblem(a)
    _load(warm, a, a.x0)
    first = warm.solve().iterations
    _load(warm, a, a.x0, grad_scale=1.001)  # a nearby problem, same structure
    again = warm.solve().iterations
    fresh = QPSubproblem(a)
    _load(fresh, a, a.x0, grad_scale=1.001)
    assert again < fresh.solve().iterations and again < first
