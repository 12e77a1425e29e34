"""IPOPT cross-check solver (flipkit.solvers.ipopt) on the translate segment."""

import copy

import casadi as ca
import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.behaviors.models import Models
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.config import CellConfig
from flipkit.errors import NoSolutionFound
from flipkit.model.ik import solve_pose
from flipkit.solvers.ipopt import IpoptOptions, IpoptResult, _ConstraintCallback, _EvalCache, solve_ipopt
from flipkit.solvers.sqp import SolveResult


@pytest.fixture(scope="module")
def translate_nlp():
    models = Models(CellConfig())
    qs = solve_pose(models.loaded, (0.64, -0.33, 0.15), (0, 0, 0))
    return transcribe("translate", models, qs, goal=flat_pose((0.75, 0.0, 0.15)))


@pytest.fixture(scope="module")
def translate_result(translate_nlp):
    return solve_ipopt(translate_nlp)


def _with_T_bounds(nlp, lo, hi):
    """Shallow copy of ``nlp`` with the duration bounds replaced (s)."""
    bad = copy.copy(nlp)
    iT = nlp.layout.T_index
    bad.x_lb, bad.x_ub = nlp.x_lb.copy(), nlp.x_ub.copy()
    bad.x_lb[iT], bad.x_ub[iT] = lo, hi
    bad.x0 = np.clip(nlp.x0, np.minimum(bad.x_lb, bad.x_ub), bad.x_ub)
    return bad


def test_callback_jacobian_matches_nlp(translate_nlp):
    """CasADi's Jacobian of the constraint callback is the NLP's, scaled, on its pattern."""
    nlp = translate_nlp
    cb = _ConstraintCallback("c", _EvalCache(nlp))
    z = ca.MX.sym("z", nlp.n)
    jac_fun = ca.Function("J", [z], [ca.jacobian(cb(z), z)])
    z0 = nlp.x0 / nlp.x_scale
    J_ca = jac_fun(z0).sparse()
    c, jac = nlp.evaluate(nlp.x0)
    values = jac * nlp.c_scale[nlp.jac_rows] * nlp.x_scale[nlp.jac_cols]
    J_ref = sp.csc_matrix((values, (nlp.jac_rows, nlp.jac_cols)), shape=(nlp.m, nlp.n))
    assert abs(J_ca - J_ref).max() <= 1e-12 * abs(J_ref).max()
    assert jac_fun.sparsity_out(0).nnz() == len(nlp.jac_rows)  # not densified
    np.testing.assert_allclose(np.asarray(cb(z0)).ravel(), nlp.c_scale * c, rtol=1e-12, atol=1e-12)


def test_translate_solves(translate_nlp, translate_result):
    nlp, r = translate_nlp, translate_result
    assert isinstance(r, IpoptResult) and isinstance(r, SolveResult)
    assert r.success and r.status == "solved" and r.solver == "ipopt"
    assert r.return_status in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
    groups = nlp.violation_by_group(r.x)  # independent feasibility check
    assert max(groups.values()) <= 1e-6, groups
    assert r.max_violation <= 1e-6
    assert np.all(r.x >= nlp.x_lb) and np.all(r.x <= nlp.x_ub)
    assert r.objective == pytest.approx(nlp.objective(r.x))
    assert r.objective < nlp.objective(nlp.x0)
    assert 0 < r.iterations == len(r.log) - 1
    assert r.log[-1]["inf_pr"] <= 1e-6 and r.wall_time_s > 0
    assert r.evaluations <= 3 * (r.iterations + 1)  # c and J at a point share one evaluation


def test_deliberately_infeasible_raises(translate_nlp):
    """T fixed at 50 ms: the end pose cannot be reached within the joint limits."""
    bad = _with_T_bounds(translate_nlp, 0.05, 0.05)
    with pytest.raises(NoSolutionFound) as info:
        solve_ipopt(bad, options=IpoptOptions(max_iter=300))
    err = info.value
    assert err.status != "solved" and err.status == err.result.return_status
    assert err.group in bad.violation_by_group(err.result.x)
    assert err.amount > 1e-6 and err.problem is bad


def test_crossed_bounds_raise_without_calling_ipopt(translate_nlp):
    bad = _with_T_bounds(translate_nlp, 0.6, 0.05)
    with pytest.raises(NoSolutionFound) as info:
        solve_ipopt(bad)
    assert info.value.status == "inconsistent_bounds" and info.value.group == "bounds"
    assert info.value.amount == pytest.approx(0.55)


def test_failure_returned_when_not_raising(translate_nlp):
    r = solve_ipopt(translate_nlp, options=IpoptOptions(max_iter=2), raise_on_failure=False)
    assert not r.success and r.status == "Maximum_Iterations_Exceeded" and r.iterations == 2
