"""The cell a plan is verified against: the cell it will run in, never the plan's own record.

That cell is :class:`~flipkit.config.CellConfig`'s defaults, or one the user names with a
cell file (``flipkit verify --cell FILE``, :func:`read_cell_file`). A plan file records the
cell it was planned in: ``cell_geometry`` (grill and table areas, task-space limits, the
arm's clearance margin and the walls, acceleration bounds), ``grill_height``, ``gravity``
and, under ``robot``, ``arm`` (profile, speed margin, safety preset), ``base_in_world`` and
``q_home``. :func:`record_differences` compares that record with the cell in use field by
field; a plan whose record differs was planned for another cell and is refused
(:class:`CellMismatchError`, naming the fields). :func:`checked_cell` is the cell the checks
then run in: the cell in use, with the plan's own arm model (its URDF, checked by sha256),
spatula and burger.

A cell file is a JSON object ``{"cell_geometry": {...}, "arm": {...}}`` in the plan file's
layouts of the same keys (``docs/plan-format.md``); ``arm`` is optional (default the
defaults'). Copying a trusted plan's ``cell_geometry`` and ``robot.arm`` makes one.
"""

from __future__ import annotations

import math
from dataclasses import fields, replace

import numpy as np

from flipkit.config import CellConfig, RobotConfig
from flipkit.errors import ConfigError, VerificationError
from flipkit.fileio import InputFileError, read_text
from flipkit.jsonread import strict_loads
from flipkit.planning.plans.cell_record import geometry_configs

ARM_KEYS = ("profile", "speed_margin", "safety_preset")
CELL_FILE_KEYS = ("cell_geometry", "arm")
MAX_CELL_BYTES = 2**20  # bytes: a cell file is about 1 kB


class CellMismatchError(VerificationError):
    """A plan whose record of its cell differs from the cell it is verified against."""


def _same(a, b) -> bool:
    """Equal values: numbers to 1e-12 (relative), arrays and tuples elementwise."""
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    try:
        x, y = np.asarray(a, float), np.asarray(b, float)
    except (TypeError, ValueError):
        return a == b
    if x.shape != y.shape:
        return False
    return bool(np.all((x == y) | np.isclose(x, y, rtol=1e-12, atol=1e-12)))


def _geometry_differences(record: dict, cell: CellConfig, compare_space: bool) -> list[str]:
    """Paths ``cell_geometry.<key>.<field>`` whose recorded value differs from ``cell``'s
    (the ``space`` fields only if ``compare_space``)."""
    geo, out = geometry_configs(record), []
    for key in ("grill", "table", "limits"):
        for f in fields(geo[key]):
            if not _same(getattr(geo[key], f.name), getattr(getattr(cell, key), f.name)):
                out.append(f"cell_geometry.{key}.{f.name}")
    space = geo["space"]
    for name in ("margin", "handle_radius") if compare_space else ():
        if not _same(getattr(space, name), getattr(cell.space, name)):
            out.append(f"cell_geometry.space.{name}")
    if compare_space and space.walls != cell.space.walls:
        out.append("cell_geometry.space.walls")
    for name in ("accel_limit", "free_accel_limit"):
        mine, theirs = geo[name], getattr(cell.robot, name)
        if not (mine == theirs or (math.isfinite(mine) and _same(mine, theirs))):
            out.append(f"cell_geometry.{name}")
    return out


def record_differences(plan, cell: CellConfig, compare_space: bool = True) -> list[str]:
    """The plan's recorded fields (key paths) whose values differ from the cell ``cell``.

    A file written without ``cell_geometry`` has only the other fields compared;
    ``compare_space=False`` leaves out the walls and margins (a what-if check in another
    space, :func:`~flipkit.planning.plans.verify.verify_plan`'s ``space``).
    """
    out = ([] if plan.cell_geometry is None
           else _geometry_differences(plan.cell_geometry, cell, compare_space))
    if not _same(plan.grill_height, cell.grill.height):
        out.append("grill_height")
    if not _same(plan.gravity, cell.gravity):
        out.append("gravity")
    robot = plan.robot
    out += [f"robot.arm.{k}" for k in ARM_KEYS if not _same(robot["arm"][k],
                                                             getattr(cell.robot, k))]
    for key in ("base_in_world", "q_home"):
        if not _same(robot[key], getattr(cell.robot, key)):
            out.append(f"robot.{key}")
    return out


def check_record(plan, cell: CellConfig, where: str = "plan", compare_space: bool = True) -> None:
    """Refuse a plan whose record of its cell differs from ``cell``
    (:func:`record_differences`).

    Raises:
        CellMismatchError: One line naming ``where`` and the differing fields.
    """
    diff = record_differences(plan, cell, compare_space)
    if diff:
        more = f" and {len(diff) - 6} more" if len(diff) > 6 else ""
        raise CellMismatchError(f"{where}: planned for another cell: {', '.join(diff[:6])}"
                                f"{more} differ from the cell it is checked in (the defaults, "
                                "or --cell FILE); plan it in this cell or name its cell")


def checked_cell(plan, cell: CellConfig) -> CellConfig:
    """The cell the checks run in: ``cell`` (grill, table, limits, space, gravity, arm
    profile and bounds), with the plan's own arm model, spatula and burger
    (:meth:`~flipkit.planning.plans.plan_file.Plan.cell`)."""
    own = plan.cell()
    robot = replace(own.robot, accel_limit=cell.robot.accel_limit,
                    free_accel_limit=cell.robot.free_accel_limit,
                    **{k: getattr(cell.robot, k) for k in ARM_KEYS})
    return replace(own, robot=robot, grill=cell.grill, table=cell.table, limits=cell.limits,
                   space=cell.space, gravity=cell.gravity)


def read_cell_file(path) -> CellConfig:
    """The cell of a cell file (module docstring): the defaults with its geometry and arm.

    Raises:
        ConfigError: Unreadable, not JSON, a repeated key, unknown or missing keys, or a
            malformed value (one line naming the file and the key).
    """
    try:
        doc = strict_loads(read_text(path, "--cell", MAX_CELL_BYTES))
    except InputFileError:
        raise
    except (ValueError, RecursionError) as exc:
        raise ConfigError(f"--cell {path}: not a cell file ({str(exc).splitlines()[0]})") \
            from None
    if not isinstance(doc, dict) or "cell_geometry" not in doc or set(doc) - set(CELL_FILE_KEYS):
        got = sorted(doc) if isinstance(doc, dict) else type(doc).__name__
        raise ConfigError(f"--cell {path}: expected an object with the keys cell_geometry "
                          f"(and optionally arm), got {got}")
    try:
        geo = geometry_configs(doc["cell_geometry"])
        arm = doc.get("arm", {})
        if not isinstance(arm, dict) or set(arm) - set(ARM_KEYS):
            raise ConfigError(f"arm: expected an object with keys among {', '.join(ARM_KEYS)}")
        robot = RobotConfig(accel_limit=geo.pop("accel_limit"),
                            free_accel_limit=geo.pop("free_accel_limit"), **arm)
        return CellConfig(robot=robot, **geo)
    except (ConfigError, TypeError) as exc:
        raise ConfigError(f"--cell {path}: {' '.join(str(exc).split())}") from None


__all__ = ["CellMismatchError", "check_record", "checked_cell", "read_cell_file",
           "record_differences"]
