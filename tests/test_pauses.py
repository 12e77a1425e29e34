"""The arm's pause at the sense of sense-plan-act trials (flipkit.experiments.pauses)."""

import pytest

from flipkit.experiments.pauses import PAUSE_TARGET_S, format_pauses, pause_summary


def _trial(time_s):
    return {"replan": None if time_s is None else {"time_s": time_s, "failure": None}}


def test_the_summary_counts_every_replanned_trial_and_skips_open_loop_ones():
    times = [0.002, 0.004, 0.003, 0.9, 0.2, 0.001, 0.005, 0.002, 0.003, 0.004]
    out = pause_summary([_trial(t) for t in times] + [_trial(None)])
    assert out["trials"] == 10
    assert out["median_s"] == pytest.approx(0.0035)
    assert out["worst_s"] == pytest.approx(0.9)
    assert out["p90_s"] == pytest.approx(0.2 + 0.1 * (0.9 - 0.2))  # linear: sorted index 8.1
    assert out["over_target"] == 2 and out["target_s"] == PAUSE_TARGET_S
    assert pause_summary([_trial(t) for t in times], target_s=0.1)["over_target"] == 2
    assert pause_summary([_trial(t) for t in times], target_s=0.5)["over_target"] == 1


def test_a_serves_wait_beyond_its_lead_is_the_pause_not_its_replan_time():
    serves = [{"replan": {"time_s": 0.3, "wait_s": 0.0, "failure": None}},
              {"replan": {"time_s": 0.7, "wait_s": 0.2, "failure": None}}]
    out = pause_summary(serves)
    assert out["worst_s"] == pytest.approx(0.2) and out["median_s"] == pytest.approx(0.1)
    assert out["over_target"] == 1


def test_no_replans_give_none_and_say_open_loop():
    assert pause_summary([_trial(None), _trial(None)]) is None
    assert pause_summary([]) is None
    assert format_pauses(None) == "no re-plans (open loop)"


def test_the_report_line_names_median_p90_worst_and_overruns():
    line = format_pauses(pause_summary([_trial(0.002), _trial(0.004), _trial(0.3)]))
    assert "over 3 re-plans" in line and "median 0.004 s" in line
    assert "worst 0.300 s" in line and "1 over 0.15 s" in line


def test_the_arms_pause_is_whole_control_steps_of_the_replan_beyond_its_lead():
    from flipkit.simulation.control import pause_steps

    dt = 0.002
    assert pause_steps(0.0051, dt) == pytest.approx(0.006)  # no lead: all of it
    assert pause_steps(0.6051, dt, 0.6) == pytest.approx(0.006)  # the part beyond the lead
    for within in (0.3, 0.6):  # within the lead: no pause, and not -0.0
        p = pause_steps(within, dt, 0.6)
        assert p == 0.0 and str(p) == "0.0"
