"""The side table over time: which spot each served burger gets, and when a spot is free.

The table holds :func:`~flipkit.planning.kitchen.cook.table_spots` spots (nine on the
default cell). A served burger's plate is taken away :data:`DWELL_S` after its serve ends,
and the spot is then free for another burger; so a cook or a stream of any length fits the
table, as long as the spots free up as fast as the arm serves.

A spot is held from the lift-off of the serve that carries a burger to it (the arm is
committed to that spot from then on) until ``dwell_s`` after that serve ends. A burger
served to a spot that was used before may therefore lift off only ``dwell_s`` after the
previous burger's serve on that spot ended; both schedulers keep this
(:mod:`~flipkit.planning.kitchen.schedule`, :mod:`~flipkit.planning.kitchen.cpsat`).

Spots are assigned before any motion is planned, because a serve's plan needs its spot:
:func:`assign_spots` gives the burgers, in drop order, the spot nearest the grill that is
free by their nominal serve marks (``t_drop`` + 150 s) with :data:`REUSE_MARGIN_S` to
spare.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flipkit.errors import ConfigError

# Dwell (s): how long a served plate stays on the table before it is taken away. Our choice:
# 30 s, a hand at the pass clearing a plate within half a minute, and short enough that the
# table never fills: the arm places at most one plate per serve, a serve takes at least 4.0 s
# (the throughput target), so at most ceil(30 / 4.0) = 8 plates arrive
# within any 30 s, fewer than the nine spots. A longer dwell caps the stream: nine spots at
# dwell D take at most 9 x 3600 / D burgers per hour (D = 120 s: 270 per hour);
# `flipkit schedule --dwell` sets it.
DWELL_S = 30.0
MAX_DWELL_S = 3600.0  # s: an hour; beyond it the table is a store, not a pass (ours)
# Margin (s) between the nominal serve marks of two burgers sharing a spot, on top of the
# dwell: a serve (5.9 s) plus both events' default late windows (2 s each), rounded up.
REUSE_MARGIN_S = 10.0


@dataclass(frozen=True)
class SpotAssignment:
    """A served burger's spot.

    Attributes:
        burger: The burger's id.
        spot: Its table spot (x, y) (m).
        previous: The burger served to the same spot before it (``None``: the first).
    """

    burger: str
    spot: tuple
    previous: str | None = None


def check_dwell(dwell_s, name: str = "dwell") -> float:
    """``dwell_s`` as a float in [0, :data:`MAX_DWELL_S`] s (``name``: in the message).

    Raises:
        ConfigError: Not a finite number in that range.
    """
    try:
        value = float(dwell_s)
    except (TypeError, ValueError):
        value = math.nan
    if not (math.isfinite(value) and 0 <= value <= MAX_DWELL_S):
        raise ConfigError(f"{name} must be a number of seconds in [0, {MAX_DWELL_S:g}], "
                          f"got {dwell_s!r}")
    return value


def assign_spots(order, spots, dwell_s: float = DWELL_S,
                 margin_s: float = REUSE_MARGIN_S) -> list[SpotAssignment]:
    """Give every burger of ``order`` a table spot.

    In drop order, each burger takes the first spot of ``spots`` (nearest the grill first)
    whose last burger's nominal serve mark lies ``dwell_s + margin_s`` or more before its
    own; when none does, the spot whose last burger's mark is earliest (the schedulers then
    wait for it to free up).

    Args:
        order: :class:`~flipkit.planning.kitchen.cook.CookBurger` rows, in drop order.
        spots: Table spots (x, y) (m), at least one.
        dwell_s, margin_s: As the module (s).

    Returns:
        One :class:`SpotAssignment` per burger, in ``order``'s order.

    Raises:
        ConfigError: No spots, or a dwell out of range.
    """
    spots = [tuple(s) for s in spots]
    if not spots:
        raise ConfigError("the table has no spots")
    gap = check_dwell(dwell_s) + float(margin_s)
    last: list[tuple[float, str] | None] = [None] * len(spots)  # (mark, burger) per spot
    out = []
    for b in order:
        free = [k for k, held in enumerate(last) if held is None or held[0] + gap <= b.serve_mark]
        k = free[0] if free else min(range(len(spots)), key=lambda j: (last[j][0], j))
        out.append(SpotAssignment(b.burger, spots[k], None if last[k] is None else last[k][1]))
        last[k] = (b.serve_mark, b.burger)
    return out


def table_rate_cap(n_spots: int, dwell_s: float = DWELL_S) -> float:
    """The most burgers per hour a table of ``n_spots`` can take at ``dwell_s`` (inf at 0)."""
    return math.inf if dwell_s <= 0 else n_spots * 3600.0 / dwell_s


__all__ = ["DWELL_S", "MAX_DWELL_S", "REUSE_MARGIN_S", "SpotAssignment", "assign_spots",
           "check_dwell", "table_rate_cap"]
