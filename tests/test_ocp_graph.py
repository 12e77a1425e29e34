"""The stage-wise SX graph (flipkit.transcription.ocp_graph) states the NLP's very rows."""

import casadi as ca
import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.behaviors.models import Models
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit.config import TABLE1_LOCATIONS
from flipkit.errors import NoSymbolicFormError
from flipkit.model.ik import solve_pose
from flipkit.transcription.ocp_graph import OcpGraph

NO_CLEARANCE = SegmentOptions(arm_clearance=False)


@pytest.fixture(scope="module")
def models(cell):
    return Models(cell)


@pytest.fixture(scope="module")
def translate(models):
    q0 = solve_pose(models.loaded, (0.65, -0.30, 0.15), (0, 0, 0))
    nlp = transcribe("translate", models, q0, goal=flat_pose((0.80, -0.10, 0.15)),
                        options=NO_CLEARANCE)
    return nlp, OcpGraph(nlp)


@pytest.fixture(scope="module")
def pickup(models):
    """A moving-end segment: braking margin, cone, tip and orientation rows."""
    nlp = transcribe("pickup", models, models.bare.q_home, location=TABLE1_LOCATIONS[1],
                        options=NO_CLEARANCE)
    return nlp, OcpGraph(nlp)


def _random_point(nlp, seed):
    rng = np.random.default_rng(seed)
    return nlp.x0 + rng.normal(0.0, 0.1, nlp.n) * nlp.x_scale


@pytest.mark.parametrize("which", ["translate", "pickup"])
def test_rows_equal_nlp_evaluate(which, request):
    """At a random point every path row is the NLP's scaled row, every NLP row appears once,
    the gap rows vanish, and the bounds are the NLP's."""
    nlp, graph = request.getfixturevalue(which)
    for seed in (0, 1):
        x = _random_point(nlp, seed)
        c, _ = nlp.evaluate(x)
        g = np.asarray(graph.constraints(graph.from_nlp_point(x))).ravel()
        gap, src = graph.row_source < 0, graph.row_source
        assert np.abs(g[gap]).max() == 0.0
        np.testing.assert_allclose(g[~gap], nlp.c_scale[src[~gap]] * c[src[~gap]],
                                   rtol=1e-10, atol=1e-10)
    assert np.array_equal(np.sort(src[~gap]), np.arange(nlp.m))
    np.testing.assert_array_equal(graph.lbg[~gap], nlp.c_scale[src[~gap]] * nlp.c_lo[src[~gap]])
    np.testing.assert_array_equal(graph.ubg[~gap], nlp.c_scale[src[~gap]] * nlp.c_hi[src[~gap]])
    np.testing.assert_array_equal(graph.lbx * graph.scale, nlp.x_lb[graph.index])
    np.testing.assert_allclose(graph.to_nlp_point(graph.from_nlp_point(x)), x, rtol=1e-14)


def test_jacobian_equals_nlp_jacobian(translate):
    """The graph's exact Jacobian, mapped back to the NLP's variables, is the NLP's analytic
    one (scaled): the same first derivatives, so the same KKT conditions."""
    nlp, graph = translate
    x = _random_point(nlp, 2)
    z = graph.problem["x"]
    J = ca.Function("J", [z], [ca.jacobian(graph.problem["g"], z)])
    Jg = J(graph.from_nlp_point(x)).sparse()
    # d(graph rows)/dz_nlp = Σ over the copies of each NLP variable
    P = sp.csc_matrix((np.ones(graph.n), (np.arange(graph.n), graph.index)),
                      shape=(graph.n, nlp.n))
    Jz = (Jg @ P).toarray()[graph.row_source >= 0]
    c, jac = nlp.evaluate(x)
    ref = sp.csc_matrix((jac * nlp.c_scale[nlp.jac_rows] * nlp.x_scale[nlp.jac_cols],
                         (nlp.jac_rows, nlp.jac_cols)), shape=(nlp.m, nlp.n)).toarray()
    np.testing.assert_allclose(Jz, ref[graph.row_source[graph.row_source >= 0]],
                               rtol=1e-8, atol=1e-8)


def test_stage_structure(translate):
    """FATROP's manual structure adds up: variables and rows by stage; the objective is the
    NLP's scaled Σu²."""
    nlp, graph = translate
    s = graph.structure
    assert s["N"] == nlp.layout.N // 2
    assert len(s["nx"]) == len(s["nu"]) == len(s["ng"]) == s["N"] + 1
    assert sum(s["nx"]) + sum(s["nu"]) == graph.n
    assert sum(s["nx"][1:]) + sum(s["ng"]) == graph.problem["g"].numel()
    assert set(graph.index) == set(range(nlp.n))
    x = _random_point(nlp, 3)
    f = ca.Function("f", [graph.problem["x"]], [graph.problem["f"]])
    assert float(f(graph.from_nlp_point(x))) == pytest.approx(nlp.obj_scale * nlp.objective(x),
                                                               rel=1e-12)


def test_clearance_rows_have_no_symbolic_form(models):
    q0 = solve_pose(models.loaded, (0.65, -0.30, 0.15), (0, 0, 0))
    nlp = transcribe("translate", models, q0, goal=flat_pose((0.80, -0.10, 0.15)))
    assert "arm_clearance" in nlp.block_slices
    with pytest.raises(NoSymbolicFormError, match="arm_clearance"):
        OcpGraph(nlp)


def test_key_shared_by_translates_only(models, translate, pickup):
    """Two translates between other poses differ only in their bounds: one built solver serves
    both (bench relies on it); a pickup's graph is another."""
    q0 = solve_pose(models.loaded, (0.45, 0.74, 0.19), (0, 0, 0))
    other = OcpGraph(transcribe("translate", models, q0, goal=flat_pose((0.32, 0.62, 0.20)),
                                   options=NO_CLEARANCE))
    assert other.key == translate[1].key != pickup[1].key
    assert not np.array_equal(other.lbg, translate[1].lbg)
