"""The scoop headings a cook turns its flips to, to keep clear of the burgers on the grill.

:func:`~flipkit.planning.kitchen.clearance.clear_cook` asks :class:`Turns` for a flip's next
heading when its go to burger, scoop, pickup or toss meets a burger still lying where it was
dropped (or when its plan fails at the heading it has). The candidates are the default
heading turned by each of :data:`HEADING_STEPS`, away from
the burger met first (the blade then sweeps farther from it), then toward it, each within
±:data:`~flipkit.config.task.HEADING_LIMIT` of the world's +x.
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.behaviors.targets import default_heading
from flipkit.config import CellConfig
from flipkit.config.task import HEADING_LIMIT, HEADING_STEPS
from flipkit.errors import FlipkitError




class CookConflictError(FlipkitError):
    """A motion of the cook would meet another burger and no landing spot avoids it."""


class Turns:
    """The headings turned so far (``headings``: burger id -> rad) and those tried.

    Args:
        cell: The cell (its base gives the default headings).
        steps: Turns (rad) from the default heading, tried in order on each side.
    """

    def __init__(self, cell: CellConfig, steps=HEADING_STEPS):
        self.cell, self.steps = cell, tuple(float(s) for s in steps)
        self.headings: dict[str, float] = {}
        self.tried: dict[str, list[float]] = {}

    def candidates(self, xy, away: float) -> list[float]:
        """The headings (rad) to try for a burger at ``xy`` (m): the default turned by each
        step toward the side ``away`` (±1) first, then toward the other side, within
        ±HEADING_LIMIT."""
        psi0 = default_heading(self.cell, (*xy, 0.0))
        out = [psi0 + side * s for side in (away, -away) for s in self.steps]
        return [p for p in out if abs(p) <= HEADING_LIMIT + 1e-12]

    def next(self, burger: str, lie, timeline, *, meet=None, failed: bool = False) -> float:
        """Turn ``burger``'s flip to its next heading and return it (rad).

        Args:
            burger: The flip's burger id. lie: The :class:`~flipkit.planning.kitchen.sweep.Lying`
                burger its motion meets (``None`` when its plan failed). timeline: The cook's
                timeline (where ``burger`` was dropped). meet: The meeting, for the message.
            failed: The flip's plan failed at its present heading.

        Raises:
            CookConflictError: Every candidate heading was tried (one line naming the burger,
                the headings tried and the burger met, or that its plans failed).
        """
        rec = next(r for r in timeline.burgers if r.burger.burger == burger)
        xy = np.asarray(rec.burger.location(self.cell), float)[:2]
        psi = self.headings.get(burger, default_heading(self.cell, (*xy, 0.0)))
        if burger in self.headings:
            self.tried.setdefault(burger, []).append(psi)
        away = 1.0
        if lie is not None:  # the side the met burger lies on, seen along the heading
            d = np.array([math.cos(psi), math.sin(psi)])
            v = np.asarray(lie.xy, float) - xy
            away = -1.0 if d[0] * v[1] - d[1] * v[0] > 0 else 1.0
        done = self.tried.get(burger, [])
        left = [p for p in self.candidates(xy, away) if all(abs(p - q) > 1e-9 for q in done)]
        if not left:
            span = sorted([default_heading(self.cell, (*xy, 0.0)), *done])
            tried = ", ".join(f"{math.degrees(p):.0f}" for p in span)
            why = (f"{meet.describe()}; burger {lie.burger} still lies where it was dropped"
                   if lie is not None else f"flip:{burger}: its plan fails")
            raise CookConflictError(f"{why} at every scoop heading tried ({tried} deg): "
                                    f"drop them farther apart")
        self.headings[burger] = left[0]
        return left[0]


__all__ = ["HEADING_STEPS", "CookConflictError", "Turns"]
