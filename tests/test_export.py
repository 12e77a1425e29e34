"""Export: resampling at a controller rate reproduces the plan at its nodes and its cubics."""

import numpy as np
import pytest
from test_plan import models  # noqa: F401  (fixture)
from test_plan import translate_plan

from flipkit.cli import main
from flipkit.errors import FlipkitError
from flipkit.planning.plans.export import resample, write_csv
from flipkit.planning.plans.plan_file import Plan

RATE = 100.0  # Hz; the plan lasts 1.0 + 0.8 s


@pytest.fixture(scope="module")
def plan(models):
    return translate_plan(models)


def _read(path):
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1)


def test_csv_columns_rows_and_nodes(plan, tmp_path):
    rows = write_csv(plan, tmp_path / "out.csv", RATE)
    header, data = _read(tmp_path / "out.csv")
    assert header == ["t"] + [f"q{j}" for j in range(1, 7)] + [f"qd{j}" for j in range(1, 7)]
    assert rows == data.shape[0] == round(1.8 * RATE) + 1 and data.shape[1] == 13
    np.testing.assert_allclose(data[:, 0], np.arange(rows) / RATE, rtol=0, atol=1e-15)
    # Node spacing 0.05 s (first segment) and 0.04 s (second): every 5th / 4th row is a node.
    first, second = plan.segments
    np.testing.assert_allclose(data[0:101:5, 1:7], first.q, atol=1e-12)
    np.testing.assert_allclose(data[0:100:5, 7:], first.qd[:-1], atol=1e-12)
    np.testing.assert_allclose(data[100::4, 1:7], second.q, atol=1e-12)
    np.testing.assert_allclose(data[100::4, 7:], second.qd, atol=1e-12)


def test_between_nodes_a_cubic_is_reproduced_exactly(plan):
    t, q, qd = resample(plan, 1000.0)
    seg = plan.segments[0]
    inside = t <= seg.T
    s, d = t[inside] / seg.T, seg.q[-1] - seg.q[0]
    np.testing.assert_allclose(q[inside], seg.q[0] + np.outer(3 * s**2 - 2 * s**3, d), atol=1e-12)
    np.testing.assert_allclose(qd[inside], np.outer(6 * s - 6 * s**2, d) / seg.T, atol=1e-12)
    assert t.size == 1801 and np.all(np.diff(t) > 0)


def test_unsolved_plans_need_force(models, tmp_path):
    plan = translate_plan(models)
    plan.status = "failed"
    with pytest.raises(FlipkitError, match="use --force"):
        resample(plan, RATE)
    assert resample(plan, RATE, force=True)[0].size == 181
    path = plan.to_json(tmp_path / "failed.json")
    assert main(["export", str(path), "--rate", "100", "--csv", str(tmp_path / "o.csv")]) == 2
    assert main(["export", str(path), "--rate", "100", "--csv", str(tmp_path / "o.csv"),
                 "--force"]) == 0


@pytest.mark.parametrize("rate", [0.0, -5.0, float("nan"), float("inf"), "fast"])
def test_bad_rates(plan, rate):
    with pytest.raises(FlipkitError, match="rate must be"):
        resample(plan, rate)


def test_cli(plan, tmp_path, capsys):
    path = plan.to_json(tmp_path / "plan.json")
    out = tmp_path / "traj.csv"
    assert main(["export", str(path), "--rate", "250", "--csv", str(out)]) == 0
    assert "wrote 461 rows" in capsys.readouterr().out  # 451 on the grid, 10 nodes off it
    assert _read(out)[1].shape == (461, 13)
    assert main(["export", str(path), "--rate", "-1", "--csv", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("flipkit: error:") and "rate must be" in err and "\n" not in err
    assert main(["export", str(tmp_path / "nope.json"), "--rate", "100", "--csv", str(out)]) == 2


def test_a_tampered_plan_is_not_exported(plan, tmp_path, capsys):
    """A joint angle moved by 0.01 rad: verify fails it, so export refuses it (exit 2), names
    the failed check and writes no file (a controller never gets an unverified trajectory)."""
    import json

    path = plan.to_json(tmp_path / "plan.json")
    doc = json.loads(path.read_text())
    doc["segments"][0]["q"][7][2] += 0.01
    path.write_text(json.dumps(doc))
    out = tmp_path / "traj.csv"
    assert main(["export", str(path), "--rate", "250", "--csv", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "plan fails" in err and "refused" in err
    assert not out.exists()
    assert main(["export", str(path), "--rate", "250", "--csv", str(out), "--force"]) == 2
    assert not out.exists()
    with pytest.raises(FlipkitError, match="plan fails 'dynamics'|plan fails 'defects'"):
        write_csv(Plan.load(path), out, 250.0)
