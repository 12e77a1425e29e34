"""Strict reading of JSON inputs (plan files, cell files, an atlas's header).

Python's :func:`json.loads` keeps the last of two equal keys in an object, so a file holding
``"status": "failed", "status": "solved"`` would read as solved. A repeated key is refused
here, naming it, so that what a file says is what every reader of it sees. (``NaN`` and
``Infinity``, which are not JSON either, are read as numbers and refused by the field checks,
which name the key path: :mod:`flipkit.planning.plans.json_fields`.)
"""

from __future__ import annotations

import json

from flipkit.errors import ConfigError


class DuplicateKeyError(ConfigError):
    """JSON text with a key repeated in one object."""


def _unique_keys(pairs: list) -> dict:
    """An object's (key, value) pairs as a dict, refused if a key repeats."""
    seen = {}
    for key, value in pairs:
        if key in seen:
            raise DuplicateKeyError(f"duplicate key {key!r} in one object (a reader would "
                                    "see only one of its values)")
        seen[key] = value
    return seen


def strict_loads(text: str):
    """The JSON value of ``text``, every object's keys distinct.

    Raises:
        DuplicateKeyError: A key repeated in one object (one line naming it).
        ValueError: Not JSON (:class:`json.JSONDecodeError`). RecursionError: Nested too
            deeply for the parser.
    """
    return json.loads(text, object_pairs_hook=_unique_keys)


__all__ = ["DuplicateKeyError", "strict_loads"]
