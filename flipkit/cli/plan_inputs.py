"""The cheap checks of ``flipkit plan``'s inputs: the numbers typed on the command line and
the batch CSV, each refused in one line before the planners (pinocchio, CasADi, cvxpy,
SciPy) are imported.

The checks that need the arm's model — ``--start-q`` against the joint limits and the
singularities, a point against the cell's obstacles — run in
:mod:`flipkit.cli.commands.plan`, after it loads.
"""

from __future__ import annotations

import csv
import math

from flipkit.behaviors.targets import check_burger_height, check_heading
from flipkit.config.physics import PHYSICAL_RANGES
from flipkit.config.task import R_LAND_RANGE
from flipkit.csv_header import header_columns
from flipkit.decimal_text import decimal
from flipkit.errors import ConfigError, UnreachableError
from flipkit.fileio import InputFileError, data_lines, read_text
from flipkit.planning.planners.inputs import MAX_BATCH, check_spacing

CSV_COLUMNS = (("x", "y", "z"), ("px", "py", "pz"))  # the batch CSV's headers


def numbers(what: str, values, count: int | None = None) -> list[float]:
    """Command-line words as finite floats (exactly ``count`` of them if given).

    Raises:
        ConfigError: A word that is not a decimal number, a non-finite one, or the wrong
            count; one line naming ``what``.
    """
    values = [values] if isinstance(values, str) else list(values)
    if count is not None and len(values) != count:
        raise ConfigError(f"{what} takes {count} numbers, got {len(values)}")
    try:
        out = [decimal(v) for v in values]
    except ValueError:
        raise ConfigError(f"{what}: not a decimal number in {' '.join(values)} (digits, an "
                          "optional point and exponent; no separators)") from None
    if not all(math.isfinite(v) for v in out):
        raise ConfigError(f"{what} must be finite, got {' '.join(values)}")
    return out


def yaw(value) -> float:
    """``--yaw`` (rad) wrapped to (−π, π]: 2π plans as 0."""
    y = numbers("--yaw", value)[0]
    return math.pi - (math.pi - y) % (2 * math.pi)


def heading(value):
    """``--heading DEG`` as the scoop heading (rad), within
    :func:`~flipkit.behaviors.targets.check_heading`'s range; ``None`` (the default heading)
    without one."""
    if value is None:
        return None
    try:
        return check_heading(math.radians(numbers("--heading", value)[0]))
    except UnreachableError as exc:
        raise UnreachableError(f"--heading: {exc}") from None


def burger(values, cell) -> list[float]:
    """``--burger X Y Z`` (m), its height on the grill surface
    (:func:`~flipkit.behaviors.targets.check_burger_height`)."""
    loc = numbers("--burger", values, 3)
    check_burger_height(cell, loc[2], "--burger")
    return loc


def burger_diameter(value) -> float | None:
    """``--burger-diameter`` (m), the patty's diameter as the cell's camera sees it, within the
    range of patties the cell is studied for (``PHYSICAL_RANGES["burger.diameter"]``);
    ``None`` when not given (the cell's nominal burger)."""
    if value is None:
        return None
    d = numbers("--burger-diameter", value)[0]
    lo, hi, source = PHYSICAL_RANGES["burger.diameter"]
    if not lo <= d <= hi:
        raise ConfigError(f"--burger-diameter must be in [{lo:g}, {hi:g}] m ({source}), "
                          f"got {value}")
    return d


def r_land(value) -> float:
    """``--r-land`` (m) within R_LAND_RANGE: a smaller disc is within the landing's spread
    (its prediction and verify's recomputation agree only to R_LAND_RANGE[0])."""
    r = numbers("--r-land", value)[0]
    lo, hi = R_LAND_RANGE
    if not lo <= r <= hi:
        raise ConfigError(f"--r-land must be in [{lo:g}, {hi:g}] m, got {value}: "
                          + (f"the landing's spread (prediction against verify's check) is "
                             f"{lo:g} m, a smaller disc cannot be planned to"
                             if r < lo else "a wider disc is larger than the burger"))
    return r


def read_locations(path) -> list[tuple[float, float, float]]:
    """Burger locations (m) from a CSV with the header x,y,z or px,py,pz (in any order, no
    other column: :func:`~flipkit.csv_header.header_columns`).

    Blank lines and lines starting with ``#`` are skipped; at most :data:`MAX_BATCH` rows.

    Raises:
        ConfigError: Unreadable file, a header with an unknown, missing or repeated column,
            a non-numeric or non-finite value, no rows or more than five (one line naming
            the file and the line).
    """
    try:
        text = read_text(path, "--burgers", 2**20)
    except InputFileError as exc:
        raise ConfigError(f"--burgers {path}: cannot read burger CSV "
                          f"({str(exc).split(': ', 1)[-1]})") from None
    lines = data_lines(text)
    if not lines:
        raise ConfigError(f"{path}: no header and no burger rows")
    col = header_columns(lines[0][1], CSV_COLUMNS, f"{path}: line {lines[0][0]}")
    rows = lines[1:]
    if not 1 <= len(rows) <= MAX_BATCH:
        raise ConfigError(f"{path}: expected 1 to {MAX_BATCH} burger rows, got {len(rows)}")
    out = []
    for n, line in rows:
        cells = next(csv.reader([line]))
        if len(cells) != len(col):
            raise ConfigError(f"{path}: line {n}: expected {len(col)} values, got {len(cells)}")
        out.append(tuple(numbers(f"{path}: line {n}", [cells[i].strip() for i in col.values()])))
    return out


def batch_locations(path, cell) -> list[tuple[float, float, float]]:
    """The burgers of ``plan batch --burgers``: read (:func:`read_locations`), each on the
    grill surface and one diameter from the others."""
    locations = read_locations(path)
    for k, loc in enumerate(locations, 1):
        check_burger_height(cell, loc[2], f"{path}: burger {k}")
    check_spacing(locations, cell.burger.diameter, str(path))  # as schedule does
    return locations


__all__ = ["CSV_COLUMNS", "batch_locations", "burger", "numbers", "r_land", "read_locations",
           "yaw"]
