"""CITATION.cff is valid Citation File Format 1.2.0 and cites this version of the package.

The schema is ``tests/data/citation-file-format-1.2.0.schema.json``, unmodified, from
https://github.com/citation-file-format/citation-file-format/blob/1.2.0/schema.json (tag
1.2.0; source, commit and SHA-256 in the ``.source`` file beside it). It is JSON Schema
draft-07, where ``format`` is only an annotation unless the validator is given a format
checker: the ``date`` and ``uri`` formats are checked here with
``Draft7Validator.FORMAT_CHECKER`` (``uri`` through rfc3987-syntax / rfc3986-validator).
YAML reads ``2026-11-25`` as a date; the schema's own note asks tools to validate it as a
string, so dates are turned back into ISO strings first.
"""

import datetime
import hashlib
import json
import tomllib
from pathlib import Path

import pytest
import yaml
from jsonschema import Draft7Validator

import flipkit

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = Path(__file__).parent / "data" / "citation-file-format-1.2.0.schema.json"


def as_json(value):
    """YAML's dates as ISO strings, recursively (the schema's note to tool implementers)."""
    if isinstance(value, dict):
        return {k: as_json(v) for k, v in value.items()}
    if isinstance(value, list):
        return [as_json(v) for v in value]
    return value.isoformat() if isinstance(value, datetime.date) else value


def errors(document) -> list[str]:
    schema = json.loads(SCHEMA.read_text())
    validator = Draft7Validator(schema, format_checker=Draft7Validator.FORMAT_CHECKER)
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
            for e in validator.iter_errors(document)]


@pytest.fixture(scope="module")
def citation():
    return as_json(yaml.safe_load((ROOT / "CITATION.cff").read_text()))


def test_the_schema_is_the_stored_cff_1_2_0_draft_07_schema():
    source = SCHEMA.with_name(SCHEMA.name + ".source").read_text()
    assert hashlib.sha256(SCHEMA.read_bytes()).hexdigest() in source
    schema = json.loads(SCHEMA.read_text())
    assert schema["$id"] == "https://citation-file-format.github.io/1.2.0/schema.json"
    assert schema["$schema"] == "http://json-schema.org/draft-07/schema"
    Draft7Validator.check_schema(schema)


def test_citation_cff_is_valid(citation):
    assert errors(citation) == []


def test_citation_cff_cites_this_package_and_the_paper(citation):
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert citation["cff-version"] == "1.2.0" and citation["type"] == "software"
    assert citation["version"] == flipkit.__version__
    assert citation["license"] == project["license"]["text"]
    assert citation["date-released"] == "2026-11-25"
    assert citation["authors"] == [{"name": "flipkit developers"}]
    paper = citation["references"][0]
    assert paper["title"].startswith("Direct Collocation for Dynamic Behaviors")
    assert [a["family-names"] for a in paper["authors"]] == [
        "Kolathaya", "Guffey", "Sinnet", "Ames"]


@pytest.mark.parametrize("key, value, where", [
    ("date-released", "2026-13-01", "date-released"),  # the schema's pattern
    ("date-released", "2026-02-30", "date-released"),  # the date format only
    ("repository-code", "https://exa mple.org/x", "repository-code"),  # the uri format only
    ("authors", [], "authors"),
    ("colour", "blue", ""),  # no additional properties
])
def test_the_validator_rejects_a_broken_citation(citation, key, value, where):
    found = errors({**citation, key: value})
    assert found and all(e.startswith(f"{where}:") for e in found), found


def test_without_a_format_checker_draft_07_formats_pass():
    """Why the format checker is passed: a plain draft-07 validator accepts 30 February."""
    schema = json.loads(SCHEMA.read_text())
    assert Draft7Validator(schema["definitions"]["date"]).is_valid("2026-02-30")
