"""The SQP subproblem: DPP, compiled once per structure, warm starts cut OSQP iterations."""

import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.behaviors import Models, build_segment, flat_pose
from flipkit.config import CellConfig
from flipkit.ik import solve_pose
from flipkit.qp import QPSubproblem, subproblem_for


@pytest.fixture(scope="module")
def setup():
    models = Models(CellConfig())
    qs = solve_pose(models.loaded, (0.64, -0.33, 0.15), (0, 0, 0))
    a = build_segment("translate", models, qs, goal=flat_pose((0.75, 0.0, 0.15)))
    b = build_segment("translate", models, qs, goal=flat_pose((0.70, -0.1, 0.16)))
    return a, b


def _load(qp, nlp, x, grad_scale=1.0, prox=1e-2):
    D = nlp.x_scale
    c, jac = nlp.evaluate(x)
    qp.update(nlp, nlp.c_scale * c, jac * nlp.c_scale[nlp.jac_rows] * D[nlp.jac_cols],
              grad_scale * nlp.gradient(x) * nlp.obj_scale * D,
              nlp.hessian_diagonal() * nlp.obj_scale * D**2 + prox,
              np.maximum((nlp.x_lb - x) / D, -0.5), np.minimum((nlp.x_ub - x) / D, 0.5), 10.0)
    return c, jac


def test_shared_structure_shares_one_compiled_problem(setup):
    a, b = setup
    assert a.structure_key == b.structure_key
    assert subproblem_for(a) is subproblem_for(b)
    assert subproblem_for(a).problem.is_dpp()


def test_step_satisfies_linearised_constraints(setup):
    a, _ = setup
    qp = QPSubproblem(a)
    c, jac = _load(qp, a, a.x0)
    sol = qp.solve()
    assert sol.status == "optimal"
    J = sp.csr_matrix((jac * a.c_scale[a.jac_rows] * a.x_scale[a.jac_cols],
                       (a.jac_rows, a.jac_cols)), shape=(a.m, a.n))
    lin = a.c_scale * c + J @ sol.d
    eq = a.c_lo == a.c_hi
    assert np.abs(lin[eq] - (a.c_scale * a.c_lo)[eq]).max() < 1e-4
    assert np.all(np.abs(sol.d) <= 0.5 + 1e-6)


def test_warm_start_cuts_iterations(setup):
    a, _ = setup
    cold = QPSubproblem(a)
    _load(cold, a, a.x0)
    first = cold.solve().iterations
    _load(cold, a, a.x0, grad_scale=1.001)  # a nearby problem, same structure
    warm = cold.solve().iterations
    fresh = QPSubproblem(a)
    _load(fresh, a, a.x0, grad_scale=1.001)
    assert warm < fresh.solve().iterations and warm < first
