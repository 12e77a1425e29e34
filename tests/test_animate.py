"""``flipkit animate``: a tiny GIF renders; bad input fails with one line and exit 2."""

import json

import numpy as np
import pytest
from PIL import Image

from flipkit.simulation.animate import frame_indices, key_frames, write_filmstrip
from flipkit.cli import main
from flipkit.cli.animate import MODES as CLI_MODES
from flipkit.simulation.execute import MODES, execute_plan


def test_tiny_gif_has_frames(flip_plan_file, tmp_path):
    out = tmp_path / "run.gif"
    assert main(["animate", str(flip_plan_file), "--out", str(out), "--fps", "2", "--width",
                 "64", "--height", "48", "--no-progress"]) == 0
    img = Image.open(out)
    assert img.size == (64, 48) and img.n_frames > 1
    frames = []
    for i in range(img.n_frames):
        img.seek(i)
        frames.append(np.asarray(img.convert("RGB"), float))
    assert max(np.abs(f - frames[0]).max() for f in frames[1:]) > 0  # the arm moves


def test_filmstrip_and_key_frames(flip_plan, tmp_path):
    ex = execute_plan(flip_plan, hold=0.3)
    keys = key_frames(ex)
    assert list(keys) == ["release", "mid_flight", "landing"]
    r, mid, land = keys.values()
    assert r is not None and land is not None  # the plan's burger leaves the blade and lands
    t0, t1 = ex.bounds["flip"]
    assert t0 <= ex.run.t[r] <= t1 and r < mid < land  # release inside the flip, then flight
    assert abs(ex.run.t[mid] - 0.5 * (ex.run.t[r] + ex.run.t[land])) <= 1e-3
    assert not ex.run.touch_spatula[r + 1:land].any() and not ex.run.touch_grill[r + 1:land].any()
    out = write_filmstrip(ex, tmp_path / "strip.png", 80, 60)
    assert Image.open(out).size[0] > Image.open(out).size[1]


def test_frame_indices_follow_the_clock():
    t = np.arange(0, 2.0005, 0.001)
    idx = frame_indices(t, 10)
    assert len(idx) == 21 and np.allclose(np.diff(t[idx]), 0.1)


def test_cli_modes_are_execute_modes():
    assert CLI_MODES == MODES


@pytest.fixture
def failed_plan(flip_plan_file, tmp_path):
    doc = json.loads(flip_plan_file.read_text())
    doc["status"] = "failed"
    path = tmp_path / "failed.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("case, message", [
    ("extension", "give a file ending in .gif or .mp4"), ("missing", "cannot read"),
    ("failed", "solved flip plan"), ("not_json", "JSON"),
])
def test_bad_input_exits_2(flip_plan_file, failed_plan, tmp_path, capsys, case, message):
    bad = tmp_path / "bad.json"
    bad.write_text("{oops")
    plan = {"missing": tmp_path / "nope.json", "failed": failed_plan, "not_json": bad}.get(
        case, flip_plan_file)
    out = tmp_path / ("run.avi" if case == "extension" else "run.gif")
    code = main(["animate", str(plan), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and message in err, err
    assert not out.exists()
