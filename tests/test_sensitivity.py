"""The one-at-a-time sensitivity study: settings over PHYSICAL_RANGES, the per-trial physics
override of validate.run_trial, the worst setting, and one small real study."""

import pytest

from flipkit.experiments import sensitivity
from flipkit.config import PHYSICAL_RANGES, CellConfig, with_parameter
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.experiments.trials import Perturbations, trial_jobs, trial_key


def test_settings_cover_both_ends_of_every_range_in_order():
    rows = sensitivity.settings()
    assert len(rows) == 2 * len(PHYSICAL_RANGES)
    assert [r[0] for r in rows[::2]] == list(PHYSICAL_RANGES)
    for name, end, value in rows:
        lo, hi, _ = PHYSICAL_RANGES[name]
        assert value == (lo if end == "low" else hi)
    assert sensitivity.settings(["burger.mu"]) == [("burger.mu", "low", 0.2),
                                                   ("burger.mu", "high", 0.8)]
    with pytest.raises(InvalidChoiceError):
        sensitivity.settings(["burger.colour"])


def test_physics_enters_the_job_and_its_cache_key_only_when_given():
    plain = trial_jobs("{}", 1, 0, Perturbations())[0]
    moved = trial_jobs("{}", 1, 0, Perturbations(), physics={"burger.mu": 0.2})[0]
    assert "physics" not in plain and moved["physics"] == {"burger.mu": 0.2}
    assert trial_key(plain) != trial_key(moved)
    assert with_parameter(CellConfig(), "burger.mu", 0.2).burger.mu == 0.2


def _counts(scoop, pickup, flip, n=4):
    return {"value": 1.0, "trials": n, "success": {"scoop": scoop, "pickup": pickup,
                                                   "flip": flip}, "failures": []}


def test_worst_takes_fewest_flips_then_fewest_pickups():
    result = {"parameters": {
        "burger.mu": {"low": _counts(4, 3, 1), "high": _counts(4, 4, 4)},
        "physics.mu_grill": {"low": _counts(4, 2, 1), "high": _counts(4, 4, 3)}}}
    w = sensitivity.worst(result)
    assert (w["parameter"], w["end"], w["success"]["flip"]) == ("physics.mu_grill", "low", 1)
    assert sensitivity.worst(result, "scoop")["parameter"] == "burger.mu"
    with pytest.raises(InvalidChoiceError):
        sensitivity.worst(result, "land")


def test_run_sensitivity_rejects_no_plans_and_bad_trials():
    with pytest.raises(ConfigError):
        sensitivity.run_sensitivity([None])
    with pytest.raises(ConfigError):
        sensitivity.run_sensitivity(["{}"], trials=0)


@pytest.mark.slow
def test_small_study_runs_the_trials_at_each_setting(flip_plan_file):
    text = flip_plan_file.read_text()
    out = sensitivity.run_sensitivity([text], trials=1, parameters=["physics.mu_grill"],
                                      replan=False)
    assert out["plans"] == 1 and out["nominal"]["trials"] == 1
    assert set(out["parameters"]["physics.mu_grill"]) == {"low", "high"}
    for end, value in (("low", 0.2), ("high", 1.0)):
        c = out["parameters"]["physics.mu_grill"][end]
        assert c["value"] == value and c["trials"] == 1
        assert set(c["success"]) == {"scoop", "pickup", "flip"}


@pytest.mark.slow
def test_a_planned_parameter_runs_the_plans_made_for_its_value(flip_plan, flip_plan_file):
    """The blade's thickness changes the plan (the scoop model's lifted overhang): a plan
    made for the thicker blade puts the burger further along it, and a study given plans for
    an end runs those there (two plans, two trials) and the nominal plans elsewhere."""
    from flipkit.config import PLANNED_PARAMETERS
    from flipkit.experiments.trial_jobs import plan_text
    from flipkit.planning.planners.planner import plan_flip

    assert PLANNED_PARAMETERS == ("burger.diameter", "physics.blade_thickness")
    thick = with_parameter(CellConfig(), "physics.blade_thickness", 0.002)
    other = plan_flip(tuple(flip_plan.burger["location"]), cell=thick)
    assert other.status == "solved"
    x = lambda p: p.segment("flip").landing["burger_on_blade"][0]  # noqa: E731
    assert x(other) > x(flip_plan) + 0.001
    text, other_text = flip_plan_file.read_text(), plan_text(other)
    # the figures' planning jobs plan the same for a cell given by its parameters
    from flipkit.experiments.trial_jobs import plan_from_text
    from flipkit.figures.runs import plan_location_text

    job = {"location": [float(v) for v in flip_plan.burger["location"]], "solver": "auto",
           "cell": {"physics.blade_thickness": 0.002}}
    made = plan_location_text(job)
    assert made["status"] == "solved"
    assert x(plan_from_text(made["text"])) == pytest.approx(x(other), abs=1e-6)
    out = sensitivity.run_sensitivity(
        [text], trials=1, parameters=["physics.blade_thickness"], replan=False,
        replanned={("physics.blade_thickness", "high"): [other_text, other_text]})
    ends = out["parameters"]["physics.blade_thickness"]
    assert ends["high"]["trials"] == 2 and ends["low"]["trials"] == 1
    assert out["nominal"]["trials"] == 1
