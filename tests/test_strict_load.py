"""Strict parsing of a plan file, shared by ``Plan.load`` and every command: a time grid that
does not increase, more nodes than bounded and a repeated key are refused on load with the
field named; no command gets as far as a traceback."""

import json
import time

import pytest

from flipkit.cli import main
from flipkit.errors import PlanFileError
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.json_fields import MAX_NODES


def _swap_t(doc):
    t = doc["segments"][1]["t"]
    t[5], t[6] = t[6], t[5]


def _long_t(doc):
    doc["segments"][0]["t"] = [i * 1e-6 for i in range(1_000_001)]


def _many_nodes(doc):
    seg, n = doc["segments"][0], 50_001
    seg["t"] = [seg["T"] * i / (n - 1) for i in range(n)]
    for key in ("q", "qd", "qdd", "u"):
        seg[key] = [seg[key][0]] * n


@pytest.mark.parametrize("edit, words", [
    (_swap_t, ["segments[1].t: node times must increase strictly", "t[5]"]),
    (_long_t, ["segments[0].t:", "1000001", f"{MAX_NODES - 1}"]),
    (_many_nodes, ["segments[0].t:", "50001"]),
])
def test_a_bad_time_grid_is_refused_on_load(flip_plan_file, tmp_path, capsys, edit, words):
    doc = json.loads(flip_plan_file.read_text())
    edit(doc)
    path = tmp_path / "p.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(PlanFileError) as info:
        Plan.load(path)
    line = str(info.value)
    assert "\n" not in line and all(w in line for w in words), line
    assert "segments[0].q" not in line  # the node times are blamed, not q
    for argv in (["verify", path], ["export", path, "--csv", tmp_path / "e.csv"],
                 ["view", path, "--html", tmp_path / "v.html"]):
        t0 = time.perf_counter()
        rc = main([str(a) for a in argv])
        err = capsys.readouterr().err.strip()
        assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
        assert words[0] in err and time.perf_counter() - t0 < 30
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.json"]


def test_a_repeated_key_anywhere_is_refused(flip_plan_file, tmp_path):
    text = flip_plan_file.read_text()
    nested = text.replace('"r_land":', '"r_land": 10.0, "r_land":', 1)
    path = tmp_path / "p.json"
    path.write_text(nested)
    with pytest.raises(PlanFileError, match="duplicate key 'r_land'"):
        Plan.load(path)


def test_a_repeated_key_in_an_atlas_header_is_refused(tmp_path):
    import numpy as np

    from flipkit.errors import AtlasError
    from flipkit.planning.planners.atlas import Atlas

    bad = tmp_path / "a.npz"
    np.savez(bad, header=np.array('{"format": 1, "format": 2}'), locations=np.zeros((1, 3)))
    with pytest.raises(AtlasError, match="duplicate key 'format'"):
        Atlas.load(bad)
