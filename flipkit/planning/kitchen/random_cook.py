"""A cook as a camera sees it: N burgers dropped 4–5 s apart at random places on the grill
(``flipkit schedule --random N --seed S``).

The first burger drops at t = 0 and each next one U(4, 5) s after the one before. Each lies
wholly on the grill (its centre a radius inside the grill area's edges) at a uniformly random
place whose edge is at least ``gap`` (default
:data:`~flipkit.planning.kitchen.stream.CLEARANCE`, 1 mm: they may all but touch) from every
burger dropped before it: they are all on the grill at once, since a burger stays at
least 150 s and the last drops within 5 (N − 1) s. Same seed, same cook.
"""

from __future__ import annotations

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.planning.kitchen.cook import CookBurger
from flipkit.planning.kitchen.stream import CLEARANCE, PLACE_TRIES, free_place

MAX_RANDOM = 12  # burgers: more do not fit on the paper's grill, 28 × 66 cm, 10 cm apart
DROP_GAP_S = (4.0, 5.0)  # s between drops
MAX_GAP = 0.2  # m between burgers' edges: two burgers 30 cm apart span the grill's depth


def random_order(n: int, seed: int = 0, cell: CellConfig | None = None,
                 gap: float = CLEARANCE) -> list[CookBurger]:
    """The cook order (module docstring), ids ``r1`` … ``rN``, in drop order; ``gap`` (m):
    the least distance between two burgers' edges.

    Raises:
        ConfigError: ``n`` outside [1, :data:`MAX_RANDOM`], ``gap`` outside
            [CLEARANCE, :data:`MAX_GAP`], or no free place left for a burger (one line
            naming it and the seed).
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_RANDOM:
        raise ConfigError(f"--random N must be a whole number of burgers in [1, {MAX_RANDOM}], "
                          f"got {n!r}")
    if (isinstance(gap, bool) or not isinstance(gap, (int, float, np.floating))
            or not CLEARANCE <= gap <= MAX_GAP):
        raise ConfigError(f"--gap must be a distance in [{CLEARANCE}, {MAX_GAP}] m between "
                          f"burgers' edges, got {gap!r}")
    cell = cell or CellConfig()
    g, d = cell.grill, cell.burger.diameter
    r = d / 2
    area = ((g.x_range[0] + r, g.x_range[1] - r), (g.y_range[0] + r, g.y_range[1] - r))
    rng = np.random.default_rng(seed)
    t, out = 0.0, []
    for k in range(n):
        place = free_place(rng, area, [(b.x, b.y) for b in out], d, float(gap))
        if place is None:
            raise ConfigError(f"--random {n} --seed {seed} --gap {gap:g}: no free place on the "
                              f"grill for burger {k + 1} in {PLACE_TRIES} tries; drop fewer "
                              f"burgers or leave a smaller gap")
        out.append(CookBurger(f"r{k + 1}", round(t, 3), *place))
        t += float(rng.uniform(*DROP_GAP_S))
    return out


__all__ = ["DROP_GAP_S", "MAX_GAP", "MAX_RANDOM", "random_order"]
