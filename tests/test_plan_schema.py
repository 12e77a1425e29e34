"""The documented plan format (flipkit/data/plan-format.schema.json) against real plan files."""

import copy
import json
from pathlib import Path

import jsonschema
import pytest

SCHEMA = json.loads((Path(__file__).parents[1] / "flipkit" / "data" / "plan-format.schema.json")
                    .read_text())


def test_a_solved_flip_plan_matches_the_documented_format(flip_plan_file):
    doc = json.loads(Path(flip_plan_file).read_text())
    jsonschema.validate(doc, SCHEMA)
    flip = next(s for s in doc["segments"] if s["name"] == "flip")
    assert set(flip["landing"]) == {"target", "r_land", "point", "offset", "tilt_deg",
                                    "time_of_flight", "burger_on_blade", "scenarios"}


def test_the_schema_rejects_a_flip_without_landing_and_a_scoop_with_one(flip_plan_file):
    doc = json.loads(Path(flip_plan_file).read_text())
    bad = copy.deepcopy(doc)
    flip = next(s for s in bad["segments"] if s["name"] == "flip")
    del flip["landing"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA)
    bad = copy.deepcopy(doc)
    scoop = next(s for s in bad["segments"] if s["name"] == "scoop")
    scoop["release"] = {"node": 3, "time": 0.1}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA)
