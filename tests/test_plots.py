"""Figure helpers: flipkit.figures (data, draw, runs), the draw_cell options they use, and the
LaTeX macro file of the manifest (flipkit.figures.write_macros)."""

import json
import re

import matplotlib.pyplot as plt
import numpy as np
import pytest

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors.transcribe import flat_pose, transcribe
from flipkit import figures
from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.errors import ConfigError
from flipkit.model.ik import solve_pose
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.segment import Segment
from flipkit.behaviors.models import Models
from flipkit.figures import data
from flipkit.figures import draw
from flipkit.figures import runs
from flipkit.figures.draw import draw_cell
from flipkit.solvers.sqp import SolveResult

G = 9.81


def _result(nlp, x=None):
    """A SolveResult at ``x`` (default the initial guess) without solving."""
    x = nlp.x0 if x is None else x
    return SolveResult(x=x, status="solved", iterations=0, wall_time_s=0.5,
                       objective=nlp.objective(x), max_violation=0.0, solver="ipopt")


@pytest.fixture(scope="module")
def guess_plan():
    """A flip plan made of the five initial guesses, chained as bench does (no solve)."""
    cell = CellConfig()
    models = Models(cell)
    q, qd, segments = models.bare.q_home, None, []
    for name in FLIP_NAMES:
        nlp = transcribe(name, models, q, qd, location=TABLE1_LOCATIONS[1])
        segments.append(Segment.from_solution(nlp, _result(nlp)))
        nodes = nlp.layout.nodes(nlp.x0)
        q, qd = nodes[-1, 0], nodes[-1, 1]
    return Plan.from_segments("flip", cell, segments, location=TABLE1_LOCATIONS[1])


@pytest.fixture(scope="module")
def translate_nlp():
    cell = CellConfig()
    models = Models(cell)
    robot = models.for_segment("translate")
    q0 = solve_pose(robot, (0.65, -0.30, 0.15), (0.0, 0.0, 0.0), robot.q_home)
    return transcribe("translate", models, q0, goal=flat_pose((0.80, -0.10, 0.15)))


# ---------------------------------------------------------------- data: plan series, contact
def test_plan_series_lays_segments_end_to_end(guess_plan):
    s = data.plan_series(guess_plan)
    T = [seg.T for seg in guess_plan.segments]
    assert np.all(np.diff(s.t) > 0) and s.t[0] == 0.0
    assert np.allclose(s.boundaries, np.concatenate([[0.0], np.cumsum(T)]))
    assert s.names == list(FLIP_NAMES)
    assert s.t.size == 21 + 4 * 20 and s.q.shape == (s.t.size, 6)
    assert np.isclose(s.t[-1], sum(T))
    assert list(s.durations) == list(FLIP_NAMES)
    # the first node of every later segment is dropped: each node appears once
    assert np.array_equal(np.bincount(s.segment), [21, 20, 20, 20, 20])


def test_contact_series_marks_the_enforced_cone_nodes(guess_plan):
    cs = data.contact_series(guess_plan)
    names = [seg.name for seg in guess_plan.segments]
    assert [names[k] for k in np.unique(cs.segment)] == ["pickup", "flip"]
    for k in np.unique(cs.segment):
        seg = guess_plan.segments[k]
        assert np.array_equal(np.flatnonzero(cs.enforced[cs.segment == k]), seg.cone_nodes)
    assert cs.f.shape == (cs.t.size, 3) and set(cs.margin) == {"physical", "paper"}
    # physical margin = min(f_z, mu f_z - |f_x|, mu f_z - |f_y|)
    f, mu = cs.f, cs.mu
    expected = np.min([f[:, 2], mu * f[:, 2] - np.abs(f[:, 0]), mu * f[:, 2] - np.abs(f[:, 1])],
                      axis=0)
    assert np.allclose(cs.margin["physical"], expected)
    with pytest.raises(ConfigError):
        data.contact_series(guess_plan, segments=["translate"])


def test_cone_margins_flat_at_rest():
    # f = (0, 0, g): physical margin min(g, mu g) = mu g; paper form 1 - cos(mu)
    R = data.pitch_matrix(0.0)
    st = data._state(R, np.zeros(3))
    from flipkit.model.contact import make_cone

    assert np.isclose(make_cone("physical", 0.5).margin(st), 0.5 * G)
    assert np.isclose(make_cone("paper", 0.5).margin(st), 1 - np.cos(0.5))


# ---------------------------------------------------------------- data: Hermite–Simpson
def test_hermite_simpson_curves_are_exact_for_cubics():
    t = np.linspace(0.0, 2.0, 21)
    x, xd = 1 + t - 2 * t**2 + 0.5 * t**3, 1 - 4 * t + 1.5 * t**2
    hs = data.hermite_simpson_curves(t, x, xd)
    assert np.allclose(hs.delta, 0, atol=1e-12) and np.allclose(hs.xi, 0, atol=1e-12)
    assert hs.t_dense.shape == (10, 25)
    tt = hs.t_dense.ravel()
    assert np.allclose(hs.x_dense.ravel(), 1 + tt - 2 * tt**2 + 0.5 * tt**3)
    assert np.allclose(hs.interpolant(3, hs.t_mid[3]), hs.x_mid_interp[3])
    # a quartic is not interpolated exactly by a cubic: non-zero midpoint defects
    hs4 = data.hermite_simpson_curves(t, t**4, 4 * t**3)
    assert np.all(np.abs(hs4.delta) > 0)
    with pytest.raises(ConfigError):
        data.hermite_simpson_curves(t[:-1], x[:-1], xd[:-1])


def test_hermite_simpson_defects_match_the_nlp_block(translate_nlp):
    nlp, L = translate_nlp, translate_nlp.layout
    x = nlp.x0.copy()
    x[L.iq(5)] += 0.01  # a midpoint off its interpolant
    nodes, T = L.nodes(x), x[L.T_index]
    mags = data.defect_magnitudes(nlp, x)
    deltas = np.array([data.hermite_simpson_curves(L.s * T, nodes[:, 0, j], nodes[:, 1, j]).delta
                       for j in range(L.nq)])
    xis = np.array([data.hermite_simpson_curves(L.s * T, nodes[:, 0, j], nodes[:, 1, j]).xi
                    for j in range(L.nq)])
    assert np.allclose(mags["delta_q"], np.abs(deltas).max(axis=0), atol=1e-12)
    assert np.allclose(mags["xi_q"], np.abs(xis).max(axis=0), atol=1e-9)
    assert np.isclose(mags["delta_q"][2], 0.01, rtol=1e-2)  # node 5 = third midpoint
    assert np.allclose(mags["t_mid"], L.s[1::2] * T)
    assert np.all(mags["all"] >= mags["delta_q"])


# ---------------------------------------------------------------- data: cone forms
def test_cone_region_grid_boundaries_at_flat():
    mu = 0.5
    accels = np.array([0.0, 4.8, 5.0, 5.3, 5.5, -5.0])
    grid = data.cone_region_grid([0.0], accels, mu)
    assert list(grid["physical"][0] >= 0) == [True, True, False, False, False, False]
    assert list(grid["paper"][0] >= 0) == [True, True, True, True, False, True]
    assert list(grid["category"][0]) == [0, 0, 2, 2, 3, 2]
    assert np.isnan(grid["printed"][0, 0])  # eq. (20) as printed: undefined at rest
    assert np.all(grid["printed"][0, 1:] < 0)  # and no horizontal acceleration allowed


def test_tilted_spatula_needs_acceleration_to_hold_the_burger():
    # pitched by 40 deg, the burger slides at rest; accelerating into the slope holds it
    th = np.radians(40)
    grid = data.cone_region_grid([th], [0.0, 10.0], 0.5)
    assert grid["physical"][0, 0] < 0 and grid["physical"][0, 1] > 0
    b = data.tangential_boundaries(0.5)
    assert np.isclose(b["physical_axis"], np.arctan(0.5)) and b["paper"] == 0.5
    assert np.allclose(np.abs(b["square"]).max(), 0.5)
    assert np.allclose(np.hypot(*b["circle"].T), np.tan(0.5))
    assert np.allclose(data.pitch_matrix(th) @ data.pitch_matrix(-th), np.eye(3))


def test_paper_table1_is_packaged():
    rows = data.paper_table1()
    assert len(rows) == 10 and all(r["trials"] == 10 for r in rows)
    assert [r["location"] for r in rows] == [tuple(loc) for loc in TABLE1_LOCATIONS]
    assert sum(r["scoop"] for r in rows) == 96 and sum(r["flip"] for r in rows) == 95


# ---------------------------------------------------------------- draw
def test_wilson_interval():
    lo, hi = draw.wilson_interval([0, 10, 5], [10, 10, 10])
    assert lo[0] == 0 and np.isclose(hi[0], 0.2775, atol=1e-3)
    assert np.isclose(lo[1], 0.7225, atol=1e-3) and hi[1] == 1
    assert lo[2] < 0.5 < hi[2]
    lo, hi = draw.wilson_interval([0], [0])
    assert np.isnan(lo[0]) and np.isnan(hi[0])


def test_drawing_helpers_draw(guess_plan):
    with figures.style():
        fig, axes = plt.subplots(4, 1)
        t = np.linspace(0, 1, 50)
        p = np.column_stack([t, t**2, np.ones_like(t)])
        res = draw.plot_tracking(axes[:3], t, p, p + [0.001, 0, 0], [0, 0.5, 1], ["a", "b"])
        assert np.isclose(res["max_error_m"], 0.001) and np.isclose(res["rms_error_m"], 0.001)
        draw.plot_tracking_error(axes[3], t, p, p + 0.001)
        with pytest.raises(ConfigError):
            draw.plot_tracking(axes[:2], t, p, p)
        plt.close(fig)

        fig, axes = plt.subplots(3, 1, sharex=True)
        out = draw.plot_forces(axes, data.contact_series(guess_plan))
        assert out["n_nodes"] == 42 and out["n_enforced"] == 21 + 14  # flip: nodes < release
        plt.close(fig)

        fig, ax = plt.subplots()
        draw.plot_success(ax, ["1", "2"], [3, 0], [4, 4], [10, 7], [10, 10], title="scoop")
        assert [t.get_text() for t in ax.get_xticklabels()] == ["1", "2", "all"]
        med = draw.plot_solve_times(ax, ["a", "total"], {"sqp": {"a": [1.0, 3.0], "total": [4.0]},
                                                         "ipopt": {"a": [2.0]}}, budget=20.0,
                                    failed={"sqp": {"a": [0.5]}})
        assert med == {"sqp": {"a": 2.0, "total": 4.0}, "ipopt": {"a": 2.0}}
        plt.close(fig)

        fig, ax = plt.subplots()
        cell = CellConfig()
        draw.plot_grill_map(ax, cell, [[0.7, 0.0, 0.072], [0.8, -0.3, 0.072]], ["solved", "torque"],
                            {"solved": {"marker": "o"}, "torque": {"marker": "X"}},
                            table_locations=TABLE1_LOCATIONS, notes=["", "F"])
        assert ax.get_xlim()[0] > ax.get_xlim()[1]  # y grows to the left (top view)
        plt.close(fig)

        fig, ax = plt.subplots()
        grid = data.cone_region_grid(np.radians([-30, 0, 30]), [-5.0, 0.0, 5.0], 0.5)
        frac = draw.plot_cone_regions(ax, np.radians([-30, 0, 30]), [-5.0, 0.0, 5.0], grid)
        assert np.isclose(sum(frac.values()), 1.0)
        plt.close(fig)


def test_defect_zoom_reports_the_pair_defects():
    t = np.linspace(0.0, 1.0, 5)
    hs = data.hermite_simpson_curves(t, t**4, 4 * t**3)
    with figures.style():
        fig, ax = plt.subplots()
        out = draw.plot_defect_zoom(ax, hs, 1)
        draw.plot_hermite_simpson(ax, hs)
        plt.close(fig)
    assert np.isclose(out["delta"], hs.delta[1]) and np.isclose(out["xi"], hs.xi[1])


def test_draw_snapshot_and_draw_cell_options(guess_plan):
    from flipkit.model.robot import Robot

    cell = CellConfig()
    robot = Robot(cell)
    with figures.style():
        fig = plt.figure()
        ax = fig.add_subplot(projection="3d")
        drawn = draw_cell(ax, robot, cell, robot.q_home, np.zeros((0, 3)), table=False,
                          clip=True)
        assert drawn["location_labels"] == []
        plt.close(fig)
        for burger in ("blade", "grill", "flipped", None):
            fig = plt.figure()
            ax = fig.add_subplot(projection="3d")
            seg = guess_plan.segments[2]
            draw.draw_snapshot(ax, robot, cell, seg.q[-1], location=TABLE1_LOCATIONS[1],
                               burger=burger, path=data.spatula_positions(robot, seg.q),
                               title="x")
            plt.close(fig)
        fig = plt.figure()
        ax = fig.add_subplot(projection="3d")
        with pytest.raises(ConfigError):
            draw.draw_snapshot(ax, robot, cell, robot.q_home, burger="plate")
        plt.close(fig)


# ---------------------------------------------------------------- runs
def test_solve_time_table_groups_rows():
    rows = [
        {"solver": "sqp", "status": "solved", "segments": [
            {"name": "scoop", "status": "solved", "wall_time_s": 1.0},
            {"name": "flip", "status": "solved", "wall_time_s": 2.0}]},
        {"solver": "sqp", "status": "failed", "segments": [
            {"name": "scoop", "status": "stalled", "wall_time_s": 5.0}]},
        {"solver": "ipopt", "status": "solved", "segments": [
            {"name": "scoop", "status": "solved", "wall_time_s": 0.5}]},
    ]
    table = runs.solve_time_table(rows, ["scoop", "flip", "total"])
    assert table["times"]["sqp"] == {"scoop": [1.0], "flip": [2.0], "total": [3.0]}
    assert table["failed"]["sqp"]["scoop"] == [5.0]
    assert table["solved"] == {"sqp": [1, 2], "ipopt": [1, 1]}


def test_solve_time_sweep_hands_out_ipopt_first_and_returns_location_major(monkeypatch):
    calls = []

    def fake(item):
        calls.append((item["location"][0], item["solver"]))
        return {"location": item["location"], "solver": item["solver"]}

    monkeypatch.setattr(runs, "flip_solve_times", fake)
    rows = runs.solve_time_sweep([(1, 0, 0), (2, 0, 0)], ("sqp", "ipopt"), workers=0)
    assert calls == [(1.0, "ipopt"), (2.0, "ipopt"), (1.0, "sqp"), (2.0, "sqp")]
    assert [(r["location"][0], r["solver"]) for r in rows] == [
        (1.0, "sqp"), (1.0, "ipopt"), (2.0, "sqp"), (2.0, "ipopt")]
    assert runs.solve_workers(1) == 1 and runs.solve_workers(100) >= 1


def test_tracked_segment_errors():
    series = data.PlanSeries(np.array([0.0, 1.0, 2.0]), *(np.zeros((3, 6)),) * 4,
                             np.array([0, 0, 1]), np.array([0.0, 1.0, 2.0]), ["a", "b"])
    t = np.linspace(0, 2, 21)
    p_des = np.zeros((21, 3))
    p = p_des.copy()
    p[t > 1.0, 2] = 0.002
    tr = runs.Tracked(t, p, p_des, series)
    err = tr.segment_errors()
    assert [e["name"] for e in err] == ["a", "b"]
    assert err[0]["max_m"] == 0.0 and np.isclose(err[1]["max_m"], 0.002)


def test_chain_translates_needs_two_points():
    with pytest.raises(ConfigError):
        runs.chain_translates([(0.65, -0.30, 0.15)])


# ---------------------------------------------------------------- LaTeX macros
def test_format_number_and_escape():
    f = figures.format_number
    assert [f(2.0), f(0.5), f(1.31), f(12345.6), f(3), f(True), f(None), f(float("nan"))] == [
        "2", "0.5", "1.31", "12346", "3", "yes", "--", "--"]
    assert f(0.000123) == r"\ensuremath{1.23\times10^{-4}}"
    assert f(-0.061) == r"\ensuremath{-0.061}"
    assert figures.tex_escape("a_b <= 5% μ") == r"a\_b \textless{}= 5\% $\mu$"


def test_flatten_numbers():
    leaves = figures.flatten_numbers({"a": 1, "b": {"c": [1.0, 2.0], "d": None}, "e": "x"})
    assert leaves == [("a", 1), ("b.c.1", 1.0), ("b.c.2", 2.0), ("b.d", None), ("e", "x")]


def test_write_macros_one_macro_per_number(tmp_path):
    manifest = {"flipkit": "0.1.0", "git": "abc", "figures": {
        "flip": {"caption": "A_b 5 %", "notebook": "notebooks/flip.ipynb",
                 "parameters": {"quick": True},
                 "numbers": {"max_error_m": 0.00056, "ok": False, "d": [0.8, 0.6],
                             "flip_ratio": 0.9, "reasons": {"x_y": 2}}},
        "cell": {"caption": "c", "numbers": {"n": 10}}}}
    path = figures.write_macros(manifest, tmp_path / "numbers.tex")
    text = path.read_text()
    defs = re.findall(r"^\\fkdef\{([^}]*)\}\{([^}]*)\}\{(.*)\}$", text, re.M)
    assert len(defs) == 6 + 1
    assert ("flip", "max_error_m", r"\ensuremath{5.60\times10^{-4}}") in defs
    assert ("flip", "reasons.x_y", "2") in defs and ("flip", "d.2", "0.6") in defs
    assert r"\fkdefmm{flip}{max_error_m}{0.56}" in text
    assert r"\fkdefpct{flip}{flip_ratio}{90\,\%}" in text
    assert r"\fkdefmeta{flip.quick}{yes}" in text and r"\fkdefmeta{git}{abc}" in text
    assert r"\fkdefcaption{flip}{A\_b 5 \%}" in text
    assert r"\fkdefmeta{config.grill_mu}" in text
    # from a path too
    (tmp_path / "m.json").write_text(json.dumps(manifest))
    assert figures.write_macros(tmp_path / "m.json", tmp_path / "n2.tex").read_text() == text


def _landing_report():
    """A validate report of two locations: trial 0 of location 1 failed its scoop."""
    def landing(trial, xy, pred, flipped):
        return {"trial": trial, "flipped": flipped, "xy": xy, "predicted_xy": pred,
                "replan": None}
    return {"locations": [
        {"trials": 2, "failures": [{"trial": 0, "stage": "scoop", "reason": "overlap"}],
         "landings": [landing(0, [0.7, 0.0], [0.7, 0.0], False),
                      landing(1, [0.74, 0.04], [0.71, 0.0], True)]},
        {"trials": 2, "failures": [{"trial": 1, "stage": "flip", "reason": "missed_spot"}],
         "landings": [landing(0, [0.6, -0.3], None, True),
                      landing(1, [0.66, -0.3], [0.6, -0.3], False)]}]}


def test_landing_points_and_summary_count_the_flights_after_a_pickup():
    pts = data.landing_points(_landing_report(), [[0.7, 0.0], [0.6, -0.3]])
    assert pts["reached"] == 3 and pts["trials"] == 4
    assert pts["location"].tolist() == [0, 1, 1]
    assert np.isnan(pts["predicted"][1]).all()
    s = data.landing_summary(pts)
    assert s["flipped"] == 2 and s["within_tol_xy"] == 2  # (0.04, 0.04): in x and y ...
    assert s["within_tol_radius"] == 1 and s["reached"] == 3  # ... but not within 5 cm
    assert s["median_target_distance_m"] == pytest.approx(np.hypot(0.04, 0.04))
    assert s["median_prediction_error_m"] == pytest.approx(0.055)
    fig, ax = plt.subplots()
    draw.plot_landings(ax, CellConfig(), pts, [[0.7, 0.0], [0.6, -0.3]], title="open loop")
    assert ax.get_title() == "open loop" and len(ax.patches) == 3  # grill + two circles
    plt.close(fig)


def test_success_series_and_sensitivity_panels_draw():
    fig, ax = plt.subplots()
    draw.plot_success_series(ax, ["1", "2"], [{"label": "a", "k": [1, 2], "n": [2, 2]},
                                              {"label": "b", "k": [0, 0], "n": [2, 2],
                                               "open": True}], [10, 7], [10, 10], title="flip")
    assert [t.get_text() for t in ax.get_xticklabels()] == ["1", "2", "all"]
    assert {"a", "b", "paper (real robot)"} <= set(ax.get_legend_handles_labels()[1])
    plt.close(fig)
    counts = {"trials": 2, "success": {"scoop": 2, "pickup": 1, "flip": 0}}
    result = {"nominal": counts, "parameters": {"burger.mu": {"low": counts, "high": counts}}}
    fig, axes = plt.subplots(1, 3)
    assert draw.plot_sensitivity(axes, result) == ["burger.mu"]
    plt.close(fig)
