"""Hostile inputs to every command: each is refused with exit 2 and one line on stderr, no
traceback, no file written and no input changed (issue 28: one gate before anything runs,
inputs never overwritten, bounds and messages)."""

import hashlib
import json
import math
import os
import re
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from flipkit.cli import main

Q_HOME = (-0.988933, -1.792774, 2.362261, -0.569486, 0.581863, 1.570796)
LOC = ("0.69", "-0.16", "0.072")


def refused(capsys, argv, *, inputs=(), outputs=(), contains=(), watch=None) -> str:
    """Run the CLI in-process; assert exit 2, one line, no traceback, ``outputs`` absent,
    ``inputs`` byte-for-byte unchanged and no new file in ``watch``; return the line."""
    before = {Path(p): Path(p).read_bytes() for p in inputs}
    listing = sorted(os.listdir(watch)) if watch else None
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith("flipkit: error:"), err
    assert "Traceback" not in err
    for text in contains:
        assert text in lines[0], lines[0]
    for p in outputs:
        assert not Path(p).exists(), p
    for p, data in before.items():
        assert p.read_bytes() == data, p
    if watch:
        assert sorted(os.listdir(watch)) == listing
    return lines[0]


@pytest.fixture(scope="module")
def translate_file(tmp_path_factory):
    """A solved translate plan (one short NLP, about 1 s)."""
    from flipkit.planning.planners.planner import plan_translate

    plan = plan_translate((0.6, -0.1, 0.2), (0.7, 0.0, 0.25))
    assert plan.status == "solved", plan.failure
    return plan.to_json(tmp_path_factory.mktemp("translate") / "translate.json")


@pytest.fixture
def plan_copy(translate_file, tmp_path):
    path = tmp_path / "plan.json"
    path.write_bytes(translate_file.read_bytes())
    return path


@pytest.fixture(scope="module")
def unverified_flip(flip_plan_file, tmp_path_factory):
    """A flip plan still marked solved whose pickup was moved by 0.05 rad at one node: verify
    fails it (interpolant, dynamics)."""
    doc = json.loads(flip_plan_file.read_text())
    doc["segments"][2]["q"][5][0] += 0.05
    assert doc["status"] == "solved"
    path = tmp_path_factory.mktemp("unverified") / "unverified.json"
    path.write_text(json.dumps(doc))
    return path


# ------------------------------------------------------------------ one gate before anything runs
@pytest.mark.parametrize("command", ["validate", "animate", "export"])
def test_an_unverified_solved_plan_is_never_run(unverified_flip, tmp_path, capsys, command):
    out = {"validate": tmp_path / "v.json", "animate": tmp_path / "a.gif",
           "export": tmp_path / "e.csv"}[command]
    argv = {"validate": ["validate", "--plan", unverified_flip, "--trials", "1", "--workers",
                         "1", "--no-progress", "--json", out],
            "animate": ["animate", unverified_flip, "--out", out, "--no-progress"],
            "export": ["export", unverified_flip, "--rate", "100", "--csv", out]}[command]
    refused(capsys, argv, inputs=[unverified_flip], outputs=[out], watch=tmp_path,
            contains=["plan fails", "flipkit verify"])


def test_validate_plan_file_gates_the_library_call_too(unverified_flip):
    from flipkit.errors import VerificationError
    from flipkit.experiments.trials import validate_plan_file

    with pytest.raises(VerificationError, match="plan fails"):
        validate_plan_file(unverified_flip, 1, progress=False)


def test_verify_fails_a_plan_inside_the_singularity_margin(translate_file):
    from flipkit.planning.plans.plan_file import Plan
    from flipkit.planning.plans.verify import verify_plan

    assert verify_plan(Plan.load(translate_file)).groups["singularity"].ok
    plan = Plan.load(translate_file)
    seg = plan.segments[0]
    seg.q[:, 4] = 0.1  # q5 0.1 rad from sin q5 = 0, inside the 0.2 rad margin
    report = verify_plan(plan)
    assert not report.groups["singularity"].ok and not report.ok
    assert report.groups["singularity"].violation == pytest.approx(0.1)


@pytest.mark.parametrize("q, joint", [
    (("0",) * 6, "q3 (elbow)"),
    ((*map(str, Q_HOME[:4]), "0", str(Q_HOME[5])), "q5 (wrist)"),
])
def test_a_start_q_inside_the_singularity_margin_is_refused(tmp_path, capsys, q, joint):
    out = tmp_path / "p.json"
    refused(capsys, ["plan", "flip", "--burger", *LOC, "--start-q", *q, "--no-atlas",
                     "--json", out], outputs=[out], contains=["--start-q", joint, "0.2"])


# ------------------------------------------------------------------ inputs never overwritten
def test_outputs_that_name_an_input_are_refused(plan_copy, tmp_path, capsys):
    refused(capsys, ["verify", plan_copy, "--json", plan_copy], inputs=[plan_copy],
            watch=tmp_path, contains=["--json", "is an input"])
    link = tmp_path / "link.json"
    link.symlink_to(plan_copy)
    refused(capsys, ["verify", plan_copy, "--json", link], inputs=[plan_copy],
            watch=tmp_path, contains=["is an input"])
    refused(capsys, ["export", plan_copy, "--rate", "100", "--csv", plan_copy],
            inputs=[plan_copy], watch=tmp_path, contains=["--csv", ".csv"])


def test_schedule_json_onto_the_cook_order_is_refused(tmp_path, capsys):
    cook = tmp_path / "cook.csv"
    cook.write_text("burger,t_drop,x,y\nb1,0,0.69,-0.16\n")
    refused(capsys, ["schedule", cook, "--json", cook], inputs=[cook], watch=tmp_path,
            contains=["--json", ".json"])


def test_plan_json_onto_the_atlas_is_refused(tmp_path, capsys):
    from flipkit.planning.planners.atlas import default_path

    atlas = tmp_path / "atlas.json"  # a .json name, so only the same-file check can refuse
    atlas.write_bytes(default_path().read_bytes())
    refused(capsys, ["plan", "flip", "--burger", *LOC, "--atlas", atlas, "--json", atlas],
            inputs=[atlas], watch=tmp_path, contains=["is an input"])


def test_bad_outputs_are_found_before_any_work(tmp_path, capsys):
    missing = tmp_path / "no" / "such" / "p.json"
    refused(capsys, ["plan", "translate", "--from", "0.6", "-0.1", "0.2", "--to", "0.7", "0",
                     "0.25", "--json", missing], watch=tmp_path, contains=["does not exist"])
    burgers = tmp_path / "b.csv"
    burgers.write_text("x,y,z\n0.69,-0.16,0.072\n")
    refused(capsys, ["plan", "batch", "--burgers", burgers, "--out", burgers],
            inputs=[burgers], watch=tmp_path, contains=["--out", "not a directory"])
    cook = tmp_path / "cook.csv"
    cook.write_text("burger,t_drop,x,y\nb1,0,0.69,-0.16\n")
    refused(capsys, ["schedule", cook, "--json", tmp_path / "t.json", "--figure",
                     tmp_path / "t.xyz"], inputs=[cook], watch=tmp_path,
            contains=["--figure", ".pdf or .png or .svg"])
    refused(capsys, ["atlas", "build", "--out", tmp_path / "a.json"], watch=tmp_path,
            contains=["--out", ".npz"])
    refused(capsys, ["animate", "p.json", "--out", tmp_path / "a.avi"], watch=tmp_path,
            contains=["--out", ".gif or .mp4"])


def test_batch_out_directory_holding_the_input_is_refused(tmp_path, capsys):
    burgers = tmp_path / "summary.csv"
    burgers.write_text("x,y,z\n0.69,-0.16,0.072\n")
    refused(capsys, ["plan", "batch", "--burgers", burgers, "--out", tmp_path],
            inputs=[burgers], watch=tmp_path, contains=["would overwrite the input"])


def test_an_interrupted_write_leaves_the_old_file(tmp_path):
    from flipkit.fileio import replace_with, write_text

    path = tmp_path / "out.json"
    path.write_text("old")

    def broken(tmp):
        tmp.write_text("half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        replace_with(path, broken)
    assert path.read_text() == "old" and os.listdir(tmp_path) == ["out.json"]
    write_text(path, "new")
    assert path.read_text() == "new" and os.listdir(tmp_path) == ["out.json"]
    fresh = write_text(tmp_path / "fresh.json", "{}")
    mask = os.umask(0o022)
    os.umask(mask)
    assert stat.S_IMODE(fresh.stat().st_mode) == 0o666 & ~mask  # as open() creates it


# ------------------------------------------------------------------ bounds
@pytest.mark.parametrize("argv, flag", [
    (["validate", "--plan", "p.json", "--trials", "1000000", "--json", "v.json"], "--trials"),
    (["validate", "--plan", "p.json", "--trials", "0", "--json", "v.json"], "--trials"),
    (["atlas", "build", "--grid", "1000", "1000"], "--grid"),
    (["compare-ik", "--grid", "0", "2", "--json", "c.json"], "--grid"),
    (["export", "p.json", "--rate", "0.001", "--csv", "e.csv"], "--rate"),
    (["export", "p.json", "--rate", "1e9", "--csv", "e.csv"], "--rate"),
    (["plan", "batch", "--burgers", "b.csv", "--out", "o", "--workers", "0"], "--workers"),
    (["animate", "p.json", "--out", "a.gif", "--fps", "0"], "--fps"),
])
def test_numeric_options_out_of_range(tmp_path, capsys, monkeypatch, argv, flag):
    monkeypatch.chdir(tmp_path)
    line = refused(capsys, argv, watch=tmp_path, contains=[flag, "["])
    assert re.search(r"\[[-0-9.e]+, [-0-9.e]+\]", line)


@pytest.mark.parametrize("extra, contains", [
    (["--mode", "position", "--servo-lookahead", "0.01"], ["--servo-lookahead", "0 (no smoothing)",
                                                          "[0.03, 0.2] s"]),
    (["--mode", "position", "--servo-lookahead", "nan"], ["--servo-lookahead", "[0.03, 0.2] s"]),
    (["--servo-lookahead", "0.1"], ["--servo-lookahead needs --mode position"]),
])
def test_the_servo_lookahead_is_a_servoj_one_and_for_position_commands(tmp_path, capsys,
                                                                        monkeypatch, extra,
                                                                        contains):
    monkeypatch.chdir(tmp_path)
    refused(capsys, ["validate", "--plan", "p.json", "--trials", "1", "--json", "v.json",
                     *extra], watch=tmp_path, contains=contains)


def test_t_drop_is_bounded(tmp_path, capsys):
    cook = tmp_path / "cook.csv"
    cook.write_text("burger,t_drop,x,y\nb1,1e308,0.69,-0.16\n")
    refused(capsys, ["schedule", cook, "--json", tmp_path / "t.json"], inputs=[cook],
            watch=tmp_path, contains=["t_drop must be <= 86400 s"])


def test_yaw_is_wrapped():
    from flipkit.cli.plan_inputs import yaw as _yaw

    assert _yaw("6.283185307") == pytest.approx(0.0, abs=1e-9)
    assert _yaw(str(math.pi)) == pytest.approx(math.pi)
    assert _yaw(str(-math.pi)) == pytest.approx(math.pi)
    assert _yaw("-4") == pytest.approx(2 * math.pi - 4)


# ------------------------------------------------------------------ messages
def test_a_burger_height_off_the_grill_states_the_tolerance(tmp_path, capsys):
    refused(capsys, ["plan", "flip", "--burger", "0.69", "-0.16", "0.09", "--json",
                     tmp_path / "p.json"], watch=tmp_path, contains=["+-0.01 m", "0.072"])


def test_the_height_tolerance_is_the_planners(cell):
    from flipkit.behaviors.targets import BURGER_HEIGHT_TOL, check_location
    from flipkit.errors import UnreachableError

    h = cell.grill.height
    check_location(cell, (0.69, -0.16, h + 0.99 * BURGER_HEIGHT_TOL))
    with pytest.raises(UnreachableError):
        check_location(cell, (0.69, -0.16, h + 1.01 * BURGER_HEIGHT_TOL))


def test_a_serve_spot_off_the_table_says_so(tmp_path, capsys):
    line = refused(capsys, ["plan", "serve", "--burger", *LOC, "--table-spot", "5", "5",
                            "--no-atlas", "--json", tmp_path / "p.json"], watch=tmp_path,
                   contains=["--table-spot", "off the table"])
    assert "inf" not in line


def test_batch_refuses_two_burgers_on_one_spot(tmp_path, capsys):
    burgers = tmp_path / "b.csv"
    burgers.write_text("x,y,z\n0.69,-0.16,0.072\n0.70,-0.16,0.072\n")
    refused(capsys, ["plan", "batch", "--burgers", burgers, "--out", tmp_path / "o"],
            inputs=[burgers], watch=tmp_path, contains=["burgers 1 and 2", "diameter"])


def test_a_non_npz_atlas_gets_no_pickle_advice(plan_copy, tmp_path, capsys):
    line = refused(capsys, ["plan", "flip", "--burger", *LOC, "--atlas", plan_copy, "--json",
                            tmp_path / "p.json"], inputs=[plan_copy], watch=tmp_path,
                   contains=["not an .npz archive"])
    assert "pickle" not in line


def test_a_cook_order_with_a_byte_order_mark_is_read(tmp_path):
    from flipkit.planning.kitchen.cook import read_cook_csv

    cook = tmp_path / "cook.csv"
    cook.write_bytes("burger,t_drop,x,y\nb1,0,0.69,-0.16\n".encode("utf-8-sig"))
    assert [b.burger for b in read_cook_csv(cook)] == ["b1"]


def test_more_burgers_than_table_spots_are_not_refused(cell):
    from flipkit.planning.kitchen.cook import CookBurger, check_cook, table_spots

    n = len(table_spots(cell)) + 1  # served spots free up after the dwell (issue 32)
    order = [CookBurger(f"b{k}", 200.0 * k, 0.69, -0.16) for k in range(n)]
    assert len(check_cook(order, cell)) == n


@pytest.mark.parametrize("path, reason", [("/dev/zero", "not a regular file"),
                                          ("/", "is a directory")])
def test_a_device_is_not_reported_missing(capsys, path, reason):
    line = refused(capsys, ["verify", path], contains=[reason])
    assert "not found" not in line


def test_deeply_nested_json_is_one_line(tmp_path, capsys):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    refused(capsys, ["verify", deep], inputs=[deep], watch=tmp_path, contains=["nested"])


def _with_urdf(plan_file, tmp_path, text, sha=True, fmt=None):
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(text)
    doc = json.loads(plan_file.read_text())
    doc["robot"]["urdf"] = str(urdf)
    if sha:
        doc["robot"]["urdf_sha256"] = hashlib.sha256(urdf.read_bytes()).hexdigest()
    else:
        doc["robot"].pop("urdf_sha256")
        doc["format"] = "flipkit-plan/1"
    path = tmp_path / "p.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("text, sha", [
    ("not xml at all", True),
    ('<robot name="r"><link name="a"/><joint name="j" type="revolute"><parent link="x"/>'
     "</joint></robot>", True),
    ("not xml at all", False),
])
def test_a_urdf_that_is_not_a_urdf_is_one_line(translate_file, tmp_path, capsys, text, sha):
    path = _with_urdf(translate_file, tmp_path, text, sha)
    refused(capsys, ["verify", path, "--json", tmp_path / "r.json"], inputs=[path],
            watch=tmp_path, contains=["robot.urdf"])


def test_a_sha_mismatch_prints_no_digest_of_the_file_found(translate_file, tmp_path, capsys):
    path = _with_urdf(translate_file, tmp_path, "<robot/>")
    doc = json.loads(path.read_text())
    doc["robot"]["urdf_sha256"] = "0" * 64
    path.write_text(json.dumps(doc))
    line = refused(capsys, ["verify", path], inputs=[path], contains=["sha256 differs"])
    assert not re.search(r"[0-9a-f]{12}", line)


# ------------------------------------------------------------------ quick refusals
MALFORMED = {"not_json": "{oops", "no_keys": '{"format": "flipkit-plan/2"}',
             "list": "[1, 2]", "deep": "[" * 50_000 + "]" * 50_000}


@pytest.mark.parametrize("name", MALFORMED)
def test_a_malformed_plan_is_refused_before_the_heavy_imports(tmp_path, name):
    """In a fresh interpreter: refused, exit 2, and neither jsonschema nor pinocchio imported
    (each costs about 0.5-1 s)."""
    bad = tmp_path / "bad.json"
    bad.write_text(MALFORMED[name])
    script = ("import sys; from flipkit.cli import main; rc = main(sys.argv[1:]); "
              "print(rc, 'jsonschema' in sys.modules, 'pinocchio' in sys.modules)")
    run = subprocess.run([sys.executable, "-c", script, "verify", str(bad)],
                         capture_output=True, text=True, timeout=60)
    assert run.stdout.split() == ["2", "False", "False"], run.stdout + run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and "Traceback" not in run.stderr


@pytest.mark.parametrize("argv", [
    ["export", "{plan}", "--rate", "100", "--csv", "{plan}"],
    ["verify", "{deep}"],
])
def test_refusals_in_a_subprocess(plan_copy, tmp_path, argv):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    argv = [a.format(plan=plan_copy, deep=deep) for a in argv]
    before = plan_copy.read_bytes()
    run = subprocess.run([sys.executable, "-m", "flipkit", *argv], capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert "Traceback" not in run.stderr and plan_copy.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["deep.json", "plan.json"]


def test_the_animation_formats_are_the_renderers():
    from flipkit.cli.animate import FORMATS
    from flipkit.simulation.animate import FORMATS as RENDERED

    assert FORMATS == RENDERED


@pytest.mark.parametrize("goal, names", [
    (("1.10", "0", "0.30"), ("goal (1.10, 0.00, 0.30)", "wall", "margin 2 cm")),
    (("0.70", "-0.20", "0.10"), ("goal (0.70, -0.20, 0.10)", "handle", "grill", "1.8 cm"))])
def test_an_infeasible_translate_goal_is_explained_before_any_nlp(tmp_path, capsys,
                                                                   monkeypatch, goal, names):
    """Issue 28 item 4: every IK branch is checked against the joint bounds and the cell
    first; the refusal names the link, the box and the distance, and no solver runs."""
    from flipkit.planning.planners import chain

    def no_solve(*args, **kwargs):
        raise AssertionError("a solver ran for a goal the pre-check refuses")

    monkeypatch.setattr(chain, "solve_segment", no_solve)
    out = tmp_path / "t.json"
    refused(capsys, ["plan", "translate", "--from", "0.62", "-0.20", "0.30", "--to", *goal,
                     "--json", out], outputs=[out], contains=names)
