"""flipkit reads cvxpy's compiled problem in one module (flipkit.solvers.cvxpy_adapter),
written against the cvxpy that environment.lock pins."""

import re
from pathlib import Path

import cvxpy as cp
import numpy as np

from flipkit.solvers import cvxpy_adapter as adapter
from flipkit.solvers.osqp_status import SOLVED, UNPACKED, OSQPStatus

ROOT = Path(__file__).resolve().parents[1]


def test_the_adapter_is_written_for_the_locked_cvxpy():
    pinned = re.search(r"^cvxpy==(\S+)", (ROOT / "environment.lock").read_text(), re.M)
    assert pinned and pinned.group(1) == adapter.CVXPY_VERSION == cp.__version__


def test_no_other_module_reads_cvxpys_internals():
    """The private import, the parametrised program and the value setters appear in the
    adapter alone."""
    internals = ("cvxpy.reductions", "param_prob", "PARAM_PROB", "param_id_to_col",
                 "sparse_idx", "save_value", "save_dual_value", "STATUS_MAP")
    offenders = []
    for path in (ROOT / "flipkit").rglob("*.py"):
        if path.name == "cvxpy_adapter.py":
            continue
        text = path.read_text()
        offenders += [(path.name, word) for word in internals if word in text]
    assert offenders == []


def _problem():
    x = cp.Variable(3, name="x")
    G, h, g = cp.Parameter((2, 3)), cp.Parameter(2), cp.Parameter(3)
    E = cp.Parameter((1, 3))
    problem = cp.Problem(cp.Minimize(cp.sum_squares(x) + g @ x), [G @ x <= h, E @ x == 1.0])
    rng = np.random.default_rng(0)
    for prm in (G, h, g, E):
        prm.value = rng.uniform(0.5, 1.5, prm.shape)
    return problem, (G, h, g, E)


def test_the_affine_program_covers_every_parameter_and_the_osqp_data():
    problem, params = _problem()
    data, chain, inverse = adapter.problem_data(problem)
    prog = adapter.affine_program(data)
    assert set(prog.columns) == {prm.id for prm in params}
    assert prog.size == sum(prm.size for prm in params) + 1
    P, A, q, l, u = adapter.osqp_form(data)
    assert prog.n == P.shape[0] == A.shape[1] == len(q)
    assert prog.n_eq == data["A"].shape[0] == int(np.sum(l == u))
    assert prog.A.shape[0] == A.shape[0] * (prog.n + 1)
    # the tensors give cvxpy's data: q at the parameters' values
    p = np.zeros(prog.size)
    p[-1] = 1.0
    for prm in params:
        p[prog.columns[prm.id]:prog.columns[prm.id] + prm.size] = prm.value.ravel(order="F")
    np.testing.assert_allclose((prog.q @ p)[:prog.n], q, atol=1e-12)


def test_status_names_are_cvxpys():
    assert adapter.status_name(OSQPStatus.OSQP_SOLVED) == cp.OPTIMAL
    assert adapter.status_name(OSQPStatus.OSQP_SOLVED_INACCURATE) == cp.OPTIMAL_INACCURATE
    assert adapter.status_name(OSQPStatus.OSQP_PRIMAL_INFEASIBLE) == cp.INFEASIBLE
    assert (adapter.status_name(OSQPStatus.OSQP_PRIMAL_INFEASIBLE_INACCURATE)
            == cp.INFEASIBLE_INACCURATE)
    assert SOLVED < UNPACKED and OSQPStatus.OSQP_MAX_ITER_REACHED not in UNPACKED
