"""``flipkit plan translate | flip | batch`` from the command line."""

import csv
import json
import subprocess
import sys

import numpy as np
import pytest

from flipkit.behaviors.library import FLIP_NAMES
from flipkit.cli import main
from flipkit.cli.plan_inputs import read_locations
from flipkit.config import TABLE1_LOCATIONS
from flipkit.errors import ConfigError
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify import verify_plan


def _run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def _one_error_line(err):
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("flipkit: error: "), err
    assert "Traceback" not in err


def test_translate_writes_a_plan_that_verify_accepts(tmp_path, capsys):
    path = tmp_path / "t.json"
    rc, out, err = _run(capsys, "plan", "translate", "--from", 0.65, -0.30, 0.15,
                        "--to", 0.80, -0.10, 0.15, "--solver", "ipopt", "--json", path)
    assert rc == 0, err
    assert "translate solved: 1 segment(s)" in out and "iterations" in out
    assert json.loads(path.read_text())["status"] == "solved"
    rc, out, err = _run(capsys, "verify", path)
    assert rc == 0 and "plan verified" in out


@pytest.mark.parametrize("argv", [
    ["translate", "--from", "nan", "0", "0.15", "--to", "0.8", "0", "0.15"],
    ["translate", "--from", "0.7", "0", "0.15", "--to", "3.7", "0", "0.15"],
    ["translate", "--from", "0.7", "0", "--to", "0.8", "0", "0.15"],
    ["flip", "--burger", "0.3", "0.0", "0.072"],
    ["flip", "--burger", "0.75", "0.0", "inf"],
    ["flip", "--burger", "0.75", "0.0", "0.072", "--start-q", "0", "0", "0", "0", "0", "3.3"],
    ["flip", "--burger", "0.75", "0.0", "0.072", "--start-q", "0", "0", "0", "0", "0"],
    ["flip", "--burger", "0.75", "zero", "0.072"],
    ["flip", "--burger", "0.75", "0.0", "0.072", "--burger-diameter", "0.05"],
    ["flip", "--burger", "0.75", "0.0", "0.072", "--burger-diameter", "0.13"],
])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv):
    path = tmp_path / "p.json"
    rc, out, err = _run(capsys, "plan", *argv, "--json", path)
    assert rc == 2
    _one_error_line(err)
    assert not path.exists()


BAD_CSVS = {
    "missing_column": "x,y\n0.75,0.0\n",
    "non_numeric": "x,y,z\n0.75,abc,0.072\n",
    "nan": "x,y,z\n0.75,nan,0.072\n",
    "inf": "px,py,pz\n0.75,0.0,inf\n",
    "too_many_rows": "x,y,z\n" + "0.75,0.0,0.072\n" * 6,
    "empty": "",
    "header_only": "# nothing\nx,y,z\n",
    "short_row": "x,y,z\n0.75,0.0\n",
    "off_grill": "x,y,z\n0.75,0.0,0.072\n0.3,0.0,0.072\n",
}


@pytest.mark.parametrize("name", sorted(BAD_CSVS))
def test_malformed_csv_exits_2(tmp_path, capsys, name):
    src = tmp_path / "b.csv"
    src.write_text(BAD_CSVS[name])
    rc, out, err = _run(capsys, "plan", "batch", "--burgers", src, "--out", tmp_path / "out")
    assert rc == 2
    _one_error_line(err)
    assert not (tmp_path / "out").exists()


def test_csv_accepts_table1_columns_in_any_order_and_comments(tmp_path):
    src = tmp_path / "b.csv"
    src.write_text("# Table I\npy,px,pz\n-0.33,0.64,0.073\n\n# row 2\n0.00,0.75,0.073\n")
    assert read_locations(src) == [(0.64, -0.33, 0.073), (0.75, 0.0, 0.073)]
    with pytest.raises(ConfigError, match="cannot read"):
        read_locations(tmp_path / "missing.csv")


def test_real_entry_point_prints_one_line(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "flipkit", "plan", "flip", "--burger", "nan",
                           "0", "0.072", "--json", str(tmp_path / "p.json")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    _one_error_line(proc.stderr)


@pytest.fixture(scope="module")
def flip_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("flip") / "flip.json"
    # the CLI's defaults (solver auto, the package's atlas). IPOPT alone at this location
    # (0.76, 0.09) stretched the flip to 0.9 s and then found no turn back (2026-11-23); the
    # IPOPT cross-check is bench flip's ipopt column.
    loc = TABLE1_LOCATIONS[2]
    rc = main(["plan", "flip", "--burger", *map(str, loc), "--json", str(path)])
    return rc, path


def test_flip_plan_is_solved_continuous_and_verified(flip_file):
    rc, path = flip_file
    assert rc == 0
    plan = Plan.load(path)
    assert plan.status == "solved" and verify_plan(plan).ok
    assert [s.name for s in plan.segments] == list(FLIP_NAMES)
    q_home = plan.robot["q_home"]
    np.testing.assert_allclose(plan.segments[0].q[0], q_home, atol=1e-12)
    np.testing.assert_allclose(plan.segments[-1].q[-1], q_home, atol=1e-6)
    for a, b in zip(plan.segments, plan.segments[1:]):
        np.testing.assert_allclose(a.q[-1], b.q[0], atol=1e-9)
        np.testing.assert_allclose(a.qd[-1], b.qd[0], atol=1e-9)
    flip = plan.segments[FLIP_NAMES.index("flip")]
    assert flip.cone_nodes == list(range(14))  # up to the node before the release node
    assert plan.segment("flip") is flip and plan.segment("carry") is None
    k = FLIP_NAMES.index("flip")
    start = sum(float(s.T) for s in plan.segments[:k])
    assert plan.segment_span("flip") == pytest.approx((start, start + float(flip.T)))
    assert plan.segment_span("go_to_burger")[0] == 0.0 and plan.segment_span("carry") is None


def test_batch_writes_plans_and_summary(tmp_path, capsys):
    src = tmp_path / "b.csv"
    src.write_text("# one burger\npx,py,pz\n0.76,0.09,0.072\n")
    out_dir = tmp_path / "out"
    rc, out, err = _run(capsys, "plan", "batch", "--burgers", src, "--out", out_dir,
                        "--no-progress")  # auto: IPOPT alone fails here (see flip_file)
    assert rc == 0, err
    assert Plan.load(out_dir / "burger_1.json").status == "solved"
    with open(out_dir / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["status"] for r in rows] == ["solved"] and float(rows[0]["y"]) == 0.09
    assert "batch of 1: 1 solved" in out


def test_batch_warm_starts_from_the_package_atlas_unless_told_not_to(tmp_path, capsys,
                                                                      monkeypatch):
    """``plan batch`` plans each burger as ``plan flip`` does: from the package's atlas when
    it serves the default options, cold with ``--no-atlas``."""
    import flipkit.planning.planners.planner as planner
    from flipkit.planning.planners.atlas import default_atlas

    if default_atlas() is None:
        pytest.skip("no atlas shipped")
    seen = []

    def spy(pb, q=None, qd=None, **kw):
        seen.append(kw.get("atlas"))
        raise ConfigError("stopped by the test")

    monkeypatch.setattr(planner, "plan_flip", spy)
    src = tmp_path / "b.csv"
    src.write_text("x,y,z\n0.76,0.09,0.072\n")
    for extra in ((), ("--no-atlas",)):
        rc, _, err = _run(capsys, "plan", "batch", "--burgers", src, "--out", tmp_path / "o",
                          "--workers", "1", "--no-progress", *extra)
        assert rc == 2 and "stopped by the test" in err
    assert seen[0] is not None and len(seen[0]) > 0 and seen[1] is None


def test_flip_for_the_burger_the_camera_sees_records_and_checks_its_diameter(tmp_path, capsys):
    """--burger-diameter plans for that burger (cold: the package's atlas is for the 0.1 m
    one): the plan file records the diameter and verify checks the plan with it."""
    path = tmp_path / "big.json"
    rc, out, _ = _run(capsys, "plan", "flip", "--burger", "0.69", "-0.16", "0.072",
                      "--burger-diameter", "0.127", "--json", path)
    assert rc == 0 and "warm start" not in out
    plan = Plan.load(path)
    assert plan.burger["diameter"] == pytest.approx(0.127)
    assert plan.cell().burger.diameter == pytest.approx(0.127)
    assert verify_plan(plan).ok
    # the big burger's plan carries it differently from the nominal one's
    nominal = tmp_path / "nominal.json"
    assert _run(capsys, "plan", "flip", "--burger", "0.69", "-0.16", "0.072", "--json",
                nominal)[0] == 0
    a, b = (Plan.load(p).segment("flip").landing["burger_on_blade"] for p in (path, nominal))
    assert not np.allclose(a, b, atol=1e-4)
