"""The arm's motions in a cook, as the scheduler sees them, and the real planners behind them.

The scheduler (:mod:`flipkit.planning.kitchen.schedule`) does not call a planner directly: it is
given a mapping from motion kind (``"flip"``, ``"serve"``) to a :class:`MotionPlanner`, a
function ``(job, q_start) -> PlannedMotion``. :func:`default_planners` wires in the real
ones: :func:`~flipkit.planning.planners.planner.plan_flip` for ``"flip"`` and
:func:`~flipkit.planning.planners.serve.plan_serve` for ``"serve"``. Tests inject planners with fixed
durations.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Mapping, Protocol

import numpy as np

from flipkit.config import CellConfig
from flipkit.errors import FlipkitError, InvalidChoiceError, UnreachableError
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.planner import plan_flip
from flipkit.planning.kitchen.sweep import approach_height
from flipkit.planning.planners.serve import plan_serve, replan_serve, table_spot

KINDS = ("flip", "serve")


class MissingPlannerError(FlipkitError):
    """A motion kind the schedule needs has no planner in the mapping it was given."""


@dataclass(frozen=True)
class MotionJob:
    """What one motion must do.

    Attributes:
        kind: ``"flip"`` or ``"serve"``.
        burger: The burger's id.
        location: Where the burger lies (x, y, z) (m): its drop position for a flip, its
            predicted landing point (on the grill surface) for a serve.
        table_spot: Serve only: the spot (x, y) (m) on the table; ``None`` for a flip.
        land: Flip only: where the flipped burger lands (x, y) (m); ``None``: where it was
            picked up (:mod:`flipkit.planning.kitchen.clearance` moves it out of the way).
        heading: Flip only: the scoop heading (rad); ``None``: the default
            (:func:`~flipkit.behaviors.targets.default_heading`;
            :mod:`flipkit.planning.kitchen.clearance` turns it out of the way).
    """

    kind: str
    burger: str
    location: tuple
    table_spot: tuple | None = None
    land: tuple | None = None
    heading: float | None = None

    @property
    def key(self) -> tuple:
        """What makes two jobs the same motion: every field, positions to 1e-9 m."""
        def r(v):
            return None if v is None else tuple(np.round(np.asarray(v, float), 9))
        return (self.kind, self.burger, r(self.location), r(self.table_spot), r(self.land),
                None if self.heading is None else round(float(self.heading), 9))


@dataclass
class PlannedMotion:
    """A planned motion, reduced to what the scheduler needs.

    Attributes:
        ok: The plan is solved (and verified); only then is it executed.
        duration_s: Execution time of the whole motion (s), start at rest to end at rest.
        event_s: From the motion's start to the burger's event (s): a flip's landing on
            the second side, a serve's lift-off from the grill.
        q_end: Configuration (rad) the arm ends at, at rest; the next motion starts there.
        planning_time_s: Wall time the planning took (s).
        landing: Flip only: the burger's predicted landing point (x, y) (m).
        plan: The plan (anything with ``to_json(path)``), or ``None``.
        failure: One line saying why it is not ``ok``.
        ready_s: Planned ahead (:mod:`flipkit.planning.kitchen.prefetch`): when the plan was in, in s
            from the start of planning; ``None``: planned on demand, in ``planning_time_s``.
    """

    ok: bool
    duration_s: float
    event_s: float
    q_end: np.ndarray
    planning_time_s: float
    landing: tuple | None = None
    plan: object | None = None
    failure: str | None = None
    ready_s: float | None = None


class MotionPlanner(Protocol):
    """Plans one motion of ``job`` starting at rest at ``q_start`` (rad)."""

    def __call__(self, job: MotionJob, q_start: np.ndarray) -> PlannedMotion: ...


def _segment_start(plan, role: str) -> float:
    """Start time (s) of the plan's segment of ``role``, from the start of the plan."""
    span = plan.step_span(role)
    if span is None:
        raise FlipkitError(f"{plan.behavior} plan has no {role} segment "
                           f"(segments: {', '.join(s.name for s in plan.segments)})")
    return span[0]


def from_plan(plan, kind: str, planning_time_s: float) -> PlannedMotion:
    """A :class:`~flipkit.planning.plans.plan_file.Plan` as a :class:`PlannedMotion`.

    The event of a flip is its predicted landing: flip segment start + release time + time
    of flight. The event of a serve is the start of its ``pickup`` segment: the scoop has
    slid the blade under the burger and the lift begins.
    """
    ok = plan.status == "solved"
    duration = plan.duration
    last = plan.segments[-1]
    landing, event = None, duration
    if ok and kind == "flip":
        flip = plan.step("release")
        event = (_segment_start(plan, "release") + flip.release["time"]
                 + flip.landing["time_of_flight"])
        landing = tuple(float(v) for v in flip.landing["point"][:2])
    elif ok:
        event = _segment_start(plan, "lift")
    return PlannedMotion(ok=ok, duration_s=duration, event_s=float(event),
                         q_end=np.asarray(last.q[-1], float), planning_time_s=planning_time_s,
                         landing=landing, plan=plan,
                         failure=None if ok else plan.failure or "plan failed")


def refused(job: MotionJob, q_start, exc: UnreachableError, t0: float) -> PlannedMotion:
    """The motion of ``job`` that the planner refused (a place off the grill area, say): not
    ``ok``, nothing to execute, its failure the planner's one-line reason naming the place."""
    return PlannedMotion(ok=False, duration_s=0.0, event_s=0.0,
                         q_end=np.asarray(q_start, float),
                         planning_time_s=time.perf_counter() - t0,
                         failure=f"refused at ({job.location[0]:.3f}, {job.location[1]:.3f}): "
                                 f"{exc}")


def flip_planner(cell: CellConfig | None = None, solver: str = "auto", atlas=None,
                 caches: PlannerCaches | None = None) -> MotionPlanner:
    """The real flip: :func:`~flipkit.planning.planners.planner.plan_flip` from ``q_start``, landing
    at the job's ``land`` (default where the burger was picked up), scooping along the job's
    ``heading`` (default the radial one), coming in above the other
    burgers on the grill (:func:`~flipkit.planning.kitchen.sweep.approach_height`),
    warm-started from ``atlas`` if given, every flip with ``caches`` (default: new ones,
    kept by the planner returned)."""
    caches = PlannerCaches() if caches is None else caches

    def plan(job: MotionJob, q_start: np.ndarray) -> PlannedMotion:
        t0 = time.perf_counter()
        try:
            p = plan_flip(job.location, q_start, cell=cell, solver=solver, land=job.land,
                          atlas=atlas, approach_height=approach_height(cell or CellConfig()),
                          heading=job.heading, caches=caches)
        except UnreachableError as exc:
            return refused(job, q_start, exc, t0)
        return from_plan(p, "flip", time.perf_counter() - t0)

    return plan


def serve_planner(cell: CellConfig | None = None, solver: str = "auto", atlas=None,
                  caches: PlannerCaches | None = None) -> MotionPlanner:
    """The real serve: :func:`~flipkit.planning.planners.serve.plan_serve` from ``q_start`` to the
    job's table spot, placing the burger where the scoop model says the scoop leaves it on the
    blade (``plan_serve``'s default), coming in above the other
    burgers as the flip does; ``atlas`` (a pickup-and-flip atlas) warm-starts its go to
    burger, scoop and pickup; ``caches`` as :func:`flip_planner`."""
    caches = PlannerCaches() if caches is None else caches

    def plan(job: MotionJob, q_start: np.ndarray) -> PlannedMotion:
        t0 = time.perf_counter()
        try:
            p = plan_serve(job.location, job.table_spot, q_start=q_start, cell=cell,
                           solver=solver, atlas=atlas,
                           approach_height=approach_height(cell or CellConfig()),
                           caches=caches)
        except UnreachableError as exc:  # e.g. a flip's predicted landing off the grill area
            return refused(job, q_start, exc, t0)
        return from_plan(p, "serve", time.perf_counter() - t0)

    return plan


def default_planners(kinds=KINDS, cell: CellConfig | None = None, solver: str = "auto",
                     atlas=None, caches: PlannerCaches | None = None
                     ) -> Mapping[str, MotionPlanner]:
    """The real planners of ``kinds`` (flips warm-started from ``atlas`` if given), all
    planning with ``caches`` (default: new ones, which they share).

    Raises:
        InvalidChoiceError: An unknown kind.
    """
    makers: dict[str, Callable[..., MotionPlanner]] = {"flip": flip_planner,
                                                       "serve": serve_planner}
    caches = PlannerCaches() if caches is None else caches
    out = {}
    for kind in kinds:
        if kind not in makers:
            raise InvalidChoiceError("motion kind", kind, KINDS)
        out[kind] = makers[kind](cell, solver, atlas, caches)
    return out


def serve_replanner(cell: CellConfig | None = None, solver: str = "auto", atlas=None,
                    caches: PlannerCaches | None = None) -> Callable:
    """Sense, plan, act for a cook's serves: ``replan(motion, xy) -> Plan | None`` plans the
    serve of ``motion`` (a scheduled serve with its ``plan``) again, from the same start
    configuration to the same table spot, for its burger seen at ``xy`` (m) on the grill,
    coming in above the other burgers as :func:`serve_planner` does. The plan returned may
    have failed (its ``failure`` says why); a place the planner refuses (off the grill area,
    say) raises :class:`~flipkit.errors.FlipkitError` with its one-line reason. Either way
    the caller runs the scheduled serve. Every re-plan uses ``caches`` (default: new ones,
    kept by the re-planner returned)."""
    cell = cell or CellConfig()
    caches = PlannerCaches() if caches is None else caches

    def replan(motion, xy):
        old = motion.plan
        location = (float(xy[0]), float(xy[1]), float(old.burger["location"][2]))
        return plan_serve(location, table_spot(old), q_start=old.segments[0].q[0],
                          cell=cell, solver=solver, atlas=atlas,
                          approach_height=approach_height(cell), caches=caches)

    return replan


def blade_replanner(solver: str = "auto", caches: PlannerCaches | None = None) -> Callable:
    """Sense, plan, act on the blade for a cook's serves: ``replan(plan, on_blade) -> Plan``
    plans place and return home of the serve ``plan`` again for its burger seen at
    ``on_blade`` (x, y) (m, blade frame) during the carry
    (:func:`~flipkit.planning.planners.serve.replan_serve`; :mod:`flipkit.simulation.cook_blade`),
    every re-plan with ``caches`` (default: new ones, kept by the re-planner returned)."""
    caches = PlannerCaches() if caches is None else caches

    def replan(plan, on_blade):
        return replan_serve(plan, on_blade, solver=solver, caches=caches)

    return replan


def cached_planners(planners: Mapping[str, MotionPlanner]) -> dict[str, MotionPlanner]:
    """``planners`` that plan each distinct motion once: a request with the same kind, burger,
    location, table spot, landing spot and start configuration (to 1e-9) returns the first plan (the same
    object, its planning time included), so two schedules of one cook — the greedy rule and
    CP-SAT — compare on the same plans."""
    done: dict[tuple, PlannedMotion] = {}

    def maker(kind: str) -> MotionPlanner:
        def plan(job: MotionJob, q_start: np.ndarray) -> PlannedMotion:
            key = (kind, *job.key[1:], tuple(np.round(np.asarray(q_start, float), 9)))
            if key not in done:
                done[key] = planners[kind](job, q_start)
            return done[key]
        return plan
    return {kind: maker(kind) for kind in planners}


__all__ = ["KINDS", "MissingPlannerError", "MotionJob", "MotionPlanner",
           "PlannedMotion", "blade_replanner", "cached_planners", "default_planners",
           "flip_planner", "from_plan", "refused", "serve_planner"]
