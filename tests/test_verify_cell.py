"""A plan file cannot tell ``verify`` which cell it runs in: it is checked in the defaults or
in the cell file the user names (``--cell``), its own record only compared with that cell;
landing targets and radii, duplicate keys and ``--tol`` cannot loosen the check."""

import json
import os
from pathlib import Path

import pytest

from flipkit.cli import main


def _edited(flip_plan_file, tmp_path, edit, name="p.json") -> Path:
    doc = json.loads(flip_plan_file.read_text())
    edit(doc)
    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return path


def _verify(capsys, argv, code, contains=()) -> str:
    """Run ``flipkit verify``; assert the exit code, one stderr line, no traceback."""
    rc = main(["verify", *map(str, argv)])
    err = capsys.readouterr().err.strip()
    assert rc == code, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for text in contains:
        assert text in err, err
    return err


def _weaken(doc):
    geo = doc["cell_geometry"]
    geo["space"]["walls"] = []
    geo["space"]["margin"] = 0.0
    geo["accel_limit"] = 1e9


def _move_burger(doc):
    doc["burger"]["location"][0] += 0.05


@pytest.mark.parametrize("edit, fields", [
    (_weaken, ["cell_geometry.space.margin", "cell_geometry.space.walls",
               "cell_geometry.accel_limit"]),
    (lambda d: d["robot"]["arm"].update(speed_margin=1.0), ["robot.arm.speed_margin"]),
    (lambda d: d["cell_geometry"]["grill"].update(x_range=[0.0, 5.0]),
     ["cell_geometry.grill.x_range"]),
    (lambda d: d.update(gravity=[0.0, 0.0, -1.0]), ["gravity"]),
])
def test_a_record_of_another_cell_fails_naming_the_fields(flip_plan_file, tmp_path, capsys,
                                                          edit, fields):
    path = _edited(flip_plan_file, tmp_path, edit)
    before = path.read_bytes()
    _verify(capsys, [path, "--json", tmp_path / "r.json"], 1,
            ["planned for another cell", *fields])
    assert sorted(os.listdir(tmp_path)) == ["p.json"] and path.read_bytes() == before
    _verify(capsys, [path], 1, ["another cell"])  # the same without --json
    rc = main(["export", str(path), "--rate", "125", "--csv", str(tmp_path / "e.csv")])
    assert rc == 2 and not (tmp_path / "e.csv").exists()
    assert "another cell" in capsys.readouterr().err


def test_a_named_cell_file_is_the_cell_checked(flip_plan_file, tmp_path, capsys):
    """The plan's own record as a cell file verifies it; a cell file with a hood over the
    grill refuses it, naming the walls, though the file says nothing of the hood."""
    doc = json.loads(flip_plan_file.read_text())
    same = tmp_path / "cell.json"
    same.write_text(json.dumps({"cell_geometry": doc["cell_geometry"], "arm": doc["robot"]["arm"]}))
    assert main(["verify", str(flip_plan_file), "--cell", str(same)]) == 0
    capsys.readouterr()
    hooded = dict(doc["cell_geometry"])
    hooded["space"] = {**hooded["space"], "walls": [*hooded["space"]["walls"], {
        "name": "hood", "lower": [0.4, -0.5, 0.5], "upper": [1.0, 0.3, 0.6]}]}
    other = tmp_path / "hood.json"
    other.write_text(json.dumps({"cell_geometry": hooded}))
    _verify(capsys, [flip_plan_file, "--cell", other], 1, ["cell_geometry.space.walls"])


@pytest.mark.parametrize("text, words", [
    ('{"cell_geometry": {}}', ["--cell", "cell_geometry"]),
    ('{"cell_geometry": 1, "cell_geometry": 2}', ["duplicate key 'cell_geometry'"]),
    ('{"walls": []}', ["--cell", "expected an object with the keys cell_geometry"]),
    ("[1]", ["--cell", "expected an object"]),
])
def test_a_malformed_cell_file_is_one_line(flip_plan_file, tmp_path, capsys, text, words):
    cell = tmp_path / "cell.json"
    cell.write_text(text)
    _verify(capsys, [flip_plan_file, "--cell", cell], 2, words)


@pytest.mark.parametrize("edit, row", [
    (lambda seg: seg["landing"].update(target=[0.2, 0.9]), "landing"),
    (lambda seg: seg["landing"].update(r_land=10.0), "landing"),
    (lambda seg: seg["landing"]["scenarios"][0].update(r_land=10.0), "landing_scenarios"),
])
def test_a_landing_off_the_grill_or_too_wide_fails(flip_plan_file, tmp_path, capsys, edit, row):
    path = _edited(flip_plan_file, tmp_path, lambda d: edit(d["segments"][3]))
    _verify(capsys, [path], 1, [f"plan fails '{row}"])
    out = tmp_path / "e.script"
    assert main(["export", str(path), "--format", "urscript", "--out", str(out)]) == 2
    assert not out.exists()
    capsys.readouterr()


def test_a_repeated_key_is_refused(flip_plan_file, tmp_path, capsys):
    """``"status": "failed", "status": "solved"`` is not read as solved by any command."""
    text = flip_plan_file.read_text().replace('"status": "solved"',
                                              '"status": "failed", "status": "solved"', 1)
    path = tmp_path / "dup.json"
    path.write_text(text)
    _verify(capsys, [path], 2, ["duplicate key 'status'"])
    out = tmp_path / "e.script"
    assert main(["export", str(path), "--format", "urscript", "--out", str(out)]) == 2
    assert not out.exists()
    assert "duplicate key" in capsys.readouterr().err


@pytest.mark.parametrize("tol", ["1", "0.001", "1e-3", "0", "nan", "1e-12"])
def test_tol_is_bounded(flip_plan_file, tmp_path, capsys, tol):
    _verify(capsys, [flip_plan_file, "--tol", tol], 2, ["--tol", "[1e-09, 0.0001]"])


def test_the_loosest_tol_fails_a_burger_moved_5_cm(flip_plan_file, tmp_path, capsys):
    path = _edited(flip_plan_file, tmp_path, _move_burger)
    _verify(capsys, [path, "--tol", "1e-4"], 1, ["plan fails 'endpoints'"])


def test_the_cli_tolerances_are_verifys():
    from flipkit.cli import verify as cli
    from flipkit.planning.plans import verify

    assert (cli.TOL, cli.TOL_RANGE) == (verify.TOL, verify.TOL_RANGE)
    assert verify.TOL_RANGE[0] <= verify.TOL <= verify.TOL_RANGE[1]


@pytest.mark.parametrize("args, words", [
    (({"not": "a plan"},), "plan: expected a Plan"),
    (("p.json",), "plan: expected a Plan"),
])
def test_the_api_refuses_a_non_plan(args, words):
    import flipkit
    from flipkit.errors import ConfigError

    with pytest.raises(ConfigError, match=words):
        flipkit.verify_plan(*args)


@pytest.mark.parametrize("kwargs, words", [
    ({"tol": 1.0}, "tol must be a number in"), ({"tol": "x"}, "tol must be a number in"),
    ({"cell": {"grill": 1}}, "cell: expected a CellConfig"),
])
def test_the_api_refuses_bad_options(flip_plan, kwargs, words):
    from flipkit.errors import ConfigError
    from flipkit.planning.plans.verify import verify_plan

    with pytest.raises(ConfigError, match=words):
        verify_plan(flip_plan, **kwargs)
