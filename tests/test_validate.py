"""``flipkit validate`` on one plan (conftest's SQP flip plan) with two trials: schema, seeded determinism,
perturbations, and one-line errors (exit 2) on bad input."""

import json

import numpy as np
import pytest

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.cli import main
from flipkit.config import TABLE1_LOCATIONS
from flipkit.errors import ConfigError
from flipkit.experiments.perturbations import trial_rng
from flipkit.experiments.trials import STAGES, Perturbations, run_trial, track_plan, trial_jobs

LOCATION = TABLE1_LOCATIONS[5]  # where conftest's flip_plan is planned
TRIALS = 2


@pytest.fixture(scope="module")
def plan_file(flip_plan_file):
    return flip_plan_file


def validate(plan_file, out, seed, *extra):
    argv = ["validate", "--plan", str(plan_file), "--trials", str(TRIALS), "--seed", str(seed),
            "--workers", "1", "--no-progress", "--json", str(out), *extra]
    assert main(argv) == 0
    return json.loads(out.read_text())


@pytest.fixture(scope="module")
def result(plan_file):
    return validate(plan_file, plan_file.with_name("out.json"), 3)


def test_schema(result):
    assert result["trials"] == TRIALS and result["seed"] == 3
    (entry,) = result["locations"]
    assert entry["location"] == pytest.approx(list(LOCATION))  # the flip_plan fixture's
    assert entry["trials"] == TRIALS and set(entry["success"]) == set(STAGES)
    s = entry["success"]
    assert TRIALS >= s["scoop"] >= s["pickup"] >= s["flip"] >= 0  # cumulative stages
    assert len(entry["failures"]) == TRIALS - s["flip"]
    for f in entry["failures"]:
        assert 0 <= f["trial"] < TRIALS and f["stage"] in STAGES
        assert isinstance(f["amount"], float) and isinstance(f["reason"], str)
    for table in (entry["tracking"], result["tracking"]):
        assert list(table) == list(FLIP_NAMES)
        for err in table.values():
            assert 0 < err["rms_m"] <= err["max_m"] < 0.01  # PD tracking: below 1 cm
    assert result["summary"]["trials"] == TRIALS
    for stage, (lo, hi) in result["summary"]["interval_95"].items():  # Wilson, around k / n
        assert 0 <= lo <= result["summary"]["success"][stage] / TRIALS <= hi <= 1 and lo < hi
    assert result["perturbations"]["position_sigma"] == 0.005


def test_same_seed_same_result_other_seed_other_draws(plan_file, result, tmp_path):
    again = validate(plan_file, tmp_path / "again.json", 3)
    assert again == result
    text = plan_file.read_text()
    draws = {seed: [run_trial(j)["perturbation"] for j in trial_jobs(text, TRIALS, seed,
                                                                        Perturbations())]
             for seed in (3, 4)}
    # each (seed, trial) has a stream of its own: no draw of seed 3 recurs in seed 4 (with
    # default_rng(seed + trial), seed 3's trial 1 would be seed 4's trial 0)
    assert not any(d == e for d in draws[3] for e in draws[4])
    assert draws[3] == [run_trial(j)["perturbation"] for j in trial_jobs(text, TRIALS, 3,
                                                                          Perturbations())]
    doc = json.loads(text)  # the same plan moved 1 cm: trials elsewhere draw their own
    doc["burger"]["location"][1] += 0.01
    moved = [run_trial(j)["perturbation"] for j in trial_jobs(json.dumps(doc), TRIALS, 3,
                                                              Perturbations())]
    assert not any(d == e for d in draws[3] for e in moved)


def test_trial_streams_are_fixed_and_distinct():
    here, there = (0.75, 0.0, 0.072), (0.75, 0.0, 0.073)  # 1 mm apart

    def first(seed, trial, loc):
        return trial_rng(seed, trial, loc).normal(size=3)
    assert np.array_equal(first(0, 0, here), first(0, 0, here))
    assert not np.array_equal(first(0, 0, here), first(0, 1, here))
    assert not np.array_equal(first(0, 0, here), first(0, 0, there))
    assert not np.array_equal(first(3, 0, here), first(0, 3, here))
    assert not np.array_equal(first(0, 0, (0.7, -0.1, 0.072)), first(0, 0, (0.7, 0.1, 0.072)))
    for bad in (-1, 1.5, True, "0"):
        with pytest.raises(ConfigError, match="non-negative integer"):
            trial_rng(bad, 0, here)
        with pytest.raises(ConfigError, match="non-negative integer"):
            trial_rng(0, bad, here)
    for bad in ((0.7, 0.0), (0.7, np.nan, 0.07)):
        with pytest.raises(ConfigError, match="three finite numbers"):
            trial_rng(0, 0, bad)


def test_perturbation_draws_within_their_ranges():
    p = Perturbations()
    rng = np.random.default_rng(0)
    d = [p.draw(rng) for _ in range(200)]
    assert all(abs(x["grill_offset_m"]) <= 0.002 for x in d)
    assert all(0.8 <= x["mu_factor"] <= 1.2 and 0.9 <= x["mass_factor"] <= 1.1 for x in d)
    assert np.std([x["dx_m"] for x in d]) == pytest.approx(0.005, rel=0.2)
    assert np.std([x["sense_dx_m"] for x in d]) == pytest.approx(0.005, rel=0.2)
    zero = Perturbations(0.0, 0.0, (1.0, 1.0), (1.0, 1.0), 0.0).draw(rng)
    assert zero == {"dx_m": 0.0, "dy_m": 0.0, "grill_offset_m": 0.0, "mu_factor": 1.0,
                    "mass_factor": 1.0, "sense_dx_m": 0.0, "sense_dy_m": 0.0}
    with pytest.raises(ConfigError):
        Perturbations(position_sigma=-0.001)
    with pytest.raises(ConfigError):
        Perturbations(mu_scale=(1.2, 0.8))


def test_tracked_poses_follow_the_plan(plan_file):
    from flipkit.planning.plans.plan_file import Plan

    plan = Plan.load(plan_file)
    t, p, R, bounds, errors = track_plan(plan)
    assert np.all(np.diff(t) > 0) and t[0] == 0.0
    assert t[-1] == pytest.approx(sum(s.T for s in plan.segments), abs=2e-3)
    assert list(bounds) == list(FLIP_NAMES) and p.shape == (t.size, 3)
    assert R.shape == (t.size, 3, 3)


@pytest.fixture
def failed_plan(plan_file, tmp_path):
    doc = json.loads(plan_file.read_text())
    doc["status"] = "failed"
    path = tmp_path / "failed.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("case, message", [
    ("missing", "cannot read"), ("not_json", "not a JSON"), ("failed", "status is 'failed'"),
    ("zero_trials", "--trials"), ("negative_trials", "--trials"), ("negative_seed", "seed"),
])
def test_bad_input_exits_2(plan_file, failed_plan, tmp_path, capsys, case, message):
    bad = tmp_path / "bad.json"
    bad.write_text("{oops")
    plan = {"missing": tmp_path / "nope.json", "not_json": bad, "failed": failed_plan}.get(
        case, plan_file)
    trials = {"zero_trials": "0", "negative_trials": "-2"}.get(case, "2")
    out = tmp_path / "out.json"
    seed = ["--seed", "-1"] if case == "negative_seed" else []
    code = main(["validate", "--plan", str(plan), "--trials", trials, "--workers", "1",
                 "--no-progress", "--json", str(out), *seed])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and message in err
    assert not out.exists()


def test_flip_is_judged_against_the_plans_landing_target(flip_plan, tmp_path):
    """A plan from ``plan flip --land X Y`` records its own target: the judge uses it, and
    falls back to the pickup spot for a plan without one."""
    from dataclasses import replace

    from flipkit.behaviors import targets as tg
    from flipkit.experiments.trials import plan_from_text
    from flipkit.simulation.judges import landing_target

    flip = flip_plan.segment("flip")
    assert flip.landing is not None
    assert landing_target(flip_plan) == pytest.approx(flip.landing["target"])
    far = [0.30, 0.60]  # on the table, nowhere near where this flip lands
    moved = replace(flip, landing={**flip.landing, "target": far})
    plan = replace(flip_plan, segments=[moved if s.name == "flip" else s
                                        for s in flip_plan.segments])
    path = plan.to_json(tmp_path / "moved.json")
    assert landing_target(plan_from_text(path.read_text())) == pytest.approx(far)
    bare = replace(flip_plan, segments=[replace(s, landing=None, release=None)
                                        if s.name == "flip" else s for s in flip_plan.segments])
    pb = flip_plan.burger["location"]
    assert landing_target(bare) == pytest.approx(tg.landing_spot(flip_plan.cell(), pb))
    none = Perturbations(0.0, 0.0, (1.0, 1.0), (1.0, 1.0))
    job = trial_jobs(path.read_text(), 1, 0, none)[0]
    res = run_trial(job)
    if res["ok"]["pickup"]:  # the flip itself is judged: it lands ~0.4 m from the far target
        assert not res["ok"]["flip"]
        assert res["failure"]["reason"] == "missed_spot" and res["failure"]["amount"] > 0.2


@pytest.mark.parametrize("flag", [("--no-atlas",), ("--heading", "10"), ("--turn", "15")])
def test_planning_flags_need_locations(plan_file, tmp_path, capsys, flag):
    code = main(["validate", "--plan", str(plan_file), "--trials", "1", *flag,
                 "--no-progress", "--json", str(tmp_path / "o.json")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and f"{flag[0]} needs --locations" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("flag,value", [("--heading", "75"), ("--heading", "-61"),
                                        ("--heading", "nan"), ("--heading", "x"),
                                        ("--turn", "121"), ("--turn", "inf")])
def test_a_heading_out_of_range_is_refused_before_planning(tmp_path, capsys, flag, value):
    code = main(["validate", "--locations", "table1", flag, value, "--trials", "1",
                 "--no-progress", "--json", str(tmp_path / "o.json")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and flag in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o.json").exists()


def test_heading_and_turn_exclude_each_other(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["validate", "--locations", "table1", "--heading", "10", "--turn", "10",
              "--trials", "1", "--json", str(tmp_path / "o.json")])
    assert stop.value.code == 2 and "not allowed with" in capsys.readouterr().err


def test_a_location_is_planned_at_the_heading_asked(tmp_path):
    """``--heading``: the plan scoops along it, and its file is kept apart from the default's."""
    import math
    from flipkit.experiments.trials import plan_location
    from flipkit.planning.plans.plan_file import Plan

    job = {"location": [0.69, -0.16, 0.072], "solver": "sqp", "plans_dir": str(tmp_path),
           "heading": math.radians(-30.0)}
    turned = plan_location(job)
    assert turned["status"] == "solved" and turned["path"].endswith("_sqp-heading-30.0.json")
    assert Plan.load(turned["path"]).burger["heading"] == pytest.approx(math.radians(-30.0))


def test_a_location_is_planned_from_the_atlas_or_from_cold_starts(tmp_path):
    """The atlas and cold starts solve the same NLPs; the plans are kept apart by name, and
    the cold one took more SQP iterations (the atlas is warm-start data)."""
    from flipkit.experiments.trials import plan_location
    from flipkit.planning.planners.atlas import default_atlas
    from flipkit.planning.plans.plan_file import Plan

    assert default_atlas() is not None
    job = {"location": [0.69, -0.16, 0.072], "solver": "sqp", "plans_dir": str(tmp_path)}
    warm, cold = plan_location(job), plan_location({**job, "atlas": False})
    assert warm["status"] == cold["status"] == "solved"
    assert warm["path"] != cold["path"] and cold["path"].endswith("_sqp-cold.json")
    iterations = [sum(s.solver.iterations for s in Plan.load(r["path"]).segments)
                  for r in (warm, cold)]
    assert iterations[0] < iterations[1]
