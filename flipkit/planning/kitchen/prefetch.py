"""Planning a cook's motions ahead, in parallel worker processes.

Every flip and serve starts at rest at the rest configuration (q_home) and ends there (turn
back and return home end at it), so the flips of a cook order are independent of one another
and each serve depends only on its flip's predicted landing and its table spot.
:class:`PrefetchPlanners` submits every flip to an executor as soon as it is made, and each
serve as soon as its flip's plan is in, with the spot the scheduler gives it (``spots``, one
per burger in drop order: :func:`~flipkit.planning.kitchen.table.assign_spots`). The
scheduler (:func:`~flipkit.planning.kitchen.schedule.schedule_cook`) asks for motions as before; a
request whose job and start configuration match a prefetched one gets that plan, any other
(a start elsewhere) is planned on demand, in this process.

The plans are those of the serial run: the same planner with the same inputs, each in its
own process (the solvers are deterministic and start from nothing a previous solve left;
tested). Each prefetched motion records ``ready_s``, when its plan was in, from the start of
planning, so the schedule's planning clock and slack follow the real (parallel) planning.

A worker that dies (the OOM killer, a crash in native code, a signal) breaks its pool: the
motion it was planning, and every motion after it, is planned on demand in this process,
with one line on stderr, and the cook goes on.
"""

from __future__ import annotations

import concurrent.futures as cf
import sys
import time
from collections.abc import Mapping

import numpy as np
from tqdm import tqdm

from flipkit.config import CellConfig
from flipkit.planning.kitchen.motions import MotionJob, PlannedMotion, default_planners
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import REST_TOL


def plan_motion(kind: str, job: MotionJob, q_start, cell: CellConfig, solver: str,
                atlas=None, caches: PlannerCaches | None = None) -> PlannedMotion:
    """Plan one motion with the real planner of ``kind`` and ``caches`` (a worker's task
    gives none: its own, for the task)."""
    planners = default_planners((kind,), cell, solver, atlas, caches)
    return planners[kind](job, np.asarray(q_start, float))


class PrefetchPlanners(Mapping):
    """Planners (by kind) that serve plans computed ahead on ``executor``.

    Args:
        order: The cook's burgers (:class:`~flipkit.planning.kitchen.cook.CookBurger`), checked.
        kinds: Motion kinds planned (``("flip",)`` or ``("flip", "serve")``).
        q_rest: The rest configuration every motion starts and ends at (rad).
        spots: Table spots (x, y) (m), the k-th for the k-th burger of ``order``.
        executor: A :class:`concurrent.futures.Executor` (worker processes or Dask).
        cell, solver, atlas: As :func:`~flipkit.planning.kitchen.motions.default_planners`.
        caches: What the motions planned on demand, in this process, reuse
            (:class:`~flipkit.planning.planners.caches.PlannerCaches`; default: new ones).
            Each worker's task plans with its own.
    """

    def __init__(self, order, kinds, q_rest, spots, executor: cf.Executor,
                 cell: CellConfig, solver: str = "auto", atlas=None,
                 caches: PlannerCaches | None = None):
        self.kinds, self.cell, self.solver, self.atlas = tuple(kinds), cell, solver, atlas
        self.caches = PlannerCaches() if caches is None else caches
        self.q_rest, self.executor = np.asarray(q_rest, float), executor
        self._spots = {b.burger: tuple(spots[k]) for k, b in enumerate(order) if k < len(spots)}
        self._t0 = time.perf_counter()
        self._futures: dict[tuple, cf.Future] = {}
        self._ready: dict[tuple, float] = {}
        for b in order:
            self._submit(MotionJob("flip", b.burger, b.location(cell)))
        self.on_demand = 0  # motions planned in this process (no prefetched match)

    def _submit(self, job: MotionJob) -> None:
        if self.executor is None:  # the workers died: motions are planned on demand, here
            return
        try:
            fut = self.executor.submit(plan_motion, job.kind, job, self.q_rest, self.cell,
                                       self.solver, self.atlas)
        except cf.BrokenExecutor:
            self._workers_died(job)
            return
        key = job.key
        fut.add_done_callback(lambda _f, key=key: self._ready.setdefault(
            key, time.perf_counter() - self._t0))
        self._futures[key] = fut

    def prefetch(self, job: MotionJob) -> None:
        """Start planning ``job`` from the rest configuration now, unless it is already."""
        if job.key not in self._futures:
            self._submit(job)

    def _result(self, job: MotionJob, q_start) -> PlannedMotion:
        at_rest = np.abs(np.asarray(q_start, float) - self.q_rest).max() <= REST_TOL
        if at_rest:  # a job made later (another landing spot) is planned by a worker too
            self.prefetch(job)
        fut = self._futures.get(job.key)
        if fut is None or not at_rest:
            self.on_demand += 1
            t = time.perf_counter()
            pm = plan_motion(job.kind, job, q_start, self.cell, self.solver, self.atlas,
                             self.caches)
            pm.ready_s = time.perf_counter() - self._t0
            pm.planning_time_s = time.perf_counter() - t
            return pm
        try:
            pm = fut.result()
        except cf.BrokenExecutor:  # its worker died: planned here, like a motion not ahead
            self._workers_died(job)
            del self._futures[job.key]
            return self._result(job, q_start)
        pm.ready_s = self._ready.get(job.key, time.perf_counter() - self._t0)
        if job.kind == "flip" and "serve" in self.kinds and pm.ok and job.burger in self._spots:
            self.prefetch(MotionJob("serve", job.burger, (*pm.landing, self.cell.grill.height),
                                    self._spots[job.burger]))
        return pm

    def _workers_died(self, job: MotionJob) -> None:
        """The pool broke (a worker was killed, or crashed in native code): say so once,
        and plan every motion from now on in this process."""
        if self.executor is not None:
            tqdm.write(f"flipkit: a planning worker died (at {job.kind}:{job.burger}); "
                       "the cook's motions are planned in this process from now on",
                       file=sys.stderr)
        self.executor = None

    def __getitem__(self, kind: str):
        if kind not in self.kinds:
            raise KeyError(kind)
        return self._result

    def __iter__(self):
        return iter(self.kinds)

    def __len__(self) -> int:
        return len(self.kinds)


__all__ = ["PrefetchPlanners", "plan_motion"]
