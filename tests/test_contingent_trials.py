"""Sense-plan-act trials whose re-plans come from contingency flips made ahead
(flipkit.experiments.contingent, flipkit validate --replan --contingencies)."""

import pytest

from flipkit.cli import main
from flipkit.experiments import contingent
from flipkit.experiments.perturbations import Perturbations
from flipkit.experiments.trial_jobs import plan_from_text, trial_jobs, trial_key
from flipkit.experiments.trials import run_trial, validate
from flipkit.planning.planners.contingency import contingency_places
from flipkit.simulation.modes import POSITION


@pytest.fixture(scope="module")
def record(flip_plan_file):
    return contingent.prepare(flip_plan_file.read_text())


@pytest.fixture
def prepared(monkeypatch):
    """The plan texts contingent.prepare is called with, in order (it still prepares)."""
    calls = []
    real = contingent.prepare

    def counting(text, executor=None):
        calls.append(text)
        return real(text, executor)

    monkeypatch.setattr(contingent, "prepare", counting)
    return calls


def test_the_record_holds_every_contingency_verified_and_the_wait_beyond_the_scoop(
        flip_plan, record):
    assert record["places"] == [list(p) for p in contingency_places(flip_plan)]
    assert len(record["texts"]) == 4 and record["failed"] == []
    sense = sum(float(s.T) for s in flip_plan.segments[:2])  # go to burger, scoop
    assert contingent.sense_time(flip_plan) == pytest.approx(sense)
    assert record["sense_s"] == pytest.approx(sense)
    assert len(record["ready_s"]) == 4
    assert 0 < min(record["ready_s"]) and max(record["ready_s"]) <= record["prepare_s"]


def test_the_replanner_hands_out_the_contingency_of_a_place(flip_plan_file, record):
    plan = plan_from_text(flip_plan_file.read_text())
    replan = contingent.replanner(plan, record)
    place = record["places"][2]
    got = replan(plan, place)
    assert got is replan.flips[2][1]
    flip = got.segment("flip")
    assert flip.landing["burger_on_blade"][:2] == pytest.approx(place)


def test_a_contingency_not_ready_at_the_sense_is_waited_for(flip_plan_file, record):
    import time

    plan = plan_from_text(flip_plan_file.read_text())
    late = {**record, "ready_s": [record["sense_s"] + 0.3] * 4}  # all ready 0.3 s too late
    replan = contingent.replanner(plan, late)
    assert replan.wait_s(2) == pytest.approx(0.3)
    t0 = time.perf_counter()
    assert replan(plan, record["places"][2]) is replan.flips[2][1]
    assert time.perf_counter() - t0 >= 0.3
    x0, y0 = plan.segment("flip").landing["burger_on_blade"][:2]
    t0 = time.perf_counter()
    assert replan(plan, (x0, y0)) is plan  # kept: nothing to wait for
    assert time.perf_counter() - t0 < 0.3
    early = contingent.replanner(plan, {**record, "ready_s": [0.0] * 4})
    assert early.wait_s(2) == 0.0


def test_a_trial_with_contingencies_and_its_cache_key(flip_plan_file, record):
    # position control, the faithful cell's: in feed-forward this draw's blade kicks wrist 3
    # past its published speed where it lands on the grill, and the run stops before the sense
    job = trial_jobs(flip_plan_file.read_text(), 1, 3, Perturbations(), replan=True,
                     mode=POSITION)[0]
    with_c = {**job, "contingencies": record}
    key = trial_key(with_c)
    assert isinstance(key["contingencies"], str) and key != trial_key(job)
    out = run_trial(with_c)
    assert out["replan"]["time_s"] is not None and out["replan"]["failure"] is None
    assert set(out["ok"]) == {"scoop", "pickup", "flip"}


def test_validate_prepares_once_per_plan(flip_plan_file, prepared):
    calls = prepared
    text = flip_plan_file.read_text()
    out = validate([([0.69, -0.16, 0.072], {}, text)], 2, seed=3, replan=True,
                   contingencies=True, progress=False)
    assert out["contingencies"] is True and len(calls) == 1
    assert out["summary"]["trials"] == 2
    rec = out["locations"][0]["contingencies"]
    assert len(rec["places"]) == len(rec["ready_s"]) == 4 and rec["prepare_s"] > 0
    off = validate([([0.69, -0.16, 0.072], {}, text)], 1, seed=3, replan=False,
                   contingencies=True, progress=False)
    assert off["contingencies"] is False and len(calls) == 1  # open loop: nothing prepared


@pytest.mark.parametrize("extra, message", [
    (["--contingencies"], "--contingencies needs --replan"),
])
def test_contingencies_need_replan(tmp_path, capsys, flip_plan_file, extra, message):
    code = main(["validate", "--plan", str(flip_plan_file), "--trials", "1", "--json",
                 str(tmp_path / "v.json"), *extra])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0]
    assert not (tmp_path / "v.json").exists()


def test_validate_reports_the_pauses_of_its_replans(flip_plan_file):
    text = flip_plan_file.read_text()
    out = validate([([0.69, -0.16, 0.072], {}, text)], 2, seed=3, replan=True,
                   contingencies=True, progress=False, mode=POSITION)
    times = [land["replan"]["time_s"] for land in out["locations"][0]["landings"]]
    pause = out["summary"]["pause"]
    assert pause["trials"] == 2 and pause["worst_s"] == pytest.approx(max(times))
    off = validate([([0.69, -0.16, 0.072], {}, text)], 1, seed=3, replan=False,
                   progress=False)
    assert off["summary"]["pause"] is None


def test_the_cli_prints_the_pauses_of_its_replans(tmp_path, capsys, flip_plan_file):
    code = main(["validate", "--plan", str(flip_plan_file), "--trials", "1", "--replan",
                 "--contingencies", "--workers", "1", "--no-progress", "--json",
                 str(tmp_path / "v.json")])
    out = capsys.readouterr().out
    assert code == 0 and "pause at the sense over 1 re-plans: median" in out


def test_a_cache_shares_the_preparation_between_validations(flip_plan_file, tmp_path,
                                                            prepared):
    calls = prepared
    text = flip_plan_file.read_text()
    runs = [validate([([0.69, -0.16, 0.072], {}, text)], 1, seed=3, replan=True, mode=mode,
                     contingencies=True, progress=False, cache_dir=tmp_path)
            for mode in ("feedforward", "position")]
    assert len(calls) == 1
    assert runs[0]["locations"][0]["contingencies"] == runs[1]["locations"][0]["contingencies"]
