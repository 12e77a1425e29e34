import os

os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("MUJOCO_GL", "osmesa")  # offscreen rendering (flipkit.simulation.animate)

import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.config import CellConfig
from flipkit.model.robot import Robot


# Scope "package": the tests/ directory (not a package), so once per test run.
@pytest.fixture(scope="package")
def cell():
    return CellConfig()


@pytest.fixture(scope="package")
def robot(cell):
    return Robot(cell, with_burger=True)


def central_fd(fun, x, h=1e-6):
    """Central finite-difference Jacobian of fun at x (columns: ∂/∂x_k)."""
    x = np.asarray(x, dtype=float)
    cols = []
    for k in range(x.size):
        e = np.zeros_like(x)
        e[k] = h
        cols.append((np.asarray(fun(x + e)) - np.asarray(fun(x - e))) / (2 * h))
    return np.stack(cols, axis=-1)


def check_block_jacobian(nlp, block, seed: int, T: float = 0.5):
    """A block's Jacobian entries against central finite differences of its values, at the
    NLP's initial guess moved by 0.05 σ noise (``seed``) in every node variable, duration T.
    Returns the block's values there."""
    from flipkit.transcription.layout import Evaluation

    rng = np.random.default_rng(seed)
    x = nlp.x0 + 0.05 * rng.standard_normal(nlp.n) * (np.arange(nlp.n) < nlp.layout.alpha_start)
    x[nlp.layout.T_index] = T
    vals, entries = block.evaluate(Evaluation(nlp.layout, nlp.robot, x))
    J = np.zeros((block.m, nlp.n))
    np.add.at(J, (block.rows, block.cols), entries)
    cols = np.unique(block.cols)

    def values(z):
        y = x.copy()
        y[cols] = z
        return block.evaluate(Evaluation(nlp.layout, nlp.robot, y))[0]

    np.testing.assert_allclose(J[:, cols], central_fd(values, x[cols]), atol=1e-6, rtol=1e-6)
    return vals


def random_states(robot, seed, n=5):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        q = robot.q_home + rng.uniform(-0.6, 0.6, robot.nq)
        yield q, rng.uniform(-1.5, 1.5, robot.nq), rng.uniform(-5, 5, robot.nq)


@pytest.fixture(scope="package")
def flip_plan():
    """One solved SQP flip plan at a Table I location, planned once per test run (≈ 5 s).

    ``FLIPKIT_TEST_PLAN=path.json`` reuses a plan file instead (e.g. while iterating on the
    simulation side); the default plans it with the current planner.
    """
    from flipkit.planning.plans.plan_file import Plan
    from flipkit.planning.planners.planner import plan_flip

    path = os.environ.get("FLIPKIT_TEST_PLAN")
    plan = Plan.load(path) if path else plan_flip((0.69, -0.16, 0.072))
    assert plan.status == "solved", plan.failure
    return plan


@pytest.fixture(scope="package")
def flip_plan_file(flip_plan, tmp_path_factory):
    return flip_plan.to_json(tmp_path_factory.mktemp("flip_plan") / "plan.json")


def linearise(nlp, box=1.0):
    """Scaled c, entries, J, gradient, Hessian (with a proximal weight) and step box at the
    projected initial guess."""
    x = nlp.project(nlp.x0)
    D = nlp.x_scale
    c, jac = nlp.evaluate(x)
    entries = jac * nlp.c_scale[nlp.jac_rows] * D[nlp.jac_cols]
    J = sp.csr_matrix((entries, (nlp.jac_rows, nlp.jac_cols)), shape=(nlp.m, nlp.n))
    g = nlp.gradient(x) * nlp.obj_scale * D
    h = nlp.hessian_diagonal() * nlp.obj_scale * D**2 + 1e-3
    lo, hi = np.maximum((nlp.x_lb - x) / D, -box), np.minimum((nlp.x_ub - x) / D, box)
    return nlp.c_scale * c, entries, J, g, h, lo, hi
