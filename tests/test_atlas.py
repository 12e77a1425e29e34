"""The warm-start atlas: file round trip, staleness refused, interpolation, warm-started plans."""

import numpy as np
import pytest

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors import targets as tg
from flipkit.cli import main
from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.errors import AtlasError
from flipkit.experiments.atlas import solve_entry
from flipkit.planning.planners.atlas import (BRANCH_TOL, K_NEAREST, Atlas, default_path,
                                             options_hash)
from flipkit.planning.planners.planner import plan_flip
from flipkit.planning.plans.verify import verify_plan

LOC = TABLE1_LOCATIONS[6]


@pytest.fixture(scope="module")
def entry():
    """The chain solved at Table I location 7, as an atlas builder's worker returns it."""
    out = solve_entry((LOC, tg.default_heading(CellConfig(), LOC), CellConfig(),
                       SegmentOptions(), None))
    assert out["status"] == "solved"
    return out


def _atlas(entry, locations=None, shift=None, headings=None):
    """An atlas of ``entry``'s solution at ``locations`` (default its own) and ``headings``
    (default the entry's), the k-th copy with joint angles moved by shift[k] (rad)."""
    locations = [entry["location"]] if locations is None else locations
    headings = [entry["heading"]] * len(locations) if headings is None else headings
    shift = [0.0] * len(locations) if shift is None else shift
    sols = {}
    for name in FLIP_NAMES:
        x = np.array(entry["x"][name])
        rows = []
        for s in shift:
            y = x.copy()
            y[: 21 * 4 * 6].reshape(21, 4, 6)[:, 0] += s
            rows.append(y)
        sols[name] = np.array(rows)
    meta = {"options_hash": options_hash(CellConfig(), SegmentOptions()), "grid": [1, 1],
            "failed": [], "flange": CellConfig().spatula.handle}
    return Atlas(locations, headings, sols, entry["structure"], meta)


def test_file_round_trip(entry, tmp_path):
    atlas = _atlas(entry)
    back = Atlas.load(atlas.save(tmp_path / "a.npz"), CellConfig(), SegmentOptions())
    assert len(back) == 1 and back.meta["grid"] == [1, 1]
    np.testing.assert_array_equal(back.headings, atlas.headings)
    for name in FLIP_NAMES:  # stored as float32: a guess needs no more
        np.testing.assert_allclose(back.solutions[name], atlas.solutions[name], rtol=1e-6,
                                   atol=1e-6)
    assert back.structure == atlas.structure


def test_stale_or_broken_atlas_is_refused(entry, tmp_path):
    path = _atlas(entry).save(tmp_path / "a.npz")
    with pytest.raises(AtlasError, match="stale atlas.*flipkit atlas build"):
        Atlas.load(path, CellConfig(), SegmentOptions(r_land=0.03))
    with pytest.raises(AtlasError, match="stale atlas"):
        plan_flip(LOC, atlas=Atlas.load(path), options=SegmentOptions(r_land=0.03))
    changed = _atlas(entry)
    changed.structure["go_to_burger"] = "0" * 40  # the NLP changed since it was built
    with pytest.raises(AtlasError, match="'go_to_burger' segment's NLP has changed"):
        plan_flip(LOC, atlas=changed)
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not an npz")
    with pytest.raises(AtlasError, match="cannot read atlas"):
        Atlas.load(bad)
    with np.load(path) as data:  # an atlas from before scoop headings
        old = {k: data[k] for k in data.files if k != "headings"}
    np.savez_compressed(tmp_path / "old.npz", **old)
    with pytest.raises(AtlasError, match="holds no scoop headings.*flipkit atlas build"):
        Atlas.load(tmp_path / "old.npz")


def test_guess_interpolates_near_entries_and_skips_other_branches(entry):
    from flipkit.behaviors.models import Models
    from flipkit.behaviors.transcribe import transcribe

    class _NLP:  # the layout, bounds and structure key guess() reads
        def __init__(self, nlp):
            self.layout, self.structure_key = nlp.layout, entry["structure"]["flip"]
            self.x_lb, self.x_ub = nlp.x_lb, nlp.x_ub

    models = Models(CellConfig())
    p = tg.pickup_end(CellConfig(), LOC)
    from flipkit.model.ik import solve_pose
    nlp = _NLP(transcribe("flip", models, solve_pose(models.loaded, p.p, p.o), np.zeros(6),
                             location=LOC))
    a, b, c = (0.70, -0.10, LOC[2]), (0.74, -0.10, LOC[2]), (0.72, -0.14, LOC[2])
    atlas = _atlas(entry, [a, b, c], shift=[0.0, 0.2, 3 * BRANCH_TOL])
    x = atlas.solutions["flip"]
    psi = entry["heading"]
    np.testing.assert_array_equal(atlas.guess("flip", a, nlp, psi), x[0])  # at an entry: itself
    mid = atlas.guess("flip", (0.71, -0.10), nlp, psi)  # 1 cm from a, 3 cm from b; c left out
    w = np.array([1 / 0.01**2, 1 / 0.03**2])
    np.testing.assert_allclose(mid, (w[0] * x[0] + w[1] * x[1]) / w.sum(), rtol=1e-12)
    # an entry solved with its duration bound stretched (T beyond this NLP's bound) seeds
    # nothing, not even at its own location: b alone is left
    L = nlp.layout
    atlas.solutions["flip"][0, L.T_index] = 1.5 * nlp.x_ub[L.T_index]
    np.testing.assert_allclose(atlas.guess("flip", a, nlp, psi), atlas.solutions["flip"][1],
                               rtol=1e-12)


def test_a_turned_heading_counts_as_the_flange_move_it_makes(entry):
    """Entry distance: √(|Δxy|² + (handle · Δψ)²), Δψ wrapped; an entry at the same place but
    a heading turned 30° is farther than one 3 cm away at the same heading, and the guess
    weighs them so."""
    from flipkit.planning.planners.atlas import entry_distance

    h = CellConfig().spatula.handle
    locs = np.array([[0.70, -0.10, 0.07], [0.73, -0.10, 0.07], [0.70, -0.10, 0.07]])
    psis = np.array([0.5, 0.0, np.radians(-359.0)])
    d = entry_distance(locs, psis, (0.70, -0.10, 0.07), 0.0, h)
    np.testing.assert_allclose(d, [h * 0.5, 0.03, h * np.radians(1.0)], rtol=1e-12)
    atlas = _atlas(entry, [tuple(v) for v in locs[:2]], headings=list(psis[:2]))
    np.testing.assert_allclose(atlas.distance(locs[0], 0.5), [0.0, np.hypot(0.03, h * 0.5)])


def test_warm_started_plan_is_solved_and_verified(entry):
    """From an atlas whose entry is this very location, the chain is solved and checked
    like any plan (the guess seeds the solver, the plan stands on its own)."""
    plan = plan_flip(LOC, atlas=_atlas(entry))
    assert plan.status == "solved" and verify_plan(plan, space=CellConfig().space).ok


def test_cli_refuses_a_broken_atlas_in_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.npz"
    bad.write_text("{}")
    code = main(["plan", "flip", "--burger", *map(str, LOC), "--atlas", str(bad), "--json",
                 str(tmp_path / "p.json")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "cannot read atlas" in err[0]
    assert not (tmp_path / "p.json").exists()


def test_the_shipped_atlas_serves_the_default_options():
    """The package's atlas is rebuilt whenever the NLP or its options change: a stale one
    fails here (rebuild: ``flipkit atlas build``)."""
    if not default_path().exists():
        pytest.skip("no atlas shipped")
    atlas = Atlas.load(default_path(), CellConfig(), SegmentOptions())
    plan = plan_flip(TABLE1_LOCATIONS[0], atlas=atlas)  # guess() checks each structure key
    assert plan.status == "solved"


def test_the_atlas_hash_leaves_out_the_simulations_numerical_settings():
    """No NLP depends on how many strips the simulated patty has; it does on the grill's
    friction (the scoop model)."""
    from dataclasses import replace

    cell, opts = CellConfig(), SegmentOptions()
    strips = replace(cell, physics=replace(cell.physics, burger_strips=1))
    grill = replace(cell, physics=replace(cell.physics, mu_grill=0.4))
    assert options_hash(strips, opts) == options_hash(cell, opts)
    assert options_hash(grill, opts) != options_hash(cell, opts)


def test_a_serve_is_seeded_for_its_first_three_segments_only(entry, monkeypatch):
    """The serve shares go to burger, scoop and pickup with the flip: the atlas seeds those
    (at the entry itself, the stored solution exactly) and no other segment; the serve is
    solved and verified like any plan."""
    from flipkit.planning.planners import chain
    from flipkit.planning.planners.serve import plan_serve

    seeded, solve = {}, chain.solve_segment

    def spy(nlp, solver, x0=None, **kw):
        seeded.setdefault(nlp.name, None if x0 is None else np.array(x0))
        return solve(nlp, solver, x0, **kw) if x0 is not None else solve(nlp, solver, **kw)

    monkeypatch.setattr(chain, "solve_segment", spy)
    atlas = _atlas(entry)
    plan = plan_serve(LOC, (0.45, 0.70), atlas=atlas)
    assert plan.status == "solved" and verify_plan(plan, space=CellConfig().space).ok
    for name in ("go_to_burger", "scoop", "pickup"):
        np.testing.assert_array_equal(seeded[name], atlas.solutions[name][0])
    assert all(seeded[name] is None for name in ("carry", "place", "return_home"))
    stale = Atlas(atlas.locations, atlas.headings, atlas.solutions, atlas.structure,
                  {**atlas.meta, "options_hash": "0" * 64})
    with pytest.raises(AtlasError, match="stale atlas"):
        plan_serve(LOC, (0.45, 0.70), atlas=stale)


def test_anchored_guess_starts_at_the_segment_start_and_keeps_the_turn_back_end(entry):
    """The flip and turn back are seeded by a neighbour's joint path anchored at their own
    start state: node 0 is (q_start, q̇_start) exactly, u = RNEA at every node, the flip's
    path is shifted whole, the turn back's offset fades out so it still ends at rest where the
    neighbour ended; a start that is the neighbour's own returns its solution unchanged."""
    from flipkit.behaviors.models import Models
    from flipkit.behaviors.transcribe import transcribe
    from flipkit.planning.planners.atlas import anchored_guess

    models = Models(CellConfig())
    rng = np.random.default_rng(0)
    for name, how in (("flip", "shift"), ("turn_back", "blend")):
        x = np.array(entry["x"][name])
        q0 = x[: 21 * 4 * 6].reshape(21, 4, 6)[0]
        nlp = transcribe(name, models, q0[0], q0[1], location=LOC)
        L, robot = nlp.layout, nlp.robot
        nodes0 = L.nodes(x)
        np.testing.assert_array_equal(anchored_guess(nlp, x, q0[0], q0[1], how), x)
        q_start = q0[0] + rng.uniform(-0.05, 0.05, 6)
        qd_start = q0[1] + rng.uniform(-0.1, 0.1, 6)
        g = L.nodes(anchored_guess(nlp, x, q_start, qd_start, how))
        np.testing.assert_allclose(g[0, 0], q_start, atol=1e-12)
        np.testing.assert_allclose(g[0, 1], qd_start, atol=1e-9)
        for k in range(21):
            np.testing.assert_allclose(g[k, 3], robot.inverse_dynamics(*g[k, :3]), atol=1e-8)
        offset = q_start - nodes0[0, 0]
        if how == "shift":  # the whole path moves with the start (least-squares refit)
            assert np.abs(g[-1, 0] - (nodes0[-1, 0] + offset)).max() < 0.05
        else:  # the end is the neighbour's, at rest
            assert np.abs(g[-1, 0] - nodes0[-1, 0]).max() < 0.02
            np.testing.assert_allclose(g[-1, 1], 0.0, atol=1e-9)


def test_a_segment_the_atlas_solved_stretched_is_solved_stretched_first(monkeypatch):
    """Where most of the nearest atlas entries' turn backs ran past their duration bound (the
    planner's stretch), the turn back is first solved warm with the bound stretched; the
    within-bound NLP, which would only be proved infeasible, is never solved there. Where
    only one neighbour was stretched, the segment is solved within its bound first."""
    from flipkit.planning.planners import chain

    if not default_path().exists():
        pytest.skip("no atlas shipped")
    atlas = Atlas.load(default_path(), CellConfig(), SegmentOptions())
    loc = (0.69, -0.16, 0.072)
    calls, solve = [], chain.solve_segment

    def spy(nlp, solver, x0=None, **kw):
        i = nlp.layout.T_index
        calls.append((nlp.name, float(nlp.x_ub[i]), x0 is not None))
        return solve(nlp, solver, x0, **kw)

    monkeypatch.setattr(chain, "solve_segment", spy)
    plan = plan_flip(loc, atlas=atlas)
    assert plan.status == "solved" and verify_plan(plan, space=CellConfig().space).ok
    turn = [c for c in calls if c[0] == "turn_back"]
    d = np.linalg.norm(atlas.locations[:, :2] - np.array(loc[:2]), axis=1)
    near_T = atlas.solutions["turn_back"][np.argsort(d)[:K_NEAREST], -1]
    assert np.sum(near_T > turn[0][1] / 1.5 + 1e-6) >= 3  # the shipped atlas stretched them
    assert len(turn) == 1 and turn[0][2], turn  # one warm solve, stretched
    assert plan.segments[-1].T > turn[0][1] / 1.5  # longer than the unstretched bound
    calls.clear()  # at (0.64, -0.33) one of the go to burger's four neighbours is stretched
    plan = plan_flip((0.64, -0.33, 0.072), atlas=atlas)
    go = [c for c in calls if c[0] == "go_to_burger"]
    assert plan.status == "solved" and go[0][1] == pytest.approx(0.5) and go[0][2], go
