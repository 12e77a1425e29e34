"""``flipkit compare-ik`` on one Table I location with the default solver ``auto`` (IPOPT alone
no longer converges on this flip since the arm's clearance rows, issue 13): the output schema, the
collocation plan passes the independent check, the baseline names a reason from its tuple,
and the Dask executor gives the same outcome as local processes."""

import json

import numpy as np
import pytest

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.baseline import REASONS
from flipkit.baseline.classify import FAILURE_CLASSES
from flipkit.cli import main
from flipkit.experiments.compare_ik import compare_ik, plan_filename
from flipkit.config import TABLE1_LOCATIONS
from flipkit.planning.plans.plan_file import Plan
from flipkit.experiments.sweep import make_executor
from flipkit.planning.plans.verify import verify_plan

LOCATION = TABLE1_LOCATIONS[1]  # (0.75, 0.00, 0.073): IPOPT solves it, the IK baseline fails
COLLOCATION_KEYS = {"status", "reason", "time_s", "judge"}
EE_IK_KEYS = {"status", "reason", "class", "subbehavior", "amount", "time_scaling", "time_s",
              "time_breakdown_s", "durations_s", "segments"}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The CLI on local worker processes, with a cache and the plans kept."""
    tmp = tmp_path_factory.mktemp("compare")
    out, cache, plans = tmp / "out.json", tmp / "cache", tmp / "plans"
    argv = ["compare-ik", "--burger", *map(str, LOCATION), "--solver", "auto", "--workers", "1",
            "--cache", str(cache), "--plans", str(plans), "--no-progress", "--json", str(out)]
    assert main(argv) == 0
    return json.loads(out.read_text()), argv, out, plans


def test_output_schema(run):
    doc = run[0]
    assert set(doc) == {"locations", "summary"}
    (entry,) = doc["locations"]
    assert set(entry) == {"location", "collocation", "ee_ik"}
    assert entry["location"] == pytest.approx(list(LOCATION))
    assert set(entry["collocation"]) == COLLOCATION_KEYS
    assert set(entry["ee_ik"]) == EE_IK_KEYS
    for method in ("collocation", "ee_ik"):
        assert entry[method]["status"] in ("solved", "failed")
    assert entry["collocation"]["time_s"] > 0
    assert entry["ee_ik"]["time_s"] > 0 and set(entry["ee_ik"]["time_breakdown_s"]) <= set(
        FLIP_NAMES)
    assert entry["ee_ik"]["class"] in FAILURE_CLASSES + (None,)
    s = doc["summary"]
    assert s["locations"] == 1 and set(s["success_fraction"]) == {"collocation", "ee_ik"}
    assert set(s["ik_failure_reasons"]) == set(REASONS)
    assert set(s["ik_failure_classes"]) == set(FAILURE_CLASSES)
    segs = entry["ee_ik"]["segments"]  # every subbehaviour run, the first failure among them
    assert [g["subbehavior"] for g in segs] == list(FLIP_NAMES)[:len(segs)]
    first = next(g for g in segs if g["status"] != "solved")
    assert first["subbehavior"] == entry["ee_ik"]["subbehavior"]
    assert first["class"] == entry["ee_ik"]["class"]
    order = ("solved", "time_scalable", "dynamic", "kinematic", "ee")
    worst = max((g["class"] or "solved" for g in segs), key=order.index)
    assert s["ik_worst_classes"][worst] == 1 and sum(s["ik_worst_classes"].values()) == 1
    judge = entry["collocation"]["judge"]
    assert judge["status"] in ("solved", "failed") and sum(s["collocation_judge"].values()) == 1
    assert set(s["median_time_s"]["collocation"]) == set(FLIP_NAMES) | {"total"}
    assert set(s["median_time_s"]["ee_ik"]) == set(FLIP_NAMES)


def test_collocation_plan_passes_verify(run):
    doc, _, _, plans = run
    c = doc["locations"][0]["collocation"]
    assert c["status"] == "solved" and c["reason"] is None
    plan = Plan.load(plans / plan_filename(LOCATION, "auto"))
    assert plan.status == "solved" and verify_plan(plan).ok
    assert doc["summary"]["success_fraction"]["collocation"] == 1.0


def test_the_judge_passes_the_collocation_plan_and_catches_a_jump(run):
    """The baseline's judge on the collocation plan at 500 Hz: every segment passes (limits
    between the nodes, clear of the singularities); the same path with a 0.3 rad step injected
    into one joint is a configuration jump."""
    from flipkit.baseline.classify import classify_plan, classify_segment, resample_segment

    doc, _, _, plans = run
    assert doc["locations"][0]["collocation"]["judge"]["status"] == "solved"
    plan = Plan.load(plans / plan_filename(LOCATION, "auto"))
    verdicts = classify_plan(plan, 500.0)
    assert [v.status for v in verdicts] == ["solved"] * 5
    assert min(v.measures["sigma_min"] for v in verdicts) >= 0.01
    seg = plan.segments[3]  # the flip
    t, q = resample_segment(seg, 500.0)
    robot = plan.robot_for(seg, plan.cell())
    q[len(t) // 2:, 1] += 0.3  # rad, shoulder; the references are the path's own poses, as
    M = [robot.placement(qk) for qk in q]  # classify_plan takes them for a joint-space plan
    v = classify_segment(seg.name, robot, t, q, np.array([m.translation for m in M]),
                          np.array([m.rotation for m in M]))
    assert (v.reason, v.failure_class) == ("configuration_jump", "kinematic")
    assert v.amount == pytest.approx(0.3, abs=0.02)


def test_ee_ik_failure_has_a_reason_from_the_tuple(run):
    doc = run[0]
    e = doc["locations"][0]["ee_ik"]
    assert e["status"] == "failed"
    assert e["reason"] in REASONS and e["subbehavior"] in FLIP_NAMES
    assert isinstance(e["amount"], float)
    assert doc["summary"]["ik_failure_reasons"][e["reason"]] == 1


def test_rerun_reads_the_cache(run):
    doc, argv, out, _ = run
    out.unlink()
    assert main(argv) == 0  # everything cached: instant, same answer
    assert json.loads(out.read_text()) == doc


def test_dask_executor_gives_the_same_statuses(run):
    from dask.distributed import LocalCluster

    want = run[0]["locations"][0]
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        with make_executor(cluster.scheduler_address, None) as executor:
            got = compare_ik([LOCATION], "auto", executor, cache_dir=None, progress=False)
    entry = got["locations"][0]
    for method in ("collocation", "ee_ik"):
        assert entry[method]["status"] == want[method]["status"]
    assert entry["ee_ik"]["reason"] == want["ee_ik"]["reason"]
    assert entry["ee_ik"]["subbehavior"] == want["ee_ik"]["subbehavior"]


@pytest.mark.parametrize("extra, message", [
    ([], "give --locations"),
    (["--burger", "0.2", "0.0", "0.072"], "outside the grill"),
    (["--burger", "nan", "0.0", "0.072"], "finite"),
    (["--grid", "0", "2"], "--grid must be an integer in [1, 50]"),
])
def test_bad_input_exits_2(tmp_path, capsys, extra, message):
    assert main(["compare-ik", *extra, "--json", str(tmp_path / "o.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err
    assert not (tmp_path / "o.json").exists()
