"""The stage-wise SX graph (flipkit.transcription.ocp_graph) states the NLP's very rows: its
path rows are the NLP's rows, its dynamics rows the NLP's Simpson rows."""

import casadi as ca
import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.behaviors.models import Models
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.targets import scoop_ready
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


@pytest.fixture(scope="module")
def scoop_headed(models):
    """The scoop along a heading of 0.4 rad: its lateral and attitude bands in the turned
    frame (flipkit.model.task_frame)."""
    start = scoop_ready(models.cell, TABLE1_LOCATIONS[1], heading=0.4)
    q = solve_pose(models.bare, start.p, start.o, models.bare.q_home)
    nlp = transcribe("scoop", models, q, location=TABLE1_LOCATIONS[1], heading=0.4,
                     options=NO_CLEARANCE)
    return nlp, OcpGraph(nlp)


def _random_point(nlp, seed):
    rng = np.random.default_rng(seed)
    return nlp.x0 + rng.normal(0.0, 0.1, nlp.n) * nlp.x_scale


def _on_dynamics(graph, z):
    """z with each stage's knot (q, q̇) replaced by what the stage before gives it, stage by
    stage: the dynamics rows vanish there."""
    z, dyn = np.array(z, float), np.where(graph.row_source < 0)[0]
    start = np.cumsum([0] + [nx + nu for nx, nu in zip(graph.nx, graph.nu)])
    for k in range(graph.K):
        g = np.asarray(graph.constraints(z)).ravel()
        rows = dyn[sum(graph.nx[1:k + 1]):sum(graph.nx[1:k + 2])]
        z[start[k + 1]:start[k + 1] + graph.nx[k + 1]] -= g[rows]
    return z


def _simpson_rows(nlp):
    """NLP rows of the Simpson defects σ (Hermite–Simpson rows alternate δ, σ by nq)."""
    rows, nq = np.arange(nlp.m)[nlp.block_slices["hermite_simpson"]], nlp.layout.nq
    return rows[(np.arange(len(rows)) // nq) % 2 == 1]


@pytest.mark.parametrize("which", ["translate", "pickup", "scoop_headed"])
def test_rows_equal_nlp_evaluate(which, request):
    """At a random point on the dynamics every path row is the NLP's scaled row and the
    Simpson rows vanish; every other NLP row appears once; the bounds are the NLP's."""
    nlp, graph = request.getfixturevalue(which)
    path, src = graph.row_source >= 0, graph.row_source
    for seed in (0, 1):
        z = _on_dynamics(graph, graph.from_nlp_point(_random_point(nlp, seed)))
        x = graph.to_nlp_point(z)
        c, _ = nlp.evaluate(x)
        g = np.asarray(graph.constraints(z)).ravel()
        assert np.abs(g[~path]).max() < 1e-12
        np.testing.assert_allclose(g[path], nlp.c_scale[src[path]] * c[src[path]],
                                   rtol=1e-10, atol=1e-10)
        assert np.abs(nlp.c_scale * c)[_simpson_rows(nlp)].max() < 1e-10
    others = np.setdiff1d(np.arange(nlp.m), _simpson_rows(nlp))
    assert np.array_equal(np.sort(src[path]), others)
    np.testing.assert_array_equal(graph.lbg[path], nlp.c_scale[src[path]] * nlp.c_lo[src[path]])
    np.testing.assert_array_equal(graph.ubg[path], nlp.c_scale[src[path]] * nlp.c_hi[src[path]])
    np.testing.assert_array_equal(graph.lbx * graph.scale, nlp.x_lb[graph.index])
    np.testing.assert_allclose(graph.to_nlp_point(graph.from_nlp_point(x)), x, rtol=1e-14)


def test_dynamics_rows_are_the_simpson_rows(translate):
    """Off the dynamics, the rows x_{k+1} − F_k are the NLP's Simpson defects: σ_q̇ for q̇ and
    σ_q + Δt σ_q̇/6 for q, in the knot's scale (Δt = 2T/N)."""
    nlp, graph = translate
    x = _random_point(nlp, 4)
    c, _ = nlp.evaluate(x)
    L, nq = nlp.layout, nlp.layout.nq
    sigma = c[_simpson_rows(nlp)].reshape(graph.K, 2, nq)  # per interval: σ_q, σ_q̇
    g = np.asarray(graph.constraints(graph.from_nlp_point(x))).ravel()
    gap = g[graph.row_source < 0].reshape(graph.K, -1)
    dt = 2 * x[L.T_index] / L.N
    for k in range(graph.K):
        b = 2 * k + 2
        np.testing.assert_allclose(gap[k, nq:2 * nq] * nlp.x_scale[L.iqd(b)], sigma[k, 1],
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(gap[k, :nq] * nlp.x_scale[L.iq(b)],
                                   sigma[k, 0] + dt * sigma[k, 1] / 6, rtol=1e-9, atol=1e-12)
        assert np.abs(gap[k, 2 * nq:]).max() == 0.0  # q̈ copy, T and α carried unchanged


def test_jacobian_equals_nlp_jacobian(translate):
    """On the dynamics, the graph's exact Jacobian of the rows that read no derived knot,
    mapped back to the NLP's variables, is the NLP's analytic one (scaled)."""
    nlp, graph = translate
    z0 = _on_dynamics(graph, graph.from_nlp_point(_random_point(nlp, 2)))
    x = graph.to_nlp_point(z0)
    z = graph.problem["x"]
    J = ca.Function("J", [z], [ca.jacobian(graph.problem["g"], z)])
    Jg = J(z0).sparse()
    # d(graph rows)/dz_nlp = Σ over the copies of each NLP variable
    P = sp.csc_matrix((np.ones(graph.n), (np.arange(graph.n), graph.index)),
                      shape=(graph.n, nlp.n))
    c, jac = nlp.evaluate(x)
    ref = sp.csc_matrix((jac * nlp.c_scale[nlp.jac_rows] * nlp.x_scale[nlp.jac_cols],
                         (nlp.jac_rows, nlp.jac_cols)), shape=(nlp.m, nlp.n)).toarray()
    # rows of the dynamics, the task's kinematic rows and the Bezier rows read their own
    # stage's variables only (no next knot): there the Jacobians must agree entry by entry
    own = [r for name in ("dynamics", "bezier_output", "task_position", "cone")
           for r in range(nlp.block_slices[name].start, nlp.block_slices[name].stop)]
    pick = np.isin(graph.row_source, own)
    Jz = (Jg @ P).toarray()[pick]
    assert pick.sum() == len(own)
    np.testing.assert_allclose(Jz, ref[graph.row_source[pick]], rtol=1e-8, atol=1e-8)


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
    L = nlp.layout  # knot (q, q̇, q̈), T and α per state; 36 controls; u_N last
    assert s["nx"] == [3 * L.nq + 1 + L.n_alpha] * (s["N"] + 1)
    assert s["nu"] == [6 * L.nq] * s["N"] + [L.nq]
    x = _random_point(nlp, 3)
    f = ca.Function("f", [graph.problem["x"]], [graph.problem["f"]])
    assert float(f(graph.from_nlp_point(x))) == pytest.approx(nlp.obj_scale * nlp.objective(x),
                                                               rel=1e-12)


def test_hpipm_layout_has_no_last_control(translate):
    """Without a last control u_N is a state of the last stage, fed by a copy in the stage
    before; the rows and objective are the same."""
    nlp, graph = translate
    other = OcpGraph(nlp, graph.arm, final_control=False)
    assert other.nu[-1] == 0 and other.nx[-1] == graph.nx[-1] + nlp.layout.nq
    assert other.nu[-2] == graph.nu[-2] + nlp.layout.nq
    z = _on_dynamics(other, other.from_nlp_point(_random_point(nlp, 5)))
    x = other.to_nlp_point(z)
    f = ca.Function("f", [other.problem["x"]], [other.problem["f"]])
    assert float(f(z)) == pytest.approx(nlp.obj_scale * nlp.objective(x), rel=1e-12)
    g, path = np.asarray(other.constraints(z)).ravel(), other.row_source >= 0
    c, _ = nlp.evaluate(x)
    np.testing.assert_allclose(g[path], nlp.c_scale[other.row_source[path]]
                               * c[other.row_source[path]], rtol=1e-10, atol=1e-10)


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
