"""The scoop headings a cook turns its flips to, to keep clear of the burgers on the grill.

:func:`~flipkit.planning.kitchen.clearance.clear_cook` asks :class:`Turns` for a flip's next
heading when its go to burger, scoop, pickup or toss meets a burger still lying where it was
dropped (or when its plan fails at the heading it has). The candidates are the default
(radial) heading turned by each multiple of :data:`TURN_STEP` up to :data:`MAX_TURN` either
way, within ±:data:`~flipkit.config.task.HEADING_LIMIT` of the world's +x. Each is ranked by
the flip's footprint turned to it (:mod:`flipkit.planning.kitchen.heading_model`) against the
burgers lying while it runs: those predicted clear first, the smallest turn first (the radial
heading is the fastest scoop, ``docs/heading.md``), then the others by how far they are
predicted to sweep inside the clearances; turns beyond those the atlas solved near the burger
come after the rest. At most :data:`MAX_TRIES` headings are planned per burger: a plan costs about a second, and one
that fails at a heading out of reach up to fifteen.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from flipkit.behaviors.targets import default_heading
from flipkit.config import CellConfig
from flipkit.config.task import HEADING_LIMIT, HEADING_STEPS
from flipkit.errors import FlipkitError

TURN_STEP = math.radians(5.0)  # rad: turns the blade's far corner about 1.5 cm
MAX_TURN = math.radians(30.0)  # rad: the atlas's widest turn (flipkit.config.task.HEADING_STEPS)
MAX_TRIES = 4  # headings planned per burger beyond its first


CONFLICTS = ("landing", "heading", "other")
"""What a :class:`CookConflictError` ran out of: landing spots clear of the other burgers
(``landing``), scoop headings that pass them (``heading``), or rounds or schedules
(``other``)."""


class CookConflictError(FlipkitError):
    """A motion of the cook would meet another burger and no landing spot avoids it.

    Args:
        message: One line naming the burger and what it meets.
        kind: What ran out, one of :data:`CONFLICTS`.
    """

    def __init__(self, message: str, kind: str = "other"):
        if kind not in CONFLICTS:
            raise ValueError(f"conflict kind {kind!r}: one of {', '.join(CONFLICTS)}")
        super().__init__(message)
        self.kind = kind


class Turns:
    """The headings turned so far (``headings``: burger id -> rad) and those tried.

    Args:
        cell: The cell (its base gives the default headings).
        step, max_turn: The candidate turns (rad): multiples of ``step`` up to ``max_turn``.
        max_tries: Headings planned per burger beyond its default.
        solved: ``xy -> turns (rad)`` solved near a place
            (:meth:`~flipkit.planning.planners.atlas.Atlas.solved_turns`), or ``None``:
            turns beyond those, by more than half the atlas's step, are tried last.
    """

    def __init__(self, cell: CellConfig, step: float = TURN_STEP, max_turn: float = MAX_TURN,
                 max_tries: int = MAX_TRIES, solved=None):
        if not 0 < step <= max_turn:
            raise FlipkitError(f"turn step {step} rad must lie in (0, max_turn {max_turn}]")
        self.cell, self.max_tries, self.solved = cell, int(max_tries), solved
        n = int(round(max_turn / step))
        self.turns = tuple(sorted((k * step for k in range(-n, n + 1) if k), key=abs))
        self.headings: dict[str, float] = {}
        self.tried: dict[str, list[float]] = {}
        self.depths: dict[str, dict[float, float]] = {}  # burger -> heading -> predicted m·s

    def default(self, xy) -> float:
        """The default heading (rad) of a burger at ``xy`` (m)."""
        return default_heading(self.cell, (*xy, 0.0))

    def candidates(self, xy) -> list[float]:
        """The headings (rad) a burger at ``xy`` (m) may be turned to, smallest turn first,
        within ±HEADING_LIMIT."""
        psi0 = self.default(xy)
        return [psi0 + d for d in self.turns if abs(psi0 + d) <= HEADING_LIMIT + 1e-12]

    def _out_of_reach(self, xy) -> Callable[[float], bool]:
        """``heading -> bool``: its turn lies beyond the turns solved near ``xy`` by more
        than half the atlas's step (always ``False`` without ``solved``)."""
        if self.solved is None:
            return lambda p: False
        turns = np.asarray(self.solved(xy), float)
        if not turns.size:
            return lambda p: False
        half, psi0 = HEADING_STEPS[0] / 2, self.default(xy)
        lo, hi = turns.min() - half, turns.max() + half
        return lambda p: not lo - 1e-9 <= p - psi0 <= hi + 1e-9

    def next(self, burger: str, lie, timeline, *, meet=None, failed: bool = False,
             overlap: Callable[[float], float] | None = None) -> float:
        """Turn ``burger``'s flip to its next heading and return it (rad).

        Args:
            burger: The flip's burger id. lie: The :class:`~flipkit.planning.kitchen.sweep.Lying`
                burger its motion meets (``None`` when its plan failed). timeline: The cook's
                timeline (where ``burger`` was dropped). meet: The meeting, for the message.
            failed: The flip's plan failed at its present heading.
            overlap: ``turn (rad) -> m·s``: how far inside the other burgers' clearance
                the present plan, turned by that much, is predicted to sweep
                (:func:`~flipkit.planning.kitchen.heading_model.predicted_overlap`); without
                it the candidates keep their order.

        Raises:
            CookConflictError: No candidate left, or :data:`MAX_TRIES` planned (one line
                naming the burger, the headings tried and the burger met, or that its plans
                failed).
        """
        rec = next(r for r in timeline.burgers if r.burger.burger == burger)
        xy = np.asarray(rec.burger.location(self.cell), float)[:2]
        psi = self.headings.get(burger, self.default(xy))
        done = self.tried.setdefault(burger, [])
        if all(abs(psi - q) > 1e-9 for q in done):
            done.append(psi)
        left = [p for p in self.candidates(xy) if all(abs(p - q) > 1e-9 for q in done)]
        if left and len(done) <= self.max_tries:
            if overlap is not None:  # a failed plan's turn keeps the last ranking
                self.depths[burger] = {p: overlap(p - psi) for p in left}
            depth = self.depths.get(burger, {})
            far = self._out_of_reach(xy)
            left.sort(key=lambda p: (far(p), depth.get(p, 0.0)))  # stable: clear ones by turn
            self.headings[burger] = left[0]
            return left[0]
        tried = ", ".join(f"{math.degrees(p):.0f}" for p in sorted(done))
        why = (f"{meet.describe()}; burger {lie.burger} still lies where it was dropped"
               if lie is not None and meet is not None else f"flip:{burger}: its plan fails")
        widest = math.degrees(max(abs(d) for d in self.turns))
        raise CookConflictError(f"{why} at every scoop heading tried ({tried} deg; turns "
                                f"within {widest:.0f} deg of radial, at most "
                                f"{self.max_tries + 1} planned): drop them farther apart",
                                kind="heading")


__all__ = ["CONFLICTS", "MAX_TRIES", "MAX_TURN", "TURN_STEP", "CookConflictError", "Turns"]
