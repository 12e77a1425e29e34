"""The cheap first reading of a plan file: a bounded regular file, JSON, an object with a
known ``format`` and every top-level key — before anything heavy is imported (pinocchio,
jsonschema), so a malformed file is refused at once. :meth:`Plan.load
<flipkit.planning.plans.plan_file.Plan.load>` starts here and checks the rest."""

from __future__ import annotations

from pathlib import Path

from flipkit.errors import PlanFileError
from flipkit.fileio import InputFileError, read_text
from flipkit.jsonread import DuplicateKeyError, strict_loads

FORMAT = "flipkit-plan/2"
FORMATS = ("flipkit-plan/1", FORMAT)  # readable; /1: before per-segment payloads and portable URDFs
TOP_KEYS = ("behavior", "status", "robot", "gravity", "grill_height", "spatula", "burger",
            "cone", "segments", "created_by")
MAX_PLAN_BYTES = 64 * 2**20  # bytes: a five-segment plan is about 0.2 MB


def read_plan_doc(path) -> dict:
    """The JSON object of a plan file, its ``format`` and top-level keys checked.

    Raises:
        PlanFileError: Missing, not a regular file, larger than :data:`MAX_PLAN_BYTES`, not
            UTF-8, not JSON (nested too deeply included; a key repeated in one object,
            :func:`flipkit.jsonread.strict_loads`), not an object, an unknown
            format or a missing top-level key — one line naming the file.
    """
    path = Path(path)
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
    return doc


__all__ = ["FORMAT", "FORMATS", "MAX_PLAN_BYTES", "TOP_KEYS", "read_plan_doc"]
