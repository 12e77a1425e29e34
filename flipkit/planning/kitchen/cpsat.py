"""The cook as a constraint program: the order and start times of one arm's flips and serves
that keep every event closest to its mark, solved with OR-Tools CP-SAT.

Every motion starts and ends at rest at the same configuration (q_home), so its duration
and the time from its start to its burger event do not depend on the motions before it;
they are given (:class:`MotionTimes`, from the motions' plans or a model of them). Time is
integer, in ms, rounded so that the schedule in seconds is never worse on the safe side:
durations and marks up, event times down (no overlap, no event early; an event may come up
to 2 ms later than the model has it). Per burger k with drop ``t_k``:

* variables: the start of its flip ``f_k`` and of its serve ``s_k``, each an interval of
  the motion's duration; one ``NoOverlap`` over all intervals (one arm);
* deviations: flip ``df_k = f_k + e_f − (t_k + 90 s)``, serve
  ``ds_k = s_k + e_s − (f_k + e_f + 60 s)`` (the serve's mark follows its flip's landing);
* no flip before the drop nor before ``earliest_s`` (the plans are in); the serve after its
  flip ends; a serve to a spot used before lifts off ``dwell_s`` after the previous serve to
  that spot ended (:mod:`~flipkit.planning.kitchen.table`);
* no event earlier than its window allows (a side cooked short is never traded); the
  excess beyond the window ``x ≥ d − late``, ``x ≥ 0``.

Objectives, lexicographic, one solve each, with the previous optimum as a bound and the
previous solution as a hint (the first hint: :func:`edf_hint`, the greedy rule):

* first with every event in its window (``x = 0``): (B) the largest absolute deviation,
  then (C) the total absolute deviation;
* when that is infeasible (or undecided within the time limit), with lateness beyond the
  windows allowed, and first (``relax="max"``, a cook) (A) the largest excess — how much
  the worst event must break its window at the least — then the number of burgers beyond
  their windows, B and C; or (``relax="count"``, a stream) the number of burgers beyond
  their windows first, then A, B and C (the first pair in one solve, as a weighted sum
  that keeps the order). Several events often share the least largest
  excess; the one named (:class:`~flipkit.planning.kitchen.windows.WindowBreak`) is a late
  one of the last burger among them.

One worker, a fixed seed and a limit in CP-SAT's deterministic time (its count of work, about
seconds on one worker; ``max_deterministic_time``) make the result the same on every run and
machine, also when a stage is stopped by the limit: it keeps its best solution, and the
status says ``feasible`` instead of ``optimal``.

:func:`solve_here` solves in the calling process, given OR-Tools' ``cp_model`` module;
:func:`~flipkit.planning.kitchen.cpsat_process.solve_schedule` runs it in a child process, as
every caller in the package does.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from flipkit.errors import FlipkitError, InvalidChoiceError
from flipkit.planning.kitchen.cook import FIRST_SIDE_S, SECOND_SIDE_S
from flipkit.planning.kitchen.windows import WindowBreak, Windows

MS = 1000  # model time units per s
RELAX = ("max", "count")  # the first objective when the windows cannot be met


class ScheduleTimeoutError(FlipkitError):
    """CP-SAT found no schedule at all within its time limit."""


@dataclass(frozen=True)
class MotionTimes:
    """A planned motion's duration and the time from its start to its burger event (s)."""

    duration_s: float
    event_s: float


@dataclass(frozen=True)
class BurgerJob:
    """One burger as the model sees it.

    Attributes:
        burger: Its id. t_drop: Its drop time (s).
        flip: Its flip's times. serve: Its serve's times (``None``: not served).
        previous: Index (in the job list) of the burger served to the same table spot
            before it (``None``: none).
    """

    burger: str
    t_drop: float
    flip: MotionTimes
    serve: MotionTimes | None = None
    previous: int | None = None


@dataclass
class CpSatSchedule:
    """The solved schedule.

    Attributes:
        starts: ``(kind, job index)`` → start (s).
        status: ``"optimal"`` (every stage proved) or ``"feasible"`` (a stage hit the limit).
        max_excess_s, max_deviation_s, total_deviation_s: The three objectives (s).
        breach: The event furthest beyond its window when ``max_excess_s`` > 0, else ``None``.
        wall_s: Wall time (s), all stages (from a child process: its start too).
        proved_infeasible: CP-SAT proved that no schedule keeps every event in its window
            (``False`` when the windows are met, or when it ran out of time deciding).
    """

    starts: dict
    status: str
    max_excess_s: float
    max_deviation_s: float
    total_deviation_s: float
    breach: WindowBreak | None
    wall_s: float
    proved_infeasible: bool = False
    solve_s: float | None = None  # the solves alone, in the child process (s)


def _ms(seconds: float) -> int:
    return int(round(seconds * MS))


def _up(seconds: float) -> int:
    return int(math.ceil(seconds * MS - 1e-6))


def _down(seconds: float) -> int:
    return int(math.floor(seconds * MS + 1e-6))


class _Model:
    """The CP-SAT model of ``jobs`` (``cp``: OR-Tools' ``cp_model`` module); ``hard``: every
    deviation within its window, else lateness beyond it is allowed (the excess variables)."""

    def __init__(self, cp, jobs, windows: Windows, dwell_s: float, earliest_s: float,
                 hard: bool):
        self.m = m = cp.CpModel()
        work = sum(j.flip.duration_s + (j.serve.duration_s if j.serve else 0.0) for j in jobs)
        horizon = _ms(max(j.t_drop for j in jobs) + FIRST_SIDE_S + SECOND_SIDE_S + work
                      + dwell_s * (1 + len(jobs)) + 120.0)
        self.starts, self.events, intervals = {}, [], []
        floor = _up(earliest_s) if math.isfinite(earliest_s) else 0
        for k, j in enumerate(jobs):
            for kind, t in (("flip", j.flip), ("serve", j.serve)):
                if t is not None:
                    s = m.NewIntVar(max(_up(j.t_drop), floor), horizon, f"{kind}_{k}")
                    dur = _up(t.duration_s)
                    intervals.append(m.NewFixedSizeIntervalVar(s, dur, f"{kind}_{k}_iv"))
                    self.starts[kind, k] = (s, dur, _down(t.event_s))
            f, fdur, fev = self.starts["flip", k]
            devs = {"flip": f + fev - _up(j.t_drop + FIRST_SIDE_S)}
            if j.serve is not None:
                s, _, sev = self.starts["serve", k]
                m.Add(s >= f + fdur)
                devs["serve"] = s + sev - f - _up(j.flip.event_s) - _ms(SECOND_SIDE_S)
            for event, dev in devs.items():
                early, late = (_ms(v) for v in windows.of(event))  # never early beyond it
                d = m.NewIntVar(-early, late if hard else horizon, f"d_{event}_{k}")
                m.Add(d == dev)
                x = m.NewIntVar(0, 0 if hard else horizon, f"x_{event}_{k}")
                m.Add(x >= d - late)
                self.events.append((k, event, x, d))
            prev = j.previous
            if j.serve is not None and prev is not None and ("serve", prev) in self.starts:
                p, pdur, _ = self.starts["serve", prev]
                m.Add(s + sev >= p + pdur + _up(dwell_s))
        m.AddNoOverlap(intervals)
        self.max_x = m.NewIntVar(0, horizon, "max_x")
        self.max_d = m.NewIntVar(0, horizon, "max_d")
        m.AddMaxEquality(self.max_x, [e[2] for e in self.events])
        self.n_late = 0  # burgers with an event beyond its window
        if not hard:
            late_b = [m.NewBoolVar(f"late_{k}") for k in range(len(jobs))]
            for k, _, x, _ in self.events:
                m.Add(x == 0).OnlyEnforceIf(late_b[k].Not())
            self.n_late = sum(late_b)
        # the relaxed first stage, one lexicographic pair as one weighted sum (a solve stopped
        # by the time limit still presses on the second): "max" the largest excess, then the
        # burgers beyond; "count" the other way round
        self.excess_first = self.max_x * (len(jobs) + 1) + self.n_late
        self.count_first = self.n_late * (horizon + 1) + self.max_x
        abs_d = []
        for _, _, _, d in self.events:
            a = m.NewIntVar(0, horizon, "")
            m.AddAbsEquality(a, d)
            abs_d.append(a)
        m.AddMaxEquality(self.max_d, abs_d)
        self.total = sum(abs_d)

    def hint(self, values: dict) -> None:
        """Hint the starts only (ms by ``(kind, k)``)."""
        self.m.ClearHints()
        for key, (s, _, _) in self.starts.items():
            self.m.AddHint(s, values[key])

    def variables(self) -> list:
        return [self.m.GetIntVarFromProtoIndex(i) for i in range(len(self.m.Proto().variables))]

    def snapshot(self, solver) -> list:
        """Every variable's value in ``solver``'s last solution."""
        return [solver.Value(v) for v in self.variables()]

    def hint_all(self, full: list) -> None:
        """Hint every variable: a complete solution (of an earlier stage)."""
        self.m.ClearHints()
        for v, value in zip(self.variables(), full):
            self.m.AddHint(v, value)

    def read(self, full: list, windows: Windows) -> tuple[dict, list]:
        """The starts (ms by ``(kind, k)``) and the events ``(k, event, excess, deviation)``
        (ms) of the solution ``full``."""
        starts = {key: full[s.Index()] for key, (s, _, _) in self.starts.items()}
        events = [(k, e, _excess(windows, e, full[d.Index()]), full[d.Index()])
                  for k, e, _, d in self.events]  # x is only bounded below: from d
        return starts, events


def edf_hint(jobs, dwell_s: float, earliest_s: float = -math.inf) -> dict:
    """Starts (ms) by earliest deadline first, none before its mark (the greedy rule of
    :mod:`~flipkit.planning.kitchen.schedule` on given times), on the model's integer times
    so that it is one of the model's solutions: CP-SAT's first."""
    out, ends, free = {}, {}, -math.inf
    floor = _up(earliest_s) if math.isfinite(earliest_s) else 0
    pending = [(_up(j.t_drop + FIRST_SIDE_S), k, "flip") for k, j in enumerate(jobs)]
    while pending:
        pending.sort()
        due, k, kind = pending.pop(0)
        j = jobs[k]
        t = j.flip if kind == "flip" else j.serve
        ev = _down(t.event_s)
        start = max(free, due - ev, _up(j.t_drop), floor)
        if kind == "serve" and j.previous in ends:
            start = max(start, ends[j.previous] + _up(dwell_s) - ev)
        out[kind, k] = start
        free = start + _up(t.duration_s)
        if kind == "flip" and j.serve is not None:
            pending.append((start + _up(t.event_s) + _ms(SECOND_SIDE_S), k, "serve"))
        elif kind == "serve":
            ends[k] = free
    return out


def _fixed(solver, model: "_Model", limit_s: float, cp) -> list | None:
    """``model``'s hint, completed to a whole solution (every variable) with the hinted ones
    fixed, or ``None`` when it is no solution (or that took longer than ``limit_s``); the
    solver then holds it."""
    solver.parameters.fix_variables_to_their_hinted_value = True
    solver.parameters.max_deterministic_time = limit_s
    try:
        code = solver.Solve(model.m)
    finally:
        solver.parameters.fix_variables_to_their_hinted_value = False
    return model.snapshot(solver) if code in (cp.OPTIMAL, cp.FEASIBLE) else None


def check_jobs(jobs, relax: str) -> None:
    """Refuse an unknown ``relax`` (:class:`~flipkit.errors.InvalidChoiceError`) or no jobs."""
    if relax not in RELAX:
        raise InvalidChoiceError("relaxed objective", relax, RELAX)
    if not jobs:
        raise FlipkitError("no burgers to schedule")


def solve_here(cp, jobs, windows: Windows = Windows(), *, dwell_s: float = 0.0,
               earliest_s: float = -math.inf, time_limit_s: float = 10.0,
               workers: int = 1, seed: int = 0, relax: str = "max") -> CpSatSchedule:
    """The solve, in this process, with ``cp`` OR-Tools' ``cp_model`` module (the child's
    work in :mod:`~flipkit.planning.kitchen.cpsat_process`).

    Args:
        cp: ``ortools.sat.python.cp_model``.
        jobs: :class:`BurgerJob` rows, any order. windows: Event windows.
        dwell_s: Table dwell (s). earliest_s: No motion before (s).
        time_limit_s: Limit for all solves together, in CP-SAT's deterministic time (about
            seconds on one worker; the same work on every run).
        workers: CP-SAT search workers. seed: CP-SAT random seed.
        relax: The first objective when the windows cannot be met: "max" or "count".

    First with every event in its window (the stages B and C); when that is infeasible (or
    not decided within the limit), with lateness beyond the windows allowed (A, B, C). No
    event is ever earlier than its window allows. The first solution is hinted by
    :func:`edf_hint`.
    """
    jobs = list(jobs)
    check_jobs(jobs, relax)
    solver = cp.CpSolver()
    solver.parameters.num_search_workers = int(workers)
    solver.parameters.random_seed = int(seed)
    t0, proved, last = time.perf_counter(), True, edf_hint(jobs, dwell_s, earliest_s)
    found = infeasible = False

    used = [0.0]  # deterministic time spent so far

    def remaining() -> float:
        return max(0.05, time_limit_s - used[0])

    def solve(model_):
        code_ = solver.Solve(model_.m)
        used[0] += solver.ResponseProto().deterministic_time
        return code_

    for hard in (True, False):
        model = _Model(cp, jobs, windows, dwell_s, earliest_s, hard)
        stages = ((model.max_d, model.total) if hard else
                  (model.excess_first if relax == "max" else model.count_first,
                   model.max_d, model.total))
        full = None  # a complete solution of this model, every variable's value
        for objective in stages:
            model.m.Minimize(objective)
            if full is None:  # complete the hinted starts (a partial hint can be lost)
                model.hint(last)
                full = _fixed(solver, model, min(remaining(), 2.0), cp)
            if full is not None:
                model.hint_all(full)
            solver.parameters.max_deterministic_time = remaining()
            code = solve(model)
            infeasible = infeasible or (hard and code == cp.INFEASIBLE)
            if code in (cp.OPTIMAL, cp.FEASIBLE):
                full = model.snapshot(solver)
            elif full is None:
                proved = proved and found  # a later stage stopped: keep what was found
                break
            else:  # stopped without a better one: the hint's solution, evaluated
                _fixed(solver, model, 2.0, cp)
            found, proved = True, proved and code == cp.OPTIMAL
            last, events = model.read(full, windows)
            model.m.Add(objective <= int(solver.Value(objective)))
        if found:
            break
        proved = True  # the hard model's infeasibility is not a stage of the answer
    if not found:
        raise ScheduleTimeoutError(
            f"CP-SAT found no schedule within {time_limit_s:g} s; raise --time-limit or use "
            "--policy greedy")
    # the worst event; among ties (a min-max spreads the excess), a late one, the last burger
    worst = max(events, key=lambda e: (e[2], e[3] > 0, e[0], e[1] == "serve"))
    breach = None
    if worst[2] > 0:
        k, event, x, d = worst
        breach = WindowBreak(jobs[k].burger, event, d / MS, x / MS, windows.of(event),
                             sum(e[2] == x for e in events) - 1)
    return CpSatSchedule({key: v / MS for key, v in last.items()},
                         "optimal" if proved else "feasible",
                         max(e[2] for e in events) / MS, max(abs(e[3]) for e in events) / MS,
                         sum(abs(e[3]) for e in events) / MS, breach,
                         time.perf_counter() - t0, infeasible)


def _excess(windows: Windows, event: str, dev_ms: int) -> int:
    early, late = (_ms(v) for v in windows.of(event))
    return max(0, dev_ms - late, -early - dev_ms)


__all__ = ["MS", "RELAX", "BurgerJob", "CpSatSchedule", "MotionTimes", "ScheduleTimeoutError",
           "check_jobs", "edf_hint", "solve_here"]
