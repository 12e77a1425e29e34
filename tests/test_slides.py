"""Where a flipped burger first touches the grill, and how far it slides after
(flipkit.experiments.slides, BurgerRun.touchdown, the trials' touchdown_xy)."""

import numpy as np
import pytest

from flipkit.experiments.slides import format_slides, slide_summary
from flipkit.simulation.run import BurgerRun


def _landing(rest, touchdown, tilt=None):
    return {"xy": rest, "touchdown_xy": touchdown, "flipped": True, "touchdown_tilt_deg": tilt}


def test_the_summary_measures_rest_minus_touchdown_and_skips_trials_without_one():
    landings = [_landing([0.70, 0.00], [0.70, 0.00]), _landing([0.73, 0.04], [0.70, 0.00]),
                _landing([0.70, 0.01], [0.70, 0.00]), _landing([0.6, 0.0], None),
                {"xy": [0.6, 0.0], "flipped": False}]  # a record made before touchdown_xy
    out = slide_summary(landings)
    assert out["trials"] == 3 and out["max_m"] == pytest.approx(0.05)
    assert out["median_m"] == pytest.approx(0.01) and out["over_2cm"] == 1
    assert out["p90_m"] == pytest.approx(0.01 + 0.8 * 0.04)  # linear: sorted index 1.8
    assert slide_summary([_landing([0.6, 0.0], None)]) is None and slide_summary([]) is None
    line = format_slides(out)
    assert "3 trials" in line and "max 5.0 cm" in line and "1 over 2 cm" in line
    assert out["tilt_median_deg"] is None and "flat" not in line  # records without tilts
    assert format_slides(None) == ""
    tilted = slide_summary([_landing([0.7, 0.0], [0.7, 0.0], t) for t in (2.0, 3.0, 9.0)])
    assert tilted["tilt_median_deg"] == 3.0 and tilted["tilt_max_deg"] == 9.0
    assert "3.0° from flat (median), 9.0° at most" in format_slides(tilted)


def test_touchdown_is_the_first_grill_contact_from_the_given_time():
    n = 11
    grill = np.zeros(n, bool)
    grill[[1, 6, 7]] = True  # touching before the flip's start (0.3 s), then at 0.6 s
    run = BurgerRun(t=np.linspace(0, 1, n), burger_pos=np.zeros((n, 3)),
                    burger_rot=np.tile(np.eye(3), (n, 1, 1)), spatula_pos=np.zeros((n, 3)),
                    spatula_rot=np.tile(np.eye(3), (n, 1, 1)), touch_spatula=np.zeros(n, bool),
                    touch_grill=grill, force_spatula=np.zeros(n), force_grill=np.zeros(n),
                    burger_diameter=0.1, burger_thickness=0.015, blade_length=0.16,
                    blade_width=0.12, grill_height=0.057)
    assert run.touchdown(0.3) == 6 and run.touchdown(0.0) == 1 and run.touchdown(0.6) == 6
    assert run.touchdown(0.75) is None
    from flipkit.experiments.trials import _touchdown

    a = np.pi - np.radians(10.0)  # turned over about x, 10° short of flat
    run.burger_rot[6] = [[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]]
    assert _touchdown(run, 0.3)[1] == pytest.approx(10.0)
    assert _touchdown(run, 0.0)[1] == pytest.approx(180.0)  # index 1: still face up
    assert _touchdown(run, 0.75) == (None, None)


def test_a_trial_records_where_the_flipped_burger_touched_down(flip_plan_file):
    from flipkit.experiments.trials import Perturbations, location_entry, run_trial, trial_jobs

    out = run_trial(trial_jobs(flip_plan_file.read_text(), 1, 0, Perturbations())[0])
    assert out["ok"]["flip"]
    touch, rest = np.array(out["touchdown_xy"]), np.array(out["landing_xy"])
    predicted = np.array(out["predicted_landing_xy"])
    assert np.linalg.norm(touch - predicted) < 0.05  # the flight lands near its prediction
    assert np.linalg.norm(rest - touch) < 0.05
    assert 0.0 <= out["touchdown_tilt_deg"] <= 10.0  # the flip plans it within 5° of flat
    entry = location_entry((0.69, -0.16, 0.072), 1, [out], {"status": "solved"})
    assert entry["landings"][0]["touchdown_xy"] == out["touchdown_xy"]
    assert entry["landings"][0]["touchdown_tilt_deg"] == out["touchdown_tilt_deg"]
    assert slide_summary(entry["landings"])["max_m"] == pytest.approx(
        np.linalg.norm(rest - touch))
