"""SQP convergence: feasibility, agreement with IPOPT, and the committed iteration log."""

import json

import numpy as np
import pytest
from sqp_reference import LOG_PATH, log_rows, run

from flipkit.errors import NoSolutionFound
from flipkit.solvers.ipopt import solve_ipopt
from flipkit.solvers.sqp import SQPOptions, solve_sqp


@pytest.fixture(scope="module")
def reference():
    return run()


def test_converges_to_a_feasible_point(reference):
    nlp, res = reference
    assert res.status == "solved"
    groups = nlp.violation_by_group(res.x)
    assert max(groups.values()) <= 1e-6, groups
    assert res.objective < 0.5 * nlp.objective(nlp.x0)  # the guess is far from optimal


def test_matches_ipopt_on_the_same_nlp(reference):
    """Both solvers on the very same NLP interface reach the same optimum within 1e-3
    (measured: SQP 10597.91 vs IPOPT 10597.28, 5.9e-5 relative)."""
    nlp, res = reference
    ip = solve_ipopt(nlp)
    assert ip.status == "solved"
    assert abs(res.objective - ip.objective) / ip.objective < 1e-3
    # and the same duration (the cost drives T to its upper bound)
    L = nlp.layout
    assert res.x[L.T_index] == pytest.approx(ip.x[L.T_index], abs=1e-4)


def test_iteration_log_matches_committed_log(reference):
    """A silent change in convergence shows up here (crocoddyl-style log check).

    Same iteration count and statuses; objective and merit to 1e-6 relative, violation to
    1e-9 absolute (OSQP is run with a fixed adaptive-rho interval, so solves repeat).
    """
    _, res = reference
    committed = json.loads(LOG_PATH.read_text())
    rows = log_rows(res)
    assert res.iterations == committed["iterations"]
    assert [r["qp_status"] for r in rows] == [r["qp_status"] for r in committed["log"]]
    for got, ref in zip(rows, committed["log"]):
        assert got["objective"] == pytest.approx(ref["objective"], rel=1e-6)
        assert got["merit"] == pytest.approx(ref["merit"], rel=1e-6)
        assert got["violation"] == pytest.approx(ref["violation"], abs=1e-9)


def test_failure_raises_with_group_and_amount(reference):
    nlp, _ = reference
    with pytest.raises(NoSolutionFound) as err:
        solve_sqp(nlp, options=SQPOptions(max_iter=2))
    assert err.value.group in nlp.violation_by_group(nlp.x0)
    assert err.value.status == "max_iter" and np.isfinite(err.value.amount)
    assert err.value.problem is nlp and err.value.result.iterations == 2


def test_projection_satisfies_the_dynamics_rows_exactly(reference):
    """u := RNEA(q, q̇, q̈) zeroes the dynamics rows at any point (the SQP projects every
    trial point) and leaves every other variable alone."""
    nlp, _ = reference
    rng = np.random.default_rng(3)
    x = np.clip(nlp.x0 + 0.05 * nlp.x_scale * rng.standard_normal(nlp.n), nlp.x_lb, nlp.x_ub)
    xp = nlp.project(x)
    rows = nlp.block_slices["dynamics"]
    assert np.abs(nlp.constraints(x)[rows]).max() > 1e-3
    assert np.abs(nlp.constraints(xp)[rows]).max() < 1e-9
    moved = np.flatnonzero(xp != x)
    assert set(moved) <= set(nlp.u_index)


def test_locally_infeasible_segment_stops_early_as_infeasible():
    """A goal half a metre below the grill: restoration steps stop reducing the violation and
    the solve ends as ``infeasible`` long before ``max_iter``, naming the end pose."""
    from sqp_reference import START

    from flipkit.behaviors.segments import Models, build_segment, flat_pose
    from flipkit.config import CellConfig
    from flipkit.model.ik import solve_pose

    models = Models(CellConfig())
    q_start = solve_pose(models.loaded, START, (0.0, 0.0, 0.0))
    nlp = build_segment("translate", models, q_start, goal=flat_pose((0.75, 0.0, -0.5)))
    with pytest.raises(NoSolutionFound) as err:
        solve_sqp(nlp)
    assert err.value.status == "infeasible" and err.value.group == "end_pose"
    assert err.value.result.iterations < SQPOptions().max_iter // 2
    assert err.value.amount > 0.1
    elastic = [row["elastic"] for row in err.value.result.log]
    assert all(elastic[-SQPOptions().stall_iterations:])


def test_sequential_solves_repeat_exactly(reference):
    """Results do not depend on what was solved before in the process (subproblem state,
    basis and warm starts are reset per solve)."""
    nlp, res = reference
    from sqp_reference import reference_nlp

    other = reference_nlp()
    solve_sqp(other, x0=other.x0 + 0.01 * other.x_scale, raise_on_failure=False)
    again = solve_sqp(nlp)
    assert np.array_equal(again.x, res.x) and again.iterations == res.iterations


def test_no_restoration_from_a_feasible_point():
    """At a feasible iterate the linearisation is feasible (d = 0 satisfies it), so the SQP
    must never fall back to restoration there. Regression: a warm start from the previous
    subproblem's duals made OSQP report a false infeasibility certificate at this go-to-
    burger segment, and the solve stalled at J = 15 838 instead of reaching 13 678."""
    from flipkit.behaviors.segments import Models, build_segment
    from flipkit.config import CellConfig

    models = Models(CellConfig())
    nlp = build_segment("go_to_burger", models, models.bare.q_home, np.zeros(6),
                        location=(0.677778, -0.17, 0.072))
    res = solve_sqp(nlp)
    feasible_before = [True] + [row["violation"] <= 1e-6 for row in res.log[:-1]]
    assert not any(row["elastic"] for row, ok in zip(res.log, feasible_before) if ok)
    assert res.objective == pytest.approx(solve_ipopt(nlp).objective, rel=1e-3)
