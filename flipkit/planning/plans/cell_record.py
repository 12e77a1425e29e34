"""The cell's geometry as a plan file records it (``cell_geometry``), and back.

A plan is checked against the cell it was made in: its grill and table areas, the task-space
limits of Constraint 1, the whole arm's clearance margin and the walls, and the joint
acceleration bounds. The file records them so that ``flipkit verify`` and
:meth:`~flipkit.planning.plans.plan_file.Plan.cell` rebuild that cell, not today's defaults. Files
written before this record (``cell_geometry`` absent) are read with the defaults.

Layout (lengths m, angles rad, velocities m/s, accelerations m/s² or rad/s²)::

    "cell_geometry": {
      "grill":  {"height", "x_range": [2], "y_range": [2]},
      "table":  {"height", "x_range": [2], "y_range": [2]},
      "limits": {"p_min": [3], "p_max": [3], "v_max", "a_max", "pitch_range": [2]},
      "space":  {"margin", "handle_radius", "walls": [{"name", "lower": [3], "upper": [3]}]},
      "accel_limit": joint acceleration bound,
      "free_accel_limit": the free motions' bound, null for none (optional: a plan written
                          without it was planned with ``accel_limit`` for every segment)
    }
"""

from __future__ import annotations

from dataclasses import asdict

from flipkit.config.cell import CellConfig, GrillConfig, TableConfig, TaskLimits
from flipkit.config.space import CellBox, SpaceConfig
from flipkit.errors import ConfigError

import math

KEYS = ("grill", "table", "limits", "space", "accel_limit")
OPTIONAL = ("free_accel_limit",)


def _plain(value):
    """Tuples (and nested tuples) as lists, for JSON."""
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def cell_geometry(cell: CellConfig) -> dict:
    """The ``cell_geometry`` record of ``cell`` (JSON-ready)."""
    sp = cell.space
    return {"grill": _plain(asdict(cell.grill)), "table": _plain(asdict(cell.table)),
            "limits": _plain(asdict(cell.limits)),
            "space": {"margin": sp.margin, "handle_radius": sp.handle_radius,
                      "walls": [_plain(asdict(w)) for w in sp.walls]},
            "accel_limit": cell.robot.accel_limit,
            "free_accel_limit": (None if math.isinf(cell.robot.free_accel_limit)
                                 else cell.robot.free_accel_limit)}


def geometry_configs(record: dict) -> dict:
    """The configs a ``cell_geometry`` record describes: ``{"grill": GrillConfig, "table":
    TableConfig, "limits": TaskLimits, "space": SpaceConfig, "accel_limit": float,
    "free_accel_limit": float}`` (``inf`` for null; ``accel_limit`` when the record has none).

    Raises:
        ConfigError: A key is missing or unknown, or a value is malformed (the message names
            ``cell_geometry.<key>``).
    """
    if not isinstance(record, dict) or not set(KEYS) <= set(record) <= set(KEYS + OPTIONAL):
        got = sorted(record) if isinstance(record, dict) else type(record).__name__
        raise ConfigError(f"cell_geometry: expected the keys {', '.join(KEYS)} (and optionally "
                          f"{', '.join(OPTIONAL)}), got {got}")
    out = {}
    for key, kind in (("grill", GrillConfig), ("table", TableConfig), ("limits", TaskLimits)):
        out[key] = _build(key, kind, record[key], lambda d: {k: _tuple(v) for k, v in d.items()})
    out["space"] = _build("space", SpaceConfig, record["space"], _space_fields)
    accel = record["accel_limit"]
    if not isinstance(accel, (int, float)) or isinstance(accel, bool) or not accel > 0:
        raise ConfigError(f"cell_geometry.accel_limit: expected a positive number, got {accel!r}")
    out["accel_limit"] = float(accel)
    free = record.get("free_accel_limit", accel)
    if free is not None and (not isinstance(free, (int, float)) or isinstance(free, bool)
                             or not (math.isfinite(free) and free > 0)):
        raise ConfigError(f"cell_geometry.free_accel_limit: expected a positive number or "
                          f"null, got {free!r}")
    out["free_accel_limit"] = math.inf if free is None else float(free)
    return out


def _tuple(value):
    return tuple(_tuple(v) for v in value) if isinstance(value, list) else value


def _space_fields(d: dict) -> dict:
    walls = d.get("walls")
    if not isinstance(walls, list):
        raise ConfigError("walls: expected a list of boxes")
    return {**d, "walls": tuple(CellBox(**{k: _tuple(v) for k, v in w.items()}) for w in walls)}


def _build(key: str, kind, value, fields):
    """``kind(**fields(value))``, its errors named ``cell_geometry.<key>``."""
    if not isinstance(value, dict):
        raise ConfigError(f"cell_geometry.{key}: expected an object, got {type(value).__name__}")
    try:
        return kind(**fields(value))
    except (TypeError, ValueError, ConfigError) as exc:
        raise ConfigError(f"cell_geometry.{key}: {' '.join(str(exc).split())}") from None


__all__ = ["KEYS", "cell_geometry", "geometry_configs"]
