"""The go to burger's approach: how the blade comes down to where the scoop starts.

A fast go to burger that comes straight down to the scoop's start can meet the largest
burger of the sourced range on its rim, just behind the scoop's start, when it lies a few
millimetres toward the arm, and such a scoop fails. The approach therefore has three phases
over the segment's nodes (constants in :mod:`flipkit.config.task`):

1. until the descent (the last ``APPROACH_FRACTION`` of the intervals): the blade's corners
   ``APPROACH_CLEARANCE`` above the tallest burger of the range, whatever burger lies below;
2. the descent: the tip behind the near rim of the largest burger put two placement standard
   deviations toward the arm (:func:`approach_limits`);
3. the slide (the last ``APPROACH_SLIDE_FRACTION``): the blade pressed into the grill as the
   scoop is, its tip at most ``APPROACH_LOW`` above it and never past the scoop's start. A
   burger in the way is met at its foot and pushed along the grill, as the scoop pushes it.

``flipkit verify`` checks phases 2 and 3 (group ``behavior_path``) and phase 1 with the
segment's floor (``grill_clearance``).
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.behaviors import targets as tg
from flipkit.behaviors.guesses import pose_path
from flipkit.behaviors.options import SCOOP_PRESS, SCOOP_TIP_BAND
from flipkit.config import PHYSICAL_RANGES, CellConfig, ScoopUncertainty
from flipkit.config.task import (APPROACH_CLEARANCE, APPROACH_FRACTION, APPROACH_LOW,
                                 APPROACH_SLIDE_FRACTION)
from flipkit.model.orientation import rpy
from flipkit.transcription.constraints import KinematicBlock
from flipkit.transcription.guess import fit_guess


def descent_node(N: int) -> int:
    """The first node of the descent: the last ``APPROACH_FRACTION`` of N intervals."""
    return N - max(1, int(round(APPROACH_FRACTION * N)))


def slide_node(N: int) -> int:
    """The first node of the slide: the last ``APPROACH_SLIDE_FRACTION`` of N intervals."""
    return N - max(1, int(round(APPROACH_SLIDE_FRACTION * N)))


def approach_limits(cell: CellConfig, pb) -> tuple[float, float]:
    """(rim, start) (m, x of the scoop heading's frame, :meth:`~flipkit.behaviors.spec.Task.frame`,
    the scoop's direction): the furthest the blade's tip comes
    during the descent (the near rim of the largest burger of the range, put
    ``ScoopUncertainty().placement`` toward the arm), and during the slide (the scoop's
    start). ``rim`` never lies past ``start``."""
    ready = tg.scoop_ready(cell, pb)
    start = ready.p[0] + cell.spatula.length / 2 * math.cos(ready.o[1])
    rim = pb[0] - PHYSICAL_RANGES["burger.diameter"][1] / 2 - ScoopUncertainty().placement
    return min(rim, start), start


def arrival_floor(cell: CellConfig, N: int) -> np.ndarray:
    """The go to burger's floor under the blade's corners (m), (N + 1) × 4: above the tallest
    burger until the descent, above the grill during it, the tip pressed into it over the
    slide (the back corners on its surface, :func:`~flipkit.behaviors.targets.tip_pressed`)."""
    floor = np.full((N + 1, 4), cell.grill.height)
    floor[:descent_node(N)] += PHYSICAL_RANGES["burger.thickness"][1] + APPROACH_CLEARANCE
    floor[slide_node(N):] = tg.tip_pressed(cell, cell.grill.height - SCOOP_PRESS - SCOOP_TIP_BAND)
    return floor


def approach_path(ctx) -> list:
    """The descent's and the slide's bounds on the tip's position (module docstring)."""
    L, cell, frame = ctx.layout, ctx.cell, ctx.task.frame()
    rim, start = approach_limits(cell, ctx.location)
    tip = {"length": cell.spatula.length, "width": cell.spatula.width}
    return [KinematicBlock("approach_descent", L, "tip_position",
                           range(descent_node(L.N), slide_node(L.N)), -np.inf,
                           np.array([rim, np.inf, np.inf]), ctx=tip, frame=frame),
            KinematicBlock("approach_slide", L, "tip_position", range(slide_node(L.N), L.N + 1),
                           -np.inf, np.array([start, np.inf, cell.grill.height + APPROACH_LOW]),
                           ctx=tip, frame=frame)]


def approach_guess(ctx, T, pose):
    """The go to burger's initial guess: the blade's pose path
    (:func:`~flipkit.behaviors.guesses.pose_path`) from the start to 5 mm behind the rim and
    above the tallest burger (at the descent's first node), down to the grill there (at the
    slide's first node), then in to ``pose``, fitted by the Bezier polynomial."""
    L, robot = ctx.layout, ctx.robot
    rim, start = approach_limits(ctx.cell, ctx.location)
    end = np.asarray(pose.p, float)
    low = end - ctx.task.frame().world_vector([start - rim + 0.005, 0.0, -0.002])
    high = low + np.array([0.0, 0.0, PHYSICAL_RANGES["burger.thickness"][1]
                           + APPROACH_CLEARANCE + 0.01])
    o1 = np.asarray(pose.o, float)
    knots = [(0.0, robot.position(ctx.q_start), rpy(robot.rotation(ctx.q_start))),
             (descent_node(L.N) / L.N, high, o1), (slide_node(L.N) / L.N, low, o1),
             (1.0, end, o1)]
    return fit_guess(L, robot, pose_path(ctx, knots), T, ctx.qd_start, ctx.spec.at_rest)


__all__ = ["approach_guess", "approach_limits", "approach_path", "arrival_floor",
           "descent_node", "slide_node"]
