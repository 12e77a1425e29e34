"""A stream of drops: burgers dropped at a steady rate for some minutes, each at a random
free place on the grill (``flipkit schedule --stream RATE --minutes M``).

The drops come every ``3600 / rate`` s from t = 0 (a steady rhythm: the rate in burgers per
hour, the unit of the throughput it is compared with), ``rate × minutes / 60`` of them
(rounded down). Each lands at a uniformly random (x, y) on the grill area
(:class:`~flipkit.config.GrillConfig`, a fixed ``seed``) at least one burger diameter from
every burger still on the grill; a burger holds its disc from its drop until the latest
lift-off its windows allow (``t_drop`` + 90 s + the flip's late bound + 60 s + the serve's
late bound), so no two burgers that can share the grill overlap (positions in 0.1 mm, at
least one diameter + :data:`CLEARANCE` apart). A drop that finds no free
place in :data:`PLACE_TRIES` tries is refused: the grill is full at that rate.
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.planning.kitchen.cook import FIRST_SIDE_S, SECOND_SIDE_S, CookBurger
from flipkit.planning.kitchen.windows import Windows

PLACE_TRIES = 2000  # random places tried per drop before the grill counts as full
CLEARANCE = 1e-3  # m between two burgers' edges, on top of the diameter (and the rounding)
MAX_RATE_PER_H = 3600.0  # one drop a second
MAX_MINUTES = 24 * 60.0  # a day


class StreamError(ConfigError):
    """A stream that cannot be made: a rate or length out of range, or a full grill."""


def check_stream(rate_per_h, minutes) -> tuple[float, float]:
    """``(rate_per_h, minutes)`` as floats, rate in (0, :data:`MAX_RATE_PER_H`] per hour and
    minutes in (0, :data:`MAX_MINUTES`] (a stream drops at least one burger, at t = 0).

    Raises:
        StreamError: One line naming the bad value and the range.
    """
    vals = []
    for name, v, hi in (("--stream RATE (burgers per hour)", rate_per_h, MAX_RATE_PER_H),
                        ("--minutes", minutes, MAX_MINUTES)):
        try:
            f = float(v)
        except (TypeError, ValueError):
            f = math.nan
        if not (math.isfinite(f) and 0 < f <= hi):
            raise StreamError(f"{name} must be a number in (0, {hi:g}], got {v!r}")
        vals.append(f)
    return vals[0], vals[1]


def n_drops(rate_per_h: float, minutes: float) -> int:
    """How many burgers a stream drops: one every ``3600 / rate`` s, from 0 to before
    ``minutes`` (the first at 0)."""
    return int(math.floor(rate_per_h * minutes / 60.0 - 1e-9)) + 1 if minutes > 0 else 0


def free_place(rng, area, others, diameter: float, gap: float = CLEARANCE):
    """A uniformly random (x, y) (m, rounded to 0.1 mm) in ``area`` ((x0, x1), (y0, y1)) at
    least ``diameter`` + ``gap`` (m, default :data:`CLEARANCE`) from each of ``others``: the
    first of :data:`PLACE_TRIES` draws of ``rng`` that is, or ``None``."""
    (x0, x1), (y0, y1) = area
    xy = rng.uniform((x0, y0), (x1, y1), size=(PLACE_TRIES, 2))
    if len(others):
        gaps = np.linalg.norm(xy[:, None, :] - np.asarray(others, float)[None], axis=2)
        free = gaps.min(axis=1) >= diameter + gap
    else:
        free = np.ones(len(xy), bool)
    if not free.any():
        return None
    return tuple(round(float(v), 4) for v in xy[np.argmax(free)])


def stream_order(rate_per_h: float, minutes: float, seed: int = 0,
                 cell: CellConfig | None = None, windows: Windows = Windows()
                 ) -> list[CookBurger]:
    """The burgers of a stream (module docstring), ids ``s0001``, ``s0002``…, in drop order.

    Args:
        rate_per_h: Drops per hour. minutes: The stream's length (min).
        seed: Seed of the positions (numpy's default generator).
        cell: The cell (default :class:`~flipkit.config.CellConfig`).
        windows: The event windows (their late bounds set how long a burger holds its disc).

    Raises:
        StreamError: Bad rate or length, or no free place for a drop.
    """
    rate_per_h, minutes = check_stream(rate_per_h, minutes)
    cell = cell or CellConfig()
    g, d = cell.grill, cell.burger.diameter
    hold = FIRST_SIDE_S + windows.flip[1] + SECOND_SIDE_S + windows.serve[1]
    gap = 3600.0 / rate_per_h
    rng = np.random.default_rng(seed)
    on_grill: list[tuple[float, float, float]] = []  # (x, y, leaves at)
    out = []
    for k in range(n_drops(rate_per_h, minutes)):
        t = round(k * gap, 6)
        on_grill = [b for b in on_grill if b[2] > t]
        place = free_place(rng, (g.x_range, g.y_range), [b[:2] for b in on_grill], d)
        if place is None:
            raise StreamError(f"the grill is full at t = {t:g} s: {len(on_grill)} burgers "
                              f"on it and no free place for another in {PLACE_TRIES} tries; "
                              f"lower the rate ({rate_per_h:g} per hour)")
        x, y = place
        on_grill.append((x, y, t + hold))
        out.append(CookBurger(f"s{k + 1:04d}", t, x, y))
    return out


__all__ = ["MAX_MINUTES", "MAX_RATE_PER_H", "PLACE_TRIES", "StreamError", "check_stream",
           "free_place", "n_drops", "stream_order"]
