"""The plan file stands alone (flipkit-plan/2): a portable URDF name with its sha256, the
payload bodies of every segment, the JSON Schema checked on load, and flipkit-plan/1 files
still read."""

import json
import sys

import jsonschema
import numpy as np
import pytest
from test_plan import models  # noqa: F401  (fixture)
from test_plan import chain_plan, translate_plan
from test_plan_schema import SCHEMA

from flipkit.cli import main
from flipkit.config import default_urdf, urdf_sha256
from flipkit.errors import PlanFileError
from flipkit.planning.plans.plan_file import FORMAT, Plan
from flipkit.planning.plans.verify import verify_plan

PORTABLE_UR10 = "example-robot-data:ur_description/urdf/ur10_joint_limited_robot.urdf"


@pytest.fixture
def doc(models, tmp_path):
    return json.loads(translate_plan(models).to_json(tmp_path / "plan.json").read_text())


def _write(tmp_path, doc, name="edited.json"):
    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return path


def test_the_urdf_is_named_portably_with_its_sha256(doc, models, tmp_path):
    assert doc["format"] == FORMAT == "flipkit-plan/2"
    assert doc["robot"]["urdf"] == PORTABLE_UR10
    assert doc["robot"]["urdf_sha256"] == urdf_sha256(default_urdf())
    text = (tmp_path / "plan.json").read_text()
    assert sys.prefix not in text  # no path of this machine's virtual environment
    assert Plan.load(tmp_path / "plan.json").cell().robot.urdf_path == default_urdf()


def test_every_segment_lists_the_bodies_it_carries(models, doc):
    assert [s["payload"] for s in doc["segments"]] == [["spatula", "burger"]] * 2
    assert [b["name"] for b in doc["robot"]["payload"]] == ["spatula", "burger"]
    plan = chain_plan(models)
    assert {s.name: s.payload for s in plan.segments} == {
        "scoop": ["spatula"], "pickup": ["spatula", "burger"], "turn_back": ["spatula"]}
    robots = [plan.robot_for(s) for s in plan.segments]
    assert [len(r.payload) for r in robots] == [1, 2, 1]


def test_the_payload_list_decides_the_dynamics(doc, tmp_path):
    """Carrying no burger on a segment planned with one: verify sees the torque difference."""
    doc["segments"][0]["payload"] = ["spatula"]
    report = verify_plan(Plan.load(_write(tmp_path, doc)))
    assert not report.ok and report.worst()[0] == "dynamics" and report.worst()[1] == 0


def test_an_absolute_urdf_path_is_still_accepted(doc, tmp_path):
    doc["robot"]["urdf"] = default_urdf()
    assert verify_plan(Plan.load(_write(tmp_path, doc))).ok


def test_a_different_urdf_under_the_same_name_is_rejected(doc, tmp_path, capsys):
    doc["robot"]["urdf_sha256"] = "0" * 64
    path = _write(tmp_path, doc)
    with pytest.raises(PlanFileError, match="not the URDF the plan was made with"):
        Plan.load(path).cell()
    assert main(["verify", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "sha256" in err


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["segments"][1].update(payload=["spatula", "sauce"]),
     r"segments\[1\].payload: \['sauce'\] not in robot.payload"),
    (lambda d: d["segments"][0].pop("payload"), r"segments\[0\].payload: missing key"),
    (lambda d: d["robot"].pop("urdf_sha256"), "robot.urdf_sha256: missing key"),
    (lambda d: d["robot"].update(urdf="example-robot-data:../../etc/passwd"),
     "robot.urdf: URDF name"),
    (lambda d: d["robot"].update(urdf="example-robot-data:ur_description/urdf/none.urdf"),
     "no such file in example-robot-data"),
])
def test_bad_payload_and_urdf_entries_are_one_line_errors(doc, tmp_path, edit, message):
    edit(doc)
    path = _write(tmp_path, doc)
    with pytest.raises(PlanFileError, match=message) as err:
        Plan.load(path).cell()
    assert "\n" not in str(err.value)


def test_flipkit_plan_1_files_are_read_verified_and_upgraded(models, tmp_path):
    """A file written before the change: absolute URDF path, no sha256, no body names, no
    per-segment payload. Each segment then carries what its behaviour carries."""
    plan = chain_plan(models)
    doc = json.loads(plan.to_json(tmp_path / "new.json").read_text())
    doc["format"] = "flipkit-plan/1"
    doc["robot"]["urdf"] = default_urdf()
    del doc["robot"]["urdf_sha256"]
    for body in doc["robot"]["payload"]:
        del body["name"]
    for seg in doc["segments"]:
        del seg["payload"]
    old = Plan.load(_write(tmp_path, doc, "old.json"))
    assert [s.payload for s in old.segments] == [["spatula"], ["spatula", "burger"], ["spatula"]]
    # the same check, group by group, as the file it was made from (a partial chain: the
    # completeness group fails in both)
    assert {g: r.violation for g, r in verify_plan(old).groups.items()} == {
        g: r.violation for g, r in verify_plan(plan).groups.items()}
    again = json.loads(old.to_json(tmp_path / "upgraded.json").read_text())
    assert again["format"] == FORMAT and again["robot"]["urdf_sha256"] == urdf_sha256(
        default_urdf())
    jsonschema.validate(again, SCHEMA)
    for a, b in zip(old.segments, Plan.load(tmp_path / "upgraded.json").segments):
        np.testing.assert_array_equal(a.q, b.q)
        assert a.payload == b.payload


def test_the_schema_requires_the_new_keys_in_format_2_only(doc):
    jsonschema.validate(doc, SCHEMA)
    bad = json.loads(json.dumps(doc))
    del bad["segments"][0]["payload"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA)
    bad["format"] = "flipkit-plan/1"
    del bad["robot"]["urdf_sha256"]
    jsonschema.validate(bad, SCHEMA)


def test_load_checks_the_json_schema(flip_plan_file, tmp_path, capsys):
    """A landing tilt of 200° passes the key-by-key reader (a finite number) but not the
    schema (0–180°): the file is rejected on load, and by flipkit verify, in one line."""
    doc = json.loads(flip_plan_file.read_text())
    next(s for s in doc["segments"] if s["name"] == "flip")["landing"]["tilt_deg"] = 200.0
    path = _write(tmp_path, doc)
    with pytest.raises(PlanFileError, match=r"segments\[3\].landing.tilt_deg: 200.0 is greater "
                                            r"than the maximum of 180 \(JSON Schema\)"):
        Plan.load(path)
    assert main(["verify", str(path)]) == 2
    assert "(JSON Schema)" in capsys.readouterr().err
