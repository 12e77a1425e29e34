"""The cook order: burgers dropped on the grill, their cook marks and the table spots.

A cook order is one row per burger — an id, the time it is dropped on the grill (s) and
its position on the grill (m); the grill height comes from the cell. Every burger cooks
:data:`FIRST_SIDE_S` on its first side, is flipped, cooks :data:`SECOND_SIDE_S` on its
second side and is served to a table spot (paper Sec. I: 90 s and 60 s).
:func:`read_cook_csv` reads and checks the ``burger,t_drop,x,y`` file of
``flipkit schedule``; :func:`check_cook` checks an order built in Python;
:func:`table_spots` spreads the serving spots over the table so that served burgers do not
overlap.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flipkit.config import CellConfig
from flipkit.csv_header import header_columns
from flipkit.decimal_text import decimal
from flipkit.errors import ConfigError
from flipkit.fileio import InputFileError, data_lines, read_text

FIRST_SIDE_S = 90.0  # s on the first side (paper Sec. I)
SECOND_SIDE_S = 60.0  # s on the second side (paper Sec. I)
CSV_HEADER = ("burger", "t_drop", "x", "y")
SPOT_GAP = 0.01  # m: clearance between served burgers and from the table's edge (ours)
MAX_T_DROP = 24 * 3600.0  # s: latest drop time accepted (a day on the order's clock)
EXAMPLE_ORDER = Path(__file__).resolve().parents[2] / "data" / "cook_five.csv"  # 5 in 20 s


class CookOrderError(ConfigError):
    """A malformed cook order (CSV or rows): one line naming the file, line and burger."""


@dataclass(frozen=True)
class CookBurger:
    """One burger of a cook order.

    Attributes:
        burger: Its id (any non-empty text, unique in the order).
        t_drop: When it is dropped on the grill (s, on the order's clock).
        x, y: Its position on the grill (m, world frame).
    """

    burger: str
    t_drop: float
    x: float
    y: float

    @property
    def flip_mark(self) -> float:
        """When its first side is done: ``t_drop`` + 90 s."""
        return self.t_drop + FIRST_SIDE_S

    @property
    def serve_mark(self) -> float:
        """When its second side is done if flipped on time: ``t_drop`` + 150 s."""
        return self.t_drop + FIRST_SIDE_S + SECOND_SIDE_S

    def location(self, cell: CellConfig) -> tuple[float, float, float]:
        """The burger location p^b (m): (x, y) on the grill surface."""
        return (self.x, self.y, cell.grill.height)


def check_cook(burgers, cell: CellConfig | None = None, where: str = "cook order"
               ) -> list[CookBurger]:
    """Check a cook order; return it sorted by drop time (ties: as given).

    Checks: at least one burger; ids non-empty and unique; drop times finite and in
    [0, :data:`MAX_T_DROP`] s; positions finite and on the grill
    (:meth:`~flipkit.config.GrillConfig.contains`); two burgers on the grill at once (nominal
    stays [t_drop, t_drop + 150 s] overlapping) at least one burger diameter apart. The
    table does not cap the order: served spots free up after a dwell
    (:mod:`flipkit.planning.kitchen.table`).

    Args:
        burgers: :class:`CookBurger` rows. cell: The cell (default
            :class:`~flipkit.config.CellConfig`). where: Prefix of error messages.

    Raises:
        CookOrderError: The first problem found, one line naming the burger.
    """
    cell = cell or CellConfig()
    rows = list(burgers)
    if not rows:
        raise CookOrderError(f"{where}: no burgers")
    seen = set()
    for b in rows:
        if not str(b.burger).strip():
            raise CookOrderError(f"{where}: a burger has an empty id")
        if b.burger in seen:
            raise CookOrderError(f"{where}: burger id {b.burger!r} appears twice")
        seen.add(b.burger)
        if not all(math.isfinite(v) for v in (b.t_drop, b.x, b.y)):
            raise CookOrderError(f"{where}: burger {b.burger!r}: t_drop, x and y must be "
                                 f"finite, got {b.t_drop}, {b.x}, {b.y}")
        if b.t_drop < 0:
            raise CookOrderError(f"{where}: burger {b.burger!r}: t_drop must be >= 0 s, "
                                 f"got {b.t_drop:g}")
        if b.t_drop > MAX_T_DROP:
            raise CookOrderError(f"{where}: burger {b.burger!r}: t_drop must be <= "
                                 f"{MAX_T_DROP:g} s (a day), got {b.t_drop:g}")
        if not cell.grill.contains((b.x, b.y)):
            g = cell.grill
            raise CookOrderError(
                f"{where}: burger {b.burger!r}: ({b.x:.3f}, {b.y:.3f}) m is off the grill "
                f"x in [{g.x_range[0]}, {g.x_range[1]}], y in [{g.y_range[0]}, "
                f"{g.y_range[1]}] m")
    d = cell.burger.diameter
    stay = FIRST_SIDE_S + SECOND_SIDE_S
    for i, a in enumerate(rows):
        for b in rows[i + 1:]:
            gap = math.hypot(a.x - b.x, a.y - b.y)
            if gap < d and abs(a.t_drop - b.t_drop) < stay:
                raise CookOrderError(
                    f"{where}: burgers {a.burger!r} and {b.burger!r} are {gap * 1e3:.0f} mm "
                    f"apart on the grill at the same time; they need one burger diameter "
                    f"({d * 1e3:.0f} mm)")
    return sorted(rows, key=lambda b: b.t_drop)


def read_cook_csv(path, cell: CellConfig | None = None) -> list[CookBurger]:
    """Read a cook order CSV (UTF-8, with or without a byte-order mark): header
    ``burger,t_drop,x,y`` (in any order; no other column,
    :func:`~flipkit.csv_header.header_columns`), one row per burger; blank lines and lines
    starting with ``#`` are skipped.

    Returns:
        The burgers sorted by drop time (:func:`check_cook`).

    Raises:
        CookOrderError: Unreadable file, a header with an unknown, missing or repeated
            column, a row with the wrong number of values, a non-numeric or non-finite
            number, and everything :func:`check_cook` refuses — one line naming the file
            (and the line).
    """
    try:
        text = read_text(path, "cook order", 2**20)
    except InputFileError as exc:
        raise CookOrderError(f"{path}: cannot read the cook order "
                             f"({str(exc).split(': ', 1)[-1]})") from None
    lines = data_lines(text)
    if not lines:
        raise CookOrderError(f"{path}: empty; expected the header {','.join(CSV_HEADER)}")
    n0, first = lines[0]
    col = header_columns(first, (CSV_HEADER,), f"{path}: line {n0}", CookOrderError)
    burgers = []
    for n, line in lines[1:]:
        cells = [c.strip() for c in next(csv.reader([line]))]
        if len(cells) != len(CSV_HEADER):
            raise CookOrderError(f"{path}: line {n}: expected {len(CSV_HEADER)} values "
                                 f"(burger,t_drop,x,y), got {len(cells)}")
        try:
            t_drop, x, y = (decimal(cells[col[c]]) for c in CSV_HEADER[1:])
        except ValueError:
            raise CookOrderError(f"{path}: line {n}: t_drop, x and y must be decimal numbers, got "
                                 f"{','.join(cells[col[c]] for c in CSV_HEADER[1:])}") from None
        burgers.append(CookBurger(cells[col["burger"]], t_drop, x, y))
    return check_cook(burgers, cell, where=str(path))


def table_spots(cell: CellConfig | None = None, gap: float = SPOT_GAP) -> list[tuple]:
    """Serving spots (x, y) (m) on the table, one burger each, spread on a square grid.

    The burgers' centres lie at least ``d/2 + gap`` inside the table's edges and
    ``d + gap`` apart (d the burger diameter); the spots nearest the grill's centre come
    first (shortest carries for the first burgers served).

    Raises:
        ConfigError: The table cannot hold a single burger.
    """
    cell = cell or CellConfig()
    t, r, pitch = cell.table, cell.burger.diameter / 2, cell.burger.diameter + gap
    axes = []
    for lo, hi in (t.x_range, t.y_range):
        lo, hi = lo + r + gap, hi - r - gap
        if hi < lo:
            raise ConfigError(f"the table ({t.x_range}, {t.y_range}) m cannot hold a burger "
                              f"of diameter {2 * r} m")
        n = int(math.floor((hi - lo) / pitch + 1e-9)) + 1
        mid = (lo + hi) / 2
        axes.append(mid + pitch * (np.arange(n) - (n - 1) / 2))
    g = cell.grill
    centre = np.array([np.mean(g.x_range), np.mean(g.y_range)])
    spots = [(float(x), float(y)) for x in axes[0] for y in axes[1]]
    return sorted(spots, key=lambda s: (round(float(np.hypot(*(np.array(s) - centre))), 9), s))


__all__ = ["CSV_HEADER", "EXAMPLE_ORDER", "FIRST_SIDE_S", "MAX_T_DROP", "SECOND_SIDE_S", "SPOT_GAP", "CookBurger",
           "CookOrderError", "check_cook", "read_cook_csv", "table_spots"]
