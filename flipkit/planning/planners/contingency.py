"""Contingency flips: the re-plans that sense-plan-act is likely to need, made ahead.

After the scoop the cell measures where the burger lies on the blade and re-plans the flip
(:func:`~flipkit.planning.planners.planner.replan_flip`). A robust plan lands every place within
its scenarios' promise, and then the re-plan returns it at once. A place outside costs an SQP
solve of flip and turn back while the arm holds. Such places lie beyond the scenario set: in the
tails of the placement and sensing errors, and where the scoop's unmodelled drift takes the
burger, further along the blade or to its side (``docs/robust-flips.md`` §4).
:class:`Contingencies` solves the flips for four such places before they are needed, which a
cell can do while the arm goes to the burger and scoops. At the measurement it hands out the one
that keeps its promise for the measured place (its scenarios' hull holds the place, or its own
release and flight land it within its promise): a check of milliseconds instead of a solve.

Every contingency is a re-plan as :func:`replan_flip` makes it (go to burger, scoop and
pickup kept), solved and verified. Like every re-plan it is robust to the camera's error: it
lands the places 1 cm around its own, so it covers a patch of the blade, not a point. A place
that none of them covers is solved as before.

A contingency may not be ready when the camera looks: the preparation starts with the plan,
and its solves can outlast the motion before the sense. The object records when
each one became ready (``ready_s``, from the start of the preparation). Given ``sense_s``,
the time of the sense on that clock, handing out a contingency that was not ready by then
waits the rest of its solve, as a cell would wait for a solve under way. A plan that is
kept, or a contingency that was ready, costs no wait.
"""

from __future__ import annotations

import concurrent.futures as cf
import time
from dataclasses import dataclass, field

import numpy as np

from flipkit.errors import ConfigError
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.inputs import check_replan
from flipkit.planning.planners.planner import keeps_promise, replan_flip
from flipkit.planning.plans.plan_file import Plan

# m: how far past the scenario set's extremes the contingency places lie: along the blade,
# and to its side. The side margin is larger: the scoop's sideways drift is not in the
# scenario set.
MARGIN = (0.015, 0.025)


def contingency_places(plan: Plan, margin=MARGIN) -> list[tuple[float, float]]:
    """Four places (x, y) (m, blade frame) beyond a robust flip plan's scenario set:
    ``margin[0]`` past its extremes along the blade (at the predicted place's y) and
    ``margin[1]`` past them to each side (at the predicted x), clipped to the blade.

    Raises:
        ConfigError: ``plan`` is not a solved flip plan.
    """
    cell, _ = check_replan(plan, "flip", (0.0, 0.0))
    landing = plan.step("release").landing
    x0, y0 = (float(v) for v in landing["burger_on_blade"][:2])
    pts = np.array([row["burger_on_blade"][:2] for row in landing.get("scenarios", ())]
                   or [(x0, y0)], float)
    half = cell.spatula.half_extent
    mx, my = (float(v) for v in margin)
    places = [(pts[:, 0].min() - mx, y0), (pts[:, 0].max() + mx, y0),
              (x0, pts[:, 1].min() - my), (x0, pts[:, 1].max() + my)]
    return [tuple(float(v) for v in np.clip(p, -half, half)) for p in places]


def solve_contingency(job: tuple, caches: PlannerCaches | None = None) -> Plan:
    """``replan_flip(plan, place, solver=solver, keep=False, caches=caches)`` of ``job =
    (plan, place, solver)`` (a worker's task gives no ``caches``: its own, for the task)."""
    plan, place, solver = job
    return replan_flip(plan, place, solver=solver, keep=False, caches=caches)


@dataclass
class Contingencies:
    """Solved re-plans of one robust flip plan for places on the blade, and their lookup.

    Attributes:
        plan: The flip plan they belong to.
        flips: ``[(place, plan)]``: each place (x, y) (m, blade frame) whose re-plan was
            solved, and that re-plan.
        failed: The places whose re-plan failed (never handed out).
        wall_time_s: Wall time (s) of :meth:`prepare`.
        ready_s: For each of ``flips``, when it was ready (s after the preparation began).
        sense_s: When the camera looks, on the same clock (s); ``None``: every contingency
            counts as ready (module docstring).
        caches: What the re-plans made here reuse
            (:class:`~flipkit.planning.planners.caches.PlannerCaches`): those of
            :meth:`prepare` without an executor, and the solve of a place none covers.
    """

    plan: Plan
    flips: list
    failed: list
    wall_time_s: float
    ready_s: list = field(default_factory=list)
    sense_s: float | None = None
    caches: PlannerCaches = field(default_factory=PlannerCaches, repr=False, compare=False)

    @classmethod
    def prepare(cls, plan: Plan, places=None, *, solver: str = "auto",
                executor=None, caches: PlannerCaches | None = None) -> "Contingencies":
        """Solve the re-plans of ``plan`` for ``places`` (default
        :func:`contingency_places`), on ``executor`` (an Executor) if given, else here with
        ``caches`` (default: new ones, kept by the result).

        Raises:
            ConfigError: ``plan`` is not a solved flip plan, or a place is off the blade.
        """
        caches = PlannerCaches() if caches is None else caches
        t0 = time.perf_counter()
        places = contingency_places(plan) if places is None else [
            tuple(float(v) for v in check_replan(plan, "flip", p)[1]) for p in places]
        jobs = [(plan, p, solver) for p in places]
        made, ready = [None] * len(jobs), [0.0] * len(jobs)
        if executor is None:
            for i, job in enumerate(jobs):
                made[i], ready[i] = solve_contingency(job, caches), time.perf_counter() - t0
        else:
            futures = {executor.submit(solve_contingency, job): i for i, job in enumerate(jobs)}
            for future in cf.as_completed(futures):
                i = futures[future]
                made[i], ready[i] = future.result(), time.perf_counter() - t0
        ok = [i for i, m in enumerate(made) if m.status == "solved"]
        return cls(plan, [(places[i], made[i]) for i in ok],
                   [places[i] for i in range(len(made)) if i not in ok],
                   time.perf_counter() - t0, [ready[i] for i in ok], caches=caches)

    def wait_s(self, k: int) -> float:
        """How long (s) handing out contingency ``k`` at the sense waits for its solve."""
        if self.sense_s is None or not self.ready_s:
            return 0.0
        return max(0.0, self.ready_s[k] - self.sense_s)

    def lookup(self, on_blade) -> Plan | None:
        """The contingency, nearest place first, that keeps its promise for a burger at
        ``on_blade`` (x, y) (m) as the plan would (:func:`keeps_promise`: the place lies in
        its scenarios' hull, or its own release and flight land it within its promise);
        ``None`` when none does.

        Raises:
            ConfigError: ``on_blade`` is off the blade.
        """
        cell, xy = check_replan(self.plan, "flip", on_blade)
        k = self._lookup(xy, self.caches.models(cell))
        return None if k is None else self.flips[k][1]

    def _lookup(self, xy, models) -> int | None:
        """The index in :attr:`flips` that :meth:`lookup` hands out for a checked place."""
        for k in sorted(range(len(self.flips)),
                        key=lambda i: float(np.hypot(*np.subtract(self.flips[i][0], xy)))):
            if keeps_promise(self.flips[k][1], xy, models):
                return k
        return None

    def __call__(self, plan: Plan, on_blade) -> Plan:
        """Sense-plan-act's re-plan (``execute_plan(..., replan=contingencies)``): ``plan``
        itself where it keeps its promise, else the contingency that lands the measured
        place (after waiting :meth:`wait_s` for it), else :func:`replan_flip`'s solve.

        Raises:
            ConfigError: ``plan`` is not the plan these contingencies were made for, or
                ``on_blade`` is off the blade.
        """
        if plan is not self.plan:
            raise ConfigError("these contingencies were made for another plan")
        cell, xy = check_replan(plan, "flip", on_blade)
        models = self.caches.models(cell)
        if keeps_promise(plan, xy, models):
            return plan
        k = self._lookup(xy, models)
        if k is None:
            return replan_flip(plan, xy, keep=False, caches=self.caches)
        time.sleep(self.wait_s(k))  # the solve still under way (module docstring)
        return self.flips[k][1]


__all__ = ["MARGIN", "Contingencies", "contingency_places", "solve_contingency"]
