"""A cook order planned as ``flipkit schedule`` plans it, and the first random cook that plans.

:func:`plan_cook` plans every motion of a cook from rest at home (in an executor's workers),
orders and times them with CP-SAT and keeps them clear of the burgers lying on the grill
(:func:`~flipkit.planning.kitchen.clearance.clear_cook`: landings moved, scoop headings
turned). :func:`first_random_cook` draws random cooks
(:func:`~flipkit.planning.kitchen.random_cook.random_order`) seed after seed and keeps the
first one planned with every event in its window, with the one-line reason of every seed
refused before it: a film or a report that shows a random cook says which seeds it skipped.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.planning.kitchen.clearance import clear_cook
from flipkit.planning.kitchen.cook import check_cook, table_spots
from flipkit.planning.kitchen.motions import KINDS
from flipkit.planning.kitchen.optimal import schedule_cook_cpsat
from flipkit.planning.kitchen.prefetch import PrefetchPlanners
from flipkit.planning.kitchen.random_cook import random_order
from flipkit.planning.kitchen.stream import CLEARANCE
from flipkit.planning.kitchen.table import DWELL_S, assign_spots
from flipkit.planning.kitchen.turns import CookConflictError
from flipkit.planning.kitchen.windows import worst_break


@dataclass
class PlannedCook:
    """A cook order and its schedule.

    Attributes:
        burgers: The cook order (:class:`~flipkit.planning.kitchen.cook.CookBurger`).
        timeline: The CP-SAT schedule. lands: ``{burger: (x, y)}`` landings moved (m).
        headings: ``{burger: ψ}`` scoop headings turned from radial (rad).
        breach: The worst window broken, ``None`` when every event keeps its window.
        wall_s: Planning wall time (s).
    """

    burgers: list
    timeline: object
    lands: dict
    headings: dict
    breach: object
    wall_s: float

    @property
    def ok(self) -> bool:
        """Every motion planned and every event within its window."""
        return bool(self.timeline.ok) and self.breach is None


def plan_cook(burgers, executor, cell: CellConfig | None = None, solver: str = "auto",
              atlas=None) -> PlannedCook:
    """Plan, order and clear a cook (module docstring).

    Args:
        burgers: The cook order. executor: Where the motions are planned ahead
            (:func:`~flipkit.experiments.sweep.make_executor`). cell: The cell (default
            :class:`CellConfig`). solver: The collocation solver (``auto``, ``sqp``,
            ``ipopt``). atlas: The flips' warm starts, or ``None``.

    Raises:
        CookConflictError: A burger that no heading or landing keeps clear (one line).
    """
    cell = cell or CellConfig()
    order = check_cook(burgers, cell)
    spots = [a.spot for a in assign_spots(order, table_spots(cell), DWELL_S)]
    t0 = time.perf_counter()
    planners = PrefetchPlanners(order, KINDS, cell.robot.q_home, spots, executor, cell, solver,
                                atlas)
    timeline, lands, headings = clear_cook(lambda lands, headings: schedule_cook_cpsat(
        order, planners, cell.robot.q_home, kinds=KINDS, cell=cell, lands=lands,
        headings=headings), cell, atlas=atlas)
    return PlannedCook(order, timeline, lands, headings,
                       worst_break(timeline.burgers, timeline.windows),
                       time.perf_counter() - t0)


REFUSALS = ("landing", "heading", "windows", "other")
"""Why a random cook is refused: no landing spot keeps a flipped burger clear
(``landing``), a scoop meets a burger at every heading tried (``heading``), an event
outside its window (``windows``), anything else (``other``: a plan failed, no free place)."""


@dataclass
class RandomCook:
    """The first random cook planned (:func:`first_random_cook`).

    Attributes:
        seed: Its seed. cook: It, planned. refused: ``(seed, kind, reason)`` of each seed
            tried before it, in order (``kind`` one of :data:`REFUSALS`, ``reason`` one line).
    """

    seed: int
    cook: PlannedCook
    refused: list = field(default_factory=list)

    def refusal_counts(self) -> dict:
        """How many seeds were refused for each :data:`REFUSALS` kind."""
        kinds = [kind for _, kind, _ in self.refused]
        return {kind: kinds.count(kind) for kind in REFUSALS}


def _refusal(cook: PlannedCook) -> tuple[str, str]:
    """The :data:`REFUSALS` kind and one line of a cook planned but not kept."""
    if not cook.timeline.ok:
        failed = [m.key for m in cook.timeline.motions if not m.ok]
        return "other", f"motions not planned: {', '.join(failed)}"
    return "windows", f"windows broken: {cook.breach.message()}"


def first_random_cook(n: int, seeds, plan: Callable[[list], PlannedCook],
                      cell: CellConfig | None = None, gap: float = CLEARANCE) -> RandomCook:
    """The first of ``seeds`` whose random cook of ``n`` burgers plans within its windows.

    Args:
        n: Burgers per cook. seeds: The seeds to try, in order. plan: Plans one cook order
            (e.g. :func:`plan_cook` with an executor bound). cell: The cell. gap: The least
            distance between burgers' edges (m), as :func:`random_order`.

    Raises:
        ConfigError: No seed's cook planned; the message gives each seed's reason.
    """
    cell = cell or CellConfig()
    refused = []
    for seed in seeds:
        try:
            cook = plan(random_order(n, int(seed), cell, gap))
        except CookConflictError as exc:
            refused.append((int(seed), exc.kind, str(exc)))
            continue
        except ConfigError as exc:  # e.g. no free place for a burger
            refused.append((int(seed), "other", str(exc)))
            continue
        if cook.ok:
            return RandomCook(int(seed), cook, refused)
        refused.append((int(seed), *_refusal(cook)))
    tried = "; ".join(f"seed {s}: {why}" for s, _, why in refused) or "no seed given"
    raise ConfigError(f"no random cook of {n} burgers planned within its windows ({tried})")


__all__ = ["REFUSALS", "PlannedCook", "RandomCook", "first_random_cook", "plan_cook"]
