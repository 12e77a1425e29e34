"""A model of the motions' times, for streams: each kind's duration and event time taken
from a few representative plans, instead of planning every motion of a long stream.

Every flip and serve starts and ends at rest at q_home, and their planned times vary little
over the grill: each segment runs to its upper duration bound, which only a far spot or an
awkward place stretches (``docs/scheduling.md`` gives them). :func:`plan_model` plans a flip
at each of :data:`REPRESENTATIVE` (Table I locations 1, 6 and 10: the grill's near corner,
middle and far corner) and a serve from each landing to the nearest, a middle and the
farthest table spot, and keeps per kind the longest plan (conservative for the arm's load)
with its own event time. :meth:`MotionModel.planners` then stands in for the real planners:
every motion takes the model's times, lands where it was picked up and ends at rest.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from flipkit.config import TABLE1_LOCATIONS, CellConfig
from flipkit.errors import FlipkitError
from flipkit.model.robot import Robot
from flipkit.planning.kitchen.cook import CookBurger, table_spots
from flipkit.planning.kitchen.cpsat import MotionTimes
from flipkit.planning.kitchen.motions import MotionJob, MotionPlanner, PlannedMotion
from flipkit.planning.kitchen.reach import to_task_frame
from flipkit.planning.kitchen.sweep import footprint

REPRESENTATIVE = tuple(TABLE1_LOCATIONS[k - 1][:2] for k in (1, 6, 10))  # (x, y) (m)


class ModelPlanError(FlipkitError):
    """A representative motion of the duration model could not be planned."""


@dataclass(frozen=True)
class MotionModel:
    """Per motion kind, its duration and event time (s).

    Attributes:
        flip, serve: :class:`~flipkit.planning.kitchen.cpsat.MotionTimes`.
        source: Where the times come from (one line).
        footprints: Per kind, the footprint of the plan the times come from, in its
            burger's task frame (:func:`~flipkit.planning.kitchen.reach.to_task_frame`), or
            ``None`` (times given, no plans): what
            :func:`~flipkit.planning.kitchen.reach.blocked_burgers` checks a stream with.
    """

    flip: MotionTimes
    serve: MotionTimes
    source: str = "given"
    footprints: dict | None = field(default=None, compare=False, repr=False)

    def times(self, kind: str) -> MotionTimes:
        """The times of ``kind`` ("flip" or "serve")."""
        return {"flip": self.flip, "serve": self.serve}[kind]

    def planners(self) -> dict[str, MotionPlanner]:
        """Planners that return the model's times at once: ok, ending where they started
        (at rest), a flip landing where its burger lay; planning time 0."""
        def maker(kind: str) -> MotionPlanner:
            t = self.times(kind)

            def plan(job: MotionJob, q_start) -> PlannedMotion:
                return PlannedMotion(ok=True, duration_s=t.duration_s, event_s=t.event_s,
                                     q_end=np.asarray(q_start, float), planning_time_s=0.0,
                                     landing=tuple(job.location[:2]) if kind == "flip" else None)
            return plan
        return {kind: maker(kind) for kind in ("flip", "serve")}

    def to_dict(self) -> dict:
        """``{"flip": {"duration_s", "event_s"}, "serve": {...}, "source"}``."""
        return {"flip": vars(self.flip).copy(), "serve": vars(self.serve).copy(),
                "source": self.source}


def representative_order(cell: CellConfig | None = None) -> tuple[list[CookBurger], list]:
    """The burgers (:data:`REPRESENTATIVE`, dropped 200 s apart so they never share the
    grill) and the table spots their serves go to: nearest, middle and farthest."""
    spots = table_spots(cell)
    picks = [spots[0], spots[len(spots) // 2], spots[-1]]
    burgers = [CookBurger(f"model{k + 1}", 200.0 * k, x, y)
               for k, (x, y) in enumerate(REPRESENTATIVE)]
    return burgers, picks[:len(burgers)]


def plan_model(planners: Mapping[str, MotionPlanner], q_rest,
               cell: CellConfig | None = None) -> MotionModel:
    """Plan the representative motions (:func:`representative_order`) from ``q_rest`` and
    keep per kind the longest (module docstring).

    Args:
        planners: Real planners by kind (``flip`` and ``serve``), e.g.
            :func:`~flipkit.planning.kitchen.motions.default_planners` or prefetching ones
            built for :func:`representative_order` (the flips are asked for first).
        q_rest: The rest configuration (rad).

    Raises:
        ModelPlanError: A representative plan failed (one line, which and why).
    """
    cell = cell or CellConfig()
    burgers, spots = representative_order(cell)
    q = np.asarray(q_rest, float)
    done = {"flip": [], "serve": []}
    landings = []
    for b in burgers:
        pm = planners["flip"](MotionJob("flip", b.burger, b.location(cell)), q)
        if not pm.ok:
            raise ModelPlanError(f"duration model: the flip at ({b.x}, {b.y}) m failed: "
                                 f"{pm.failure}")
        done["flip"].append(pm)
        landings.append(pm.landing if pm.landing is not None else (b.x, b.y))
    for b, land, spot in zip(burgers, landings, spots):
        pm = planners["serve"](MotionJob("serve", b.burger, (*land, cell.grill.height),
                                         tuple(spot)), q)
        if not pm.ok:
            raise ModelPlanError(f"duration model: the serve from ({land[0]:.3f}, "
                                 f"{land[1]:.3f}) m to {tuple(spot)} failed: {pm.failure}")
        done["serve"].append(pm)
    longest = {k: max(v, key=lambda p: p.duration_s) for k, v in done.items()}
    spread = {k: (min(p.duration_s for p in v), max(p.duration_s for p in v))
              for k, v in done.items()}
    source = (f"the longest of {len(burgers)} planned flips ({spread['flip'][0]:.2f}-"
              f"{spread['flip'][1]:.2f} s) and serves ({spread['serve'][0]:.2f}-"
              f"{spread['serve'][1]:.2f} s)")
    return MotionModel(*(MotionTimes(longest[k].duration_s, longest[k].event_s)
                         for k in ("flip", "serve")), source=source,
                       footprints=_task_footprints(longest, cell))


def _task_footprints(longest: dict, cell: CellConfig) -> dict | None:
    """Each kind's plan's footprint in its burger's task frame; ``None`` without plans."""
    if any(pm.plan is None for pm in longest.values()):
        return None
    robot = Robot(cell, with_burger=False)
    out = {}
    for kind, pm in longest.items():
        pb = np.asarray(pm.plan.burger["location"], float)[:2]
        out[kind] = to_task_frame(footprint(pm.plan, cell, robot), pb,
                                  float(pm.plan.burger["heading"]))
    return out


__all__ = ["REPRESENTATIVE", "ModelPlanError", "MotionModel", "plan_model",
           "representative_order"]
