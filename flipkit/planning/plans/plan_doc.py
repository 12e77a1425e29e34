"""The cheap first reading of a plan file: a bounded regular file, JSON, an object with a
known ``format``, every top-level key and each segment's node times (at most
:data:`~flipkit.planning.plans.json_fields.MAX_NODES`, strictly increasing) — before
anything heavy is imported (pinocchio, SciPy, jsonschema), so a malformed file is refused at
once. :meth:`Plan.load
<flipkit.planning.plans.plan_file.Plan.load>` starts here and checks the rest."""

from __future__ import annotations

import os
from pathlib import Path

from flipkit.errors import ConfigError, PlanFileError
from flipkit.fileio import InputFileError, read_text
from flipkit.jsonread import DuplicateKeyError, strict_loads
from flipkit.planning.plans.json_fields import check_times

FORMAT = "flipkit-plan/2"
FORMATS = ("flipkit-plan/1", FORMAT)  # readable; /1: before per-segment payloads and portable URDFs
TOP_KEYS = ("behavior", "status", "robot", "gravity", "grill_height", "spatula", "burger",
            "cone", "segments", "created_by")
MAX_PLAN_BYTES = 64 * 2**20  # bytes: a five-segment plan is about 0.2 MB


def plan_path(path) -> Path:
    """``path`` as a :class:`~pathlib.Path`, or a one-line :class:`PlanFileError` if it is
    not a path (a ``str`` or ``os.PathLike``)."""
    if not isinstance(path, (str, os.PathLike)):
        raise PlanFileError(f"plan file: expected a path (str or os.PathLike), got "
                            f"{type(path).__name__}")
    return Path(path)


def read_plan_doc(path) -> dict:
    """The JSON object of a plan file, its ``format`` and top-level keys checked.

    Raises:
        PlanFileError: Not a path, missing, not a regular file, larger than :data:`MAX_PLAN_BYTES`, not
            UTF-8, not JSON (nested too deeply included; a key repeated in one object,
            :func:`flipkit.jsonread.strict_loads`), not an object, an unknown
            format, a missing top-level key or a segment's node times out of bounds or
            order (:func:`~flipkit.planning.plans.json_fields.check_times`) — one line
            naming the file.
    """
    path = plan_path(path)
    try:
        text = read_text(path, "plan file", MAX_PLAN_BYTES)
    except InputFileError as exc:
        reason = str(exc).split(": ", 1)[-1]
        raise PlanFileError(f"{path}: cannot read plan file ({reason})") from None
    try:
        doc = strict_loads(text)
    except DuplicateKeyError as exc:
        raise PlanFileError(f"{path}: {exc}") from None
    except RecursionError:
        raise PlanFileError(f"{path}: not a JSON file (nested too deeply to read)") from None
    except ValueError as exc:
        msg = str(exc).splitlines()[0]
        raise PlanFileError(f"{path}: not a JSON file ({msg})") from None
    if not isinstance(doc, dict):
        raise PlanFileError(f"{path}: top level: expected a JSON object, got "
                            f"{type(doc).__name__}")
    if doc.get("format") not in FORMATS:
        raise PlanFileError(f"{path}: format: expected one of {', '.join(map(repr, FORMATS))}, "
                            f"got {doc.get('format')!r}"[:300])
    missing = [k for k in TOP_KEYS if k not in doc]
    if missing:
        raise PlanFileError(f"{path}: {missing[0]}: missing key")
    segments = doc["segments"] if isinstance(doc["segments"], list) else []
    for k, seg in enumerate(segments):  # the node bound first: it bounds the rest's work
        if isinstance(seg, dict) and "t" in seg:
            try:
                check_times(f"segments[{k}].t", seg["t"])
            except ConfigError as exc:
                raise PlanFileError(f"{path}: {exc}") from None
    return doc


__all__ = ["FORMAT", "FORMATS", "MAX_PLAN_BYTES", "TOP_KEYS", "plan_path", "read_plan_doc"]
