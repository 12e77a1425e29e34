"""The rows' curvature in the null space: the damped BFGS update, and the condensed QP with it."""

from types import SimpleNamespace

import numpy as np
import pytest
from conftest import linearise

from flipkit.behaviors.models import Models
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.config import CellConfig
from flipkit.model.ik import solve_pose
from flipkit.solvers.condensed_qp import CondensedQP
from flipkit.solvers.reduced_hessian import DAMPING, ReducedHessian
from flipkit.solvers.sqp import QPOptions, SQPOptions, TerminationOptions, solve_sqp


def _stub(n=7, r=3, seed=0):
    """A condensed-QP stand-in: a basis, free columns and Z = [−E_B⁻¹E_N; I]."""
    rng = np.random.default_rng(seed)
    free = np.sort(rng.choice(n, r, replace=False))
    Z = rng.standard_normal((n, r))
    Z[free] = np.eye(r)
    return SimpleNamespace(Z=Z, free=free, basis=np.setdiff1d(np.arange(n), free), curved=True)


def test_update_satisfies_the_secant_condition():
    """Without damping, B⁺ s = y: the reduced Hessian reproduces the measured change of the
    reduced gradient along the step, and stays symmetric positive definite."""
    qp, rng = _stub(), np.random.default_rng(1)
    h = rng.uniform(0.5, 2.0, 7)
    est = ReducedHessian(qp)
    assert est.curvature() is None  # no estimate before the first step
    s_full = rng.standard_normal(7)
    s = s_full[qp.free]
    base = qp.Z.T @ (h[:, None] * qp.Z)
    y_wanted = base @ s + 0.3 * s  # positive curvature along s: no damping
    # a gradient change whose projection Zᵀ(...) is y_wanted
    g = np.linalg.lstsq(qp.Z.T, y_wanted, rcond=None)[0]
    est.update(s_full, g, h)
    B = base + est.curvature()
    assert np.allclose(B @ s, y_wanted)
    assert np.allclose(B, B.T)
    assert np.linalg.eigvalsh(B).min() > 0


def test_negative_curvature_is_damped():
    """sᵀy < 0 (a concave row along the step): Powell's damping keeps B⁺ positive definite
    with sᵀB⁺s = DAMPING · sᵀBs."""
    qp, rng = _stub(seed=2), np.random.default_rng(3)
    h = np.ones(7)
    est = ReducedHessian(qp)
    est.curvature()
    s_full = rng.standard_normal(7)
    s = s_full[qp.free]
    base = qp.Z.T @ qp.Z
    y = -2.0 * (base @ s)
    est.update(s_full, np.linalg.lstsq(qp.Z.T, y, rcond=None)[0], h)
    B = base + est.curvature()
    assert np.linalg.eigvalsh(B).min() > 0
    assert s @ B @ s == pytest.approx(DAMPING * s @ base @ s, rel=1e-9)


def test_a_new_basis_starts_afresh_and_a_zero_step_changes_nothing():
    qp, rng = _stub(seed=4), np.random.default_rng(5)
    h = np.ones(7)
    est = ReducedHessian(qp)
    est.curvature()
    est.update(rng.standard_normal(7), rng.standard_normal(7), h)
    M = est.curvature()
    assert M is not None
    est.update(np.zeros(7), rng.standard_normal(7), h)
    assert est.curvature() is M
    qp.basis = qp.basis.copy()  # the subproblem pivoted again: other reduced coordinates
    assert est.curvature() is None
    assert est.model_term(rng.standard_normal(7)) == 0.0


@pytest.fixture(scope="module")
def translate():
    models = Models(CellConfig())
    qs = solve_pose(models.loaded, (0.64, -0.33, 0.15), (0, 0, 0))
    return transcribe("translate", models, qs, goal=flat_pose((0.75, 0.0, 0.15)),
                      options=SegmentOptions(arm_clearance=False))


def test_condensed_qp_solves_the_model_with_curvature(translate):
    """With M the condensed Hessian is still the identity (Tᵀ H T + T_Nᵀ M T_N = I), the step
    holds the linearised equalities, and the recovered multipliers close the KKT system
    g + H d + [M w]_N + Jᵀy = 0 on the variables whose box is inactive."""
    nlp = translate
    c, entries, J, g, h, lo, hi = linearise(nlp)
    qp = CondensedQP(nlp)
    rng = np.random.default_rng(6)
    A = rng.standard_normal((qp.r, qp.r))
    M = 0.05 * A @ A.T
    qp.update(nlp, c, entries, g, h, lo, hi, curvature=M)
    assert not qp.curved  # the basis was chosen in this update: M has no coordinates yet
    qp.update(nlp, c, entries, g, h, lo, hi, curvature=M)
    assert qp.curved
    T = qp.T.value
    assert np.allclose(T.T @ (h[:, None] * T) + T[qp.free].T @ M @ T[qp.free], np.eye(qp.r),
                       atol=1e-8)
    sol = qp.solve(eps=1e-10, max_iter=50000)
    assert sol.status == "optimal"
    eq = nlp.c_lo == nlp.c_hi
    assert np.abs((c + J @ sol.d - nlp.c_scale * nlp.c_lo)[eq]).max() < 1e-10
    kkt = g + h * sol.d + J.T @ sol.multipliers
    kkt[qp.free] += M @ sol.d[qp.free]
    inside = (sol.d > lo + 1e-7) & (sol.d < hi - 1e-7)
    assert np.abs(kkt[inside]).max() < 1e-6 * max(1.0, np.abs(g).max())


def test_indefinite_curvature_is_dropped(translate):
    nlp = translate
    c, entries, J, g, h, lo, hi = linearise(nlp)
    qp = CondensedQP(nlp)
    qp.update(nlp, c, entries, g, h, lo, hi)
    qp.update(nlp, c, entries, g, h, lo, hi, curvature=-1e6 * np.eye(qp.r))
    assert not qp.curved
    T = qp.T.value
    assert np.allclose(T.T @ (h[:, None] * T), np.eye(qp.r), atol=1e-8)


def test_sqp_with_and_without_the_estimate_reach_one_optimum(translate):
    """On the smooth translate both models converge to the same optimum (Σu² within 1e-3),
    each to the feasibility tolerance."""
    tight = TerminationOptions(ftol=1e-4)
    a = solve_sqp(translate, options=SQPOptions(tight, qp=QPOptions(quasi_newton=True)))
    b = solve_sqp(translate, options=SQPOptions(tight, qp=QPOptions(quasi_newton=False)))
    assert a.success and b.success
    assert a.max_violation <= 1e-6 and b.max_violation <= 1e-6
    assert a.objective == pytest.approx(b.objective, rel=1e-3)


def test_the_sqp_feeds_the_estimate_to_its_subproblems(translate, monkeypatch):
    """Every accepted hard step updates M, and the later subproblems solve with it (the
    condensed QP reports ``curved``); with ``quasi_newton=False`` neither happens."""
    from flipkit.solvers import reduced_hessian

    seen = {"updates": 0, "curved": 0}
    update, original = reduced_hessian.ReducedHessian.update, CondensedQP.update

    def counting_update(self, *args):
        seen["updates"] += 1
        return update(self, *args)

    def counting_qp(self, *args, **kwargs):
        original(self, *args, **kwargs)
        seen["curved"] += bool(self.curved)

    monkeypatch.setattr(reduced_hessian.ReducedHessian, "update", counting_update)
    monkeypatch.setattr(CondensedQP, "update", counting_qp)
    res = solve_sqp(translate)
    accepted = sum(1 for r in res.log if r["step"] > 0 and not r["elastic"])
    assert res.success and seen["updates"] == accepted > 1
    assert 0 < seen["curved"] <= res.iterations - 1
    seen.update(updates=0, curved=0)
    solve_sqp(translate, options=SQPOptions(qp=QPOptions(quasi_newton=False)))
    assert seen == {"updates": 0, "curved": 0}
