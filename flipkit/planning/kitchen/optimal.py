"""The optimising cook scheduler: plan every motion once, then order and time them with
CP-SAT (:mod:`flipkit.planning.kitchen.cpsat`).

Every flip and serve starts at rest at q_home and ends there, so a motion's plan — its
duration and the time from its start to its burger event — does not depend on the motions
before it. :func:`schedule_cook_cpsat` therefore plans each flip from ``q_start``, then each
serve from ``q_start`` to the table spot :func:`~flipkit.planning.kitchen.table.assign_spots`
gives it, and hands the planned times to the solver; the plans are the ones executed (a
plan that does not end at rest at ``q_start`` is refused: the times would then depend on
the order). With planners that prefetch in worker processes
(:class:`~flipkit.planning.kitchen.prefetch.PrefetchPlanners`) the flips are requested first,
so every serve is in flight while the remaining flips come in.

The planning clock: every plan is in at ``ready`` (s after ``plan_start``), the schedule is
known ``wall_s`` of CP-SAT later, and no motion may start before ``ready + time_limit_s``
(a bound on when the schedule is known). A motion's slack is its start minus when the
schedule was known.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.planning.kitchen.cook import SECOND_SIDE_S
from flipkit.planning.kitchen.cpsat import BurgerJob, MotionTimes
from flipkit.planning.kitchen.cpsat_process import Child, solve_schedule
from flipkit.planning.kitchen.motions import KINDS, MotionJob, MotionPlanner
from flipkit.planning.kitchen.schedule import (BurgerRecord, MotionRecord, Timeline,
                                              check_cook_inputs)
from flipkit.planning.kitchen.table import DWELL_S
from flipkit.planning.kitchen.windows import Windows
from flipkit.planning.planners.planner import REST_TOL

CPSAT = ("CP-SAT: the order and start times that keep every event in its window with the "
         "least largest, then least total, deviation from its mark; one arm")


def schedule_cook_cpsat(burgers, planners: Mapping[str, MotionPlanner], q_start, *,
                        kinds=KINDS, cell: CellConfig | None = None, spots=None,
                        windows: Windows = Windows(), dwell_s: float = DWELL_S,
                        plan_start: float | None = None, time_limit_s: float = 10.0,
                        workers: int = 1, seed: int = 0, relax: str = "max",
                        lands: Mapping | None = None,
                        headings: Mapping | None = None, child: Child | None = None) -> Timeline:
    """Plan every motion of a cook order from rest, then schedule them with CP-SAT.

    Args:
        burgers, planners, q_start, kinds, cell, spots, plan_start: As
            :func:`~flipkit.planning.kitchen.schedule.schedule_cook`.
        windows: The event windows. dwell_s: Table dwell (s).
        time_limit_s, workers, seed, relax: As
            :func:`~flipkit.planning.kitchen.cpsat_process.solve_schedule`.
        lands: Burger id -> where its flip lands it (x, y) (m); a burger not in it lands
            where it was picked up.
        headings: Burger id -> its flip's scoop heading (rad); a burger not in it gets the
            default heading.
        child: The CP-SAT :class:`~flipkit.planning.kitchen.cpsat_process.Child` to ask,
            started here while the motions are planned; default: one started for this
            schedule and stopped after it.

    Returns:
        The timeline (``policy`` :data:`CPSAT`; ``solver``: status, objectives, wall time).
        A failed plan is recorded (``ok`` False) at its burger's mark and not executed; its
        burger gets no further motion. Whether the windows are met:
        :func:`~flipkit.planning.kitchen.windows.worst_break` of its burgers.

    Raises:
        MissingPlannerError, CookOrderError, ConfigError: As ``schedule_cook``; also a plan
            that does not end at rest at ``q_start``.
        ScheduleTimeoutError: CP-SAT found no schedule within the time limit.
    """
    if child is None:  # a child for this schedule alone (it starts only when warmed)
        with Child() as own:
            return schedule_cook_cpsat(burgers, planners, q_start, kinds=kinds, cell=cell,
                                       spots=spots, windows=windows, dwell_s=dwell_s,
                                       plan_start=plan_start, time_limit_s=time_limit_s,
                                       workers=workers, seed=seed, relax=relax, lands=lands,
                                       headings=headings, child=own)
    cell, kinds, order, spots, assigned = check_cook_inputs(burgers, planners, kinds, cell,
                                                            spots, dwell_s)
    child.warm()  # the CP-SAT child starts while the motions are planned
    serve = "serve" in kinds
    q0 = np.asarray(q_start, float)
    t0 = min(b.t_drop for b in order) if plan_start is None else float(plan_start)
    if not np.isfinite(t0):
        raise ConfigError(f"plan_start must be finite (s), got {plan_start!r}")
    records = {b.burger: BurgerRecord(b) for b in order}
    plans, clock = {}, [0.0]  # (kind, burger) -> PlannedMotion; serial planning clock

    def plan(kind, job):
        pm = planners[kind](job, q0)
        ready = getattr(pm, "ready_s", None)
        clock[0] = max(clock[0], ready) if ready is not None else clock[0] + pm.planning_time_s
        if pm.ok and np.abs(np.asarray(pm.q_end, float) - q0).max() > REST_TOL:
            raise ConfigError(f"{kind}:{job.burger} ends away from its start configuration; "
                              f"the cpsat policy needs motions that start and end at rest at "
                              f"q_home (use --policy greedy)")
        plans[kind, job.burger] = pm
        if not pm.ok:
            records[job.burger].failure = f"{kind}: {pm.failure}"
        return pm

    flips = [MotionJob("flip", b.burger, b.location(cell),
                       land=None if (lands or {}).get(b.burger) is None
                       else tuple(lands[b.burger]),
                       heading=(headings or {}).get(b.burger)) for b in order]
    for job in flips:  # planners that plan ahead start every flip now
        getattr(planners, "prefetch", lambda job: None)(job)
    for b, job in zip(order, flips):
        pm = plan("flip", job)
        if pm.ok:
            records[b.burger].landing = pm.landing if pm.landing is not None else (b.x, b.y)
    if serve:
        for b in order:
            rec = records[b.burger]
            if plans["flip", b.burger].ok:
                plan("serve", MotionJob("serve", b.burger, (*rec.landing, cell.grill.height),
                                        tuple(assigned[b.burger].spot)))
    ready = clock[0]
    flipped = [b for b in order if plans["flip", b.burger].ok]
    index = {b.burger: k for k, b in enumerate(flipped)}

    def times(kind, b):
        pm = plans.get((kind, b.burger))
        return MotionTimes(pm.duration_s, pm.event_s) if pm is not None and pm.ok else None

    jobs = [BurgerJob(b.burger, b.t_drop, times("flip", b), times("serve", b) if serve else None,
                      index.get(assigned[b.burger].previous) if serve else None)
            for b in flipped]
    result = solve_schedule(jobs, windows, dwell_s=dwell_s, earliest_s=t0 + ready + time_limit_s,
                            time_limit_s=time_limit_s, workers=workers, seed=seed,
                            relax=relax, child=child) if jobs else None
    known = t0 + ready + (result.wall_s if result else 0.0)
    motions = []
    for (kind, burger), pm in plans.items():
        rec, k = records[burger], index.get(burger)
        start = (result.starts.get((kind, k)) if result is not None and k is not None
                 else None)
        if not pm.ok or start is None:  # not executed: shown at its burger's mark
            due = rec.burger.flip_mark if kind == "flip" else rec.burger.serve_mark
            motions.append(MotionRecord(kind, burger, due, due, due, None, known,
                                        pm.planning_time_s, due - known, False,
                                        pm.failure, pm.plan))
            continue
        event = start + pm.event_s
        due = rec.burger.flip_mark if kind == "flip" else rec.flip_time + SECOND_SIDE_S
        motions.append(MotionRecord(kind, burger, due, start, start + pm.duration_s, event,
                                    known, pm.planning_time_s, start - known, True, None,
                                    pm.plan))
        if kind == "flip":
            rec.flip_time = event
        else:
            rec.serve_time, rec.table_spot = event, tuple(assigned[burger].spot)
    motions.sort(key=lambda m: (m.start, m.kind != "flip"))
    solver = None if result is None else {
        "name": "cp-sat", "status": result.status, "wall_s": round(result.wall_s, 6),
        "solve_s": None if result.solve_s is None else round(result.solve_s, 6),
        "time_limit_s": time_limit_s, "workers": workers, "seed": seed, "relax": relax,
        "windows_met": result.breach is None, "proved_infeasible": result.proved_infeasible,
        "max_excess_s": result.max_excess_s, "max_deviation_s": result.max_deviation_s,
        "total_deviation_s": result.total_deviation_s}
    return Timeline([records[b.burger] for b in order], motions, kinds, t0, policy=CPSAT,
                    windows=windows, dwell_s=dwell_s, solver=solver)


__all__ = ["CPSAT", "schedule_cook_cpsat"]
