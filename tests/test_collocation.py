"""The collocation NLP: layout, defects on known trajectories, whole-NLP Jacobian vs FD."""

import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.behaviors.models import Models
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.behaviors import targets as tg
from flipkit.transcription.layout import Evaluation, Layout
from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.transcription.constraints import BezierOutput, HermiteSimpson
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.model.ik import solve_pose


@pytest.fixture(scope="module")
def models():
    return Models(CellConfig())


def test_layout_counts_547_variables():
    L = Layout()
    assert L.n == 547 and L.n_nodes == 21
    idx = np.concatenate([f(i) for i in range(21) for f in (L.iq, L.iqd, L.iqdd, L.iu)]
                         + [L.ialpha(j) for j in range(6)] + [[L.T_index]])
    assert sorted(idx) == list(range(547))
    with pytest.raises(ConfigError, match="even"):
        Layout(N=7)


def _poly_point(L, models, coeffs, T=0.8):
    """Z whose q follows sum_k coeffs[k] t^k on every joint (q̇, q̈ exact)."""
    t = L.s * T
    q = sum(c * t**k for k, c in enumerate(coeffs))[:, None] * np.ones(6)
    qd = sum(k * c * t ** (k - 1) for k, c in enumerate(coeffs) if k)[:, None] * np.ones(6)
    qdd = sum(k * (k - 1) * c * t ** (k - 2) for k, c in enumerate(coeffs) if k > 1)[:, None] * np.ones(6)
    return L.pack(q, qd, qdd, np.zeros((21, 6)), np.zeros((6, 7)), T)


def test_hermite_simpson_exact_on_cubics_not_on_quartics(models):
    L = Layout()
    hs = HermiteSimpson(L)
    cubic = _poly_point(L, models, [0.1, -0.3, 0.7, 0.5])
    ev = Evaluation(L, models.bare, cubic)
    assert np.abs(hs.evaluate(ev)[0]).max() < 1e-12
    quartic = _poly_point(L, models, [0.1, -0.3, 0.7, 0.5, 2.0])
    assert np.abs(hs.evaluate(Evaluation(L, models.bare, quartic))[0]).max() > 1e-6


def test_bezier_output_zero_on_its_own_polynomial(models):
    L = Layout()
    alpha = np.random.default_rng(1).normal(size=(6, 7))
    T = 0.7
    t = L.s * T
    q, qd, qdd = (L.bezier.evaluate(alpha, t, T, r) for r in range(3))
    x = L.pack(q, qd, qdd, np.zeros((21, 6)), alpha, T)
    vals, _ = BezierOutput(L, 10.0).evaluate(Evaluation(L, models.bare, x))
    assert np.abs(vals).max() < 1e-9
    x[L.iq(5)] += 0.01  # off the polynomial at one node: the output constraint sees it
    assert np.abs(BezierOutput(L, 10.0).evaluate(Evaluation(L, models.bare, x))[0]).max() > 1e-3


def _nlp_cases(models):
    cell = models.cell
    qs = solve_pose(models.loaded, (0.64, -0.33, 0.15), (0, 0, 0))
    yield transcribe("translate", models, qs, goal=flat_pose((0.75, 0.0, 0.15)))
    pb = TABLE1_LOCATIONS[5]
    p = tg.pickup_end(cell, pb)
    yield transcribe("flip", models, solve_pose(models.loaded, p.p, p.o), np.full(6, 0.1),
                        location=pb)
    r = tg.scoop_ready(cell, pb)
    yield transcribe("scoop", models, solve_pose(models.bare, r.p, r.o), location=pb)


def test_nlp_jacobian_matches_finite_differences(models):
    rng = np.random.default_rng(2)
    for nlp in _nlp_cases(models):
        x = nlp.x0 + 0.01 * rng.normal(size=nlp.n)
        _, jac = nlp.evaluate(x)
        J = sp.coo_matrix((jac, (nlp.jac_rows, nlp.jac_cols)), shape=(nlp.m, nlp.n)).toarray()
        h, Jfd = 1e-6, np.zeros_like(J)
        for k in range(nlp.n):
            e = np.zeros(nlp.n)
            e[k] = h
            Jfd[:, k] = (nlp.constraints(x + e) - nlp.constraints(x - e)) / (2 * h)
        np.testing.assert_allclose(J, Jfd, atol=2e-6 * max(1.0, np.abs(J).max()), err_msg=nlp.name)
        # the pattern is the structure: entries off the pattern are zero
        assert np.abs(Jfd[J == 0]).max() < 1e-6


def test_segment_validation(models):
    with pytest.raises(InvalidChoiceError, match="'translate'"):
        transcribe("jump", models, models.bare.q_home)
    with pytest.raises(ConfigError, match="burger location"):
        transcribe("scoop", models, models.bare.q_home)


def test_interpolant_rows_are_the_executed_cubic(models):
    """a_0, a_1 are the Hermite cubic's q̈ at each interval's ends (scipy's spline, the
    controller's interpolant) and bound it in between; c bounds its q̇ on the interval."""
    from scipy.interpolate import CubicHermiteSpline

    from flipkit.transcription.constraints.interpolant import InterpolantLimits

    L, rng, T = Layout(), np.random.default_rng(3), 0.9
    q, qd = rng.normal(size=(21, 6)), rng.normal(size=(21, 6))
    x = L.pack(q, qd, np.zeros((21, 6)), np.zeros((21, 6)), np.zeros((6, 7)), T)
    block = InterpolantLimits(L, models.bare.qd_max, models.bare.qdd_max)
    vals = block.evaluate(Evaluation(L, models.bare, x))[0].reshape(20, 3, 6)
    t = L.s * T
    spl = CubicHermiteSpline(t, q, qd, axis=0)
    eps = 1e-9
    np.testing.assert_allclose(vals[:, 0], spl(t[:-1] + eps, 2), rtol=1e-6)
    np.testing.assert_allclose(vals[:, 1], spl(t[1:] - eps, 2), rtol=1e-6)
    for i in range(20):
        tt = np.linspace(t[i] + eps, t[i + 1] - eps, 201)  # inside: q̈ jumps at the knots
        acc, vel = np.abs(spl(tt, 2)), np.abs(spl(tt, 1))
        assert np.all(acc <= np.maximum(abs(vals[i, 0]), abs(vals[i, 1])) * (1 + 1e-9))
        hull = np.maximum.reduce([abs(qd[i]), abs(qd[i + 1]), abs(vals[i, 2])])
        assert np.all(vel <= hull * (1 + 1e-9))
    assert block.m == 360 and np.all(block.hi[:12] == 20.0)
    np.testing.assert_array_equal(block.hi[12:18], models.bare.qd_max)


def test_branch_bounds_keep_the_elbow_and_wrist_on_the_home_side():
    from flipkit.model.singular import branch_bounds

    q_min, q_max = np.full(6, -np.pi), np.full(6, np.pi)
    home = np.array([-0.99, -1.79, 2.36, -0.57, 0.58, 1.57])
    lo, hi = branch_bounds(q_min, q_max, home, home, 0.2)
    assert (lo[2], hi[2]) == pytest.approx((0.2, np.pi - 0.2))
    assert (lo[4], hi[4]) == pytest.approx((0.2, np.pi - 0.2))
    np.testing.assert_array_equal(np.delete(lo, [2, 4]), -np.pi)  # the other joints untouched
    start = home.copy()
    start[4] = 0.05  # a start inside the margin widens the bound to it, no further
    lo, hi = branch_bounds(q_min, q_max, home, start, 0.2)
    assert lo[4] == 0.05 and hi[4] == pytest.approx(np.pi - 0.2)
    flipped = home.copy()
    flipped[4] = -0.58  # the other wrist branch: the interval below zero
    lo, hi = branch_bounds(q_min, q_max, flipped, flipped, 0.2)
    assert (lo[4], hi[4]) == pytest.approx((-np.pi + 0.2, -0.2))
    np.testing.assert_array_equal(branch_bounds(q_min, q_max, home, home, 0.0)[0], q_min)
    with pytest.raises(ConfigError, match="singularity margin"):
        branch_bounds(q_min, q_max, home, home, 2.0)


def test_shared_patterns_equal_freshly_filled_ones_and_are_read_only(models):
    """Blocks given Patterns fill a Jacobian pattern once per key: a segment built without
    them, one that fills them and one built from them have the same pattern, and the shared
    arrays cannot be written through."""
    from flipkit.transcription.constraints.base import Patterns
    from flipkit.transcription.constraints.kinematic import KinematicBlock

    q0, patterns = models.bare.q_home, Patterns()
    fresh = transcribe("go_to_burger", models, q0, location=TABLE1_LOCATIONS[0])
    filling = transcribe("go_to_burger", models, q0, location=TABLE1_LOCATIONS[0],
                         patterns=patterns)
    assert len(patterns) > 0
    shared = transcribe("go_to_burger", models, q0, location=TABLE1_LOCATIONS[3],
                        patterns=patterns)
    for nlp in (filling, shared):
        np.testing.assert_array_equal(fresh.jac_rows, nlp.jac_rows)
        np.testing.assert_array_equal(fresh.jac_cols, nlp.jac_cols)
    rows, _ = next(iter(patterns._filled.values()))
    with pytest.raises(ValueError):
        rows[0] = 1
    # the key tells blocks apart: other nodes, another pattern
    L = Layout()
    a = KinematicBlock("a", L, "position", [0, 1], -1.0, 1.0)
    b = KinematicBlock("b", L, "position", [2, 3], -1.0, 1.0)
    assert not np.array_equal(a.cols, b.cols)
    np.testing.assert_array_equal(b.cols.reshape(2, 3, 6)[:, 0], [L.iq(2), L.iq(3)])
