"""Every output path is checked before any work: a directory where no file can be created
(/proc, /sys), a file name longer than the file system takes, and a URDF name that long in a
plan are one line and exit 2, with nothing written."""

import json
import os
import time

import pytest

from flipkit.cli import main

LONG = "a" * 300  # bytes: over the 255 of a file name

LOC = ("0.69", "-0.16", "0.072")


def _refused(capsys, argv, words, max_s=30.0) -> str:
    t0 = time.perf_counter()
    rc = main([str(a) for a in argv])
    took = time.perf_counter() - t0
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert err.startswith("flipkit: error:") and all(w in err for w in words), err
    assert took < max_s, took
    return err


def _commands(plan, out_dir, name):
    return [
        ["export", plan, "--format", "ros2", "--out", f"{out_dir}/{name}.yaml"],
        ["export", plan, "--csv", f"{out_dir}/{name}.csv"],
        ["view", plan, "--html", f"{out_dir}/{name}.html"],
        ["verify", plan, "--json", f"{out_dir}/{name}.json"],
        ["plan", "flip", "--burger", *LOC, "--json", f"{out_dir}/{name}.json"],
        ["plan", "translate", "--from", "0.6", "-0.1", "0.2", "--to", "0.7", "0", "0.25",
         "--json", f"{out_dir}/{name}.json"],
    ]


@pytest.mark.parametrize("where", ["/proc", "/sys"])
@pytest.mark.parametrize("k", range(6))
def test_an_output_where_no_file_can_be_made_is_refused_first(flip_plan_file, capsys,
                                                              monkeypatch, where, k):
    from flipkit.planning.planners import chain

    def no_solve(*args, **kwargs):
        raise AssertionError("a solver ran before the output path was checked")

    monkeypatch.setattr(chain, "solve_segment", no_solve)
    argv = _commands(flip_plan_file, where, "out")[k]
    _refused(capsys, argv, [where, "not writable"])


@pytest.mark.parametrize("k", range(6))
def test_an_output_name_too_long_is_refused_first(flip_plan_file, tmp_path, capsys, k):
    argv = _commands(flip_plan_file, tmp_path, LONG)[k]
    line = _refused(capsys, argv, ["a file name of 30", "255 bytes"])
    assert len(line) < 300 and os.listdir(tmp_path) == []


def test_a_batch_directory_name_too_long_is_refused(tmp_path, capsys):
    burgers = tmp_path / "b.csv"
    burgers.write_text("x,y,z\n0.69,-0.16,0.072\n")
    _refused(capsys, ["plan", "batch", "--burgers", burgers, "--out", tmp_path / LONG],
             ["--out", "255 bytes"])
    _refused(capsys, ["plan", "batch", "--burgers", burgers, "--out", "/proc/batch"],
             ["--out", "not writable"])
    assert os.listdir(tmp_path) == ["b.csv"]


def test_a_plan_naming_a_urdf_too_long_is_one_line(flip_plan_file, tmp_path, capsys):
    doc = json.loads(flip_plan_file.read_text())
    doc["robot"]["urdf"] = str(tmp_path / f"{LONG}.urdf")
    path = tmp_path / "p.json"
    path.write_text(json.dumps(doc))
    for argv in (["verify", path], ["export", path, "--csv", tmp_path / "e.csv"]):
        line = _refused(capsys, argv, ["robot.urdf", "File name too long"])
        assert len(line) < 400
    assert os.listdir(tmp_path) == ["p.json"]


def test_the_probe_leaves_nothing(tmp_path):
    from flipkit.fileio import check_output

    check_output(tmp_path / "x.json", "--json", (".json",))
    assert os.listdir(tmp_path) == []
