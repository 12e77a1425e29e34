"""Solving a chain of segments: one segment with a solver, one with its duration bound
stretched if need be, and the whole chain of any behaviour (:class:`Planner`), each segment
from the previous one's final state (eq. 29), checked at the end
(:func:`~flipkit.planning.plans.verify.verify_plan`).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from flipkit.behaviors import library
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.spec import Behavior, Task
from flipkit.behaviors.transcribe import transcribe
from flipkit.config import CellConfig
from flipkit.errors import (AtlasError, ConfigError, FlipkitError, InvalidChoiceError,
                            SolverError)
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.segment import Segment
from flipkit.planning.plans.verify import verify_plan
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.solvers.names import SOLVERS
from flipkit.solvers.result import SolveResult, Status


# The IPOPT fallback of ``auto``: the budget is above the slowest fallback that succeeds on
# the planner's segments (docs/history.md), and bounds a hopeless one. An explicit ``ipopt``
# keeps IPOPT's own defaults. Goals that no branch reaches are refused before any NLP
# (flipkit.model.goal_check), so the fallback does not spend its budget on them.
FALLBACK_IPOPT = {"max_wall_time": 60.0, "max_iter": 1000}


def solve_segment(nlp, solver: str = "sqp", x0=None, *, caches: PlannerCaches | None = None,
                  **sqp_kwargs) -> SolveResult:
    """Solve one segment NLP with ``solver`` from ``x0`` (default ``nlp.x0``, unscaled).

    ``auto`` runs the SQP and, when it fails, IPOPT from the same start within
    :data:`FALLBACK_IPOPT`'s budget (60 s, 1000 iterations); the segment's ``solver.name`` in
    the plan file records which one produced it and the wall time counts both.

    ``sqp_kwargs`` go to :func:`~flipkit.solvers.sqp.solve_sqp` (e.g. ``options``,
    ``workspace``); without a ``workspace`` among them the SQP solves in ``caches``'s
    (:meth:`~flipkit.planning.planners.caches.PlannerCaches.workspace`), or, without
    ``caches`` either, in a workspace of its own, compiled for this solve alone.

    Returns the result whatever its status (``result.success`` tells); the worst constraint
    group of a failure is ``nlp.worst_group(result.x)``.

    Raises:
        InvalidChoiceError: ``solver`` is not one of :data:`SOLVERS`.
    """
    # The solvers load cvxpy and CasADi, slow to import: imported on the first solve, so that
    # input checks (flipkit.model.goal_check, planning.inputs) refuse bad goals without them.
    from flipkit.solvers import compiled, ipopt, sqp

    if solver == "sqp":
        if sqp_kwargs.get("workspace") is None and caches is not None:
            sqp_kwargs["workspace"] = caches.workspace(compiled.SQPWorkspace)
        try:
            return sqp.solve_sqp(nlp, x0, raise_on_failure=False, **sqp_kwargs)
        except SolverError:  # OSQP or a factorisation broke down inside a subproblem
            x = np.clip(np.asarray(nlp.x0 if x0 is None else x0, float), nlp.x_lb, nlp.x_ub)
            return SolveResult(x=x, status=Status.QP_SOLVER_ERROR, iterations=0, wall_time_s=0.0,
                               objective=nlp.objective(x), max_violation=float(
                                   nlp.scaled_violation(nlp.constraints(x)).max(initial=0.0)))
    if solver == "ipopt":
        return ipopt.solve_ipopt(nlp, x0, raise_on_failure=False)
    if solver == "auto":  # the SQP, and IPOPT from the same start if the SQP fails
        first = solve_segment(nlp, "sqp", x0, caches=caches, **sqp_kwargs)
        if first.success:
            return first
        second = ipopt.solve_ipopt(nlp, x0, ipopt.IpoptOptions(**FALLBACK_IPOPT),
                                   raise_on_failure=False)
        second.wall_time_s += first.wall_time_s
        return second
    raise InvalidChoiceError("solver", solver, SOLVERS)


def finish_plan(plan: Plan, failure: str | None, t0: float, cell: CellConfig | None = None,
                meshes=None) -> Plan:
    """Verify ``plan`` in ``cell``, the cell it was planned in (default the defaults), with
    the arm's link meshes ``meshes`` if given (:func:`~flipkit.planning.plans.verify.verify_plan`);
    set status, ``failure``, ``report`` and ``wall_time_s``."""
    plan.report = verify_plan(plan, cell=cell, meshes=meshes)
    if failure is None and not plan.report.ok:
        group, k, amount = plan.report.worst()
        failure = f"{plan.segments[k].name}: {group} violated by {amount:.3g} (verify)"
    plan.status, plan.failure = ("failed", failure) if failure else ("solved", None)
    plan.wall_time_s = time.perf_counter() - t0
    return plan


def solver_failure(name: str, nlp, result) -> str:
    """One line: the segment, its worst constraint group and amount, the solver's status
    (and the fallback's budget where IPOPT ran out of it)."""
    group, amount = nlp.worst_group(result.x)
    budget = (f" after the fallback's budget of {FALLBACK_IPOPT['max_wall_time']:g} s or "
              f"{FALLBACK_IPOPT['max_iter']} iterations" if result.status in (
                  Status.MAXIMUM_WALLTIME_EXCEEDED, Status.MAXIMUM_ITERATIONS_EXCEEDED) else "")
    return f"{name}: {group} violated by {amount:.3g} ({result.solver}: {result.status}{budget})"


def solve_stretched(build, options: SegmentOptions, solver: str, guess=None, *,
                    stretch_first=lambda nlp: False, **sqp_kwargs):
    """Build and solve a segment (``build(options) -> NLP``); if it has no solution within its
    duration bound, build and solve it once more with the bound stretched (SegmentOptions
    ``stretch``, :data:`~flipkit.behaviors.options.T_STRETCH`). Returns (nlp, result): the
    stretched one if it succeeded, else the first.

    ``guess(nlp) -> x0`` (optional) seeds a first SQP solve (a warm start, e.g. from an
    atlas); if it fails, the segment is solved as without it, from its own initial guess with
    ``solver``, before the bound is stretched, and the result's wall time counts both — unless
    the warm SQP found the segment locally infeasible within its bound (status ``infeasible``):
    then the stretched bound is tried first, and the cold solve within the bound only if that
    fails too: proving a segment infeasible warm, cold and in IPOPT costs far more than the
    stretched solve. With ``solver="ipopt"`` the guess is not used: an interior-point method
    started on another solution's active bounds is slow.

    ``stretch_first(nlp) -> bool`` (with a ``guess``): whether the guess comes from a solution
    with the bound stretched; then the stretched segment is solved warm first, and only if
    that fails is the segment solved as above. The result's wall time counts every solve.

    Raises:
        FlipkitError: The first build fails (e.g. its initial guess), or ``guess`` raises.
    """
    nlp, first = build(options), None
    if guess is not None and solver != "ipopt" and not options.stretch and stretch_first(nlp):
        try:
            longer = build(replace(options, stretch=True))
        except FlipkitError:
            longer = None
        if longer is not None:
            first = solve_segment(longer, "sqp", guess(longer), **sqp_kwargs)
            if first.success:
                return longer, first
    nlp, result = _within_then_stretched(nlp, build, options, solver, guess, **sqp_kwargs)
    return nlp, result if first is None else _counting(result, first)


def _within_then_stretched(nlp, build, options, solver, guess, **sqp_kwargs):
    """:func:`solve_stretched` without ``stretch_first``, ``nlp`` built within the bound."""
    x0 = None if guess is None or solver == "ipopt" else guess(nlp)
    deferred = False  # the cold solve within the bound, put off until the stretch fails
    if x0 is None:
        result = solve_segment(nlp, solver, **sqp_kwargs)
    else:  # the SQP from the warm start; failing that, the usual cold solve (auto: + IPOPT)
        result = solve_segment(nlp, "sqp", x0, **sqp_kwargs)
        deferred = result.status == Status.INFEASIBLE and not options.stretch
        if not result.success and not deferred:
            result = _counting(solve_segment(nlp, solver, **sqp_kwargs), result)
    if result.success or options.stretch:
        return nlp, result
    try:
        longer = build(replace(options, stretch=True))
    except FlipkitError:
        longer = None
    if longer is not None:
        second = solve_segment(longer, solver, **sqp_kwargs)
        if second.success:
            second.wall_time_s += result.wall_time_s
            return longer, second
    if deferred:
        result = _counting(solve_segment(nlp, solver, **sqp_kwargs), result)
    return nlp, result


def _counting(result: SolveResult, before: SolveResult) -> SolveResult:
    """``result`` with the wall time of the failed attempt ``before`` added."""
    result.wall_time_s += before.wall_time_s
    return result


class Planner:
    """Chains the segments of any behaviour and checks the plan.

    Each segment is solved from the previous one's final state (eq. 29), with its duration
    bound stretched once where it is infeasible within it (for behaviours that allow it),
    and the chain is verified at the end (:func:`finish_plan`).

    Args:
        cell: The cell (default :class:`~flipkit.config.CellConfig`).
        solver: One of :data:`SOLVERS`.
        options: Transcription options.
        caches: What this planner reuses and adds to
            (:class:`~flipkit.planning.planners.caches.PlannerCaches`): its cell's models,
            the blocks' patterns, the SQP's workspace and the meshes its plans are verified
            with, each passed down to where it is used; default: new ones, for this planner
            alone. Planners made one after another with the same ones (every ``plan_flip``
            of a cook) build each model and compile each subproblem structure once.

    Raises:
        InvalidChoiceError: Unknown solver.
    """

    def __init__(self, cell: CellConfig | None = None, *, solver: str = "auto",
                 options: SegmentOptions = SegmentOptions(),
                 caches: PlannerCaches | None = None):
        if not isinstance(solver, str) or solver not in SOLVERS:
            raise InvalidChoiceError("solver", solver, SOLVERS)
        if cell is not None and not isinstance(cell, CellConfig):
            raise ConfigError(f"cell: expected a CellConfig, got {type(cell).__name__}")
        if not isinstance(options, SegmentOptions):
            raise ConfigError(f"options: expected SegmentOptions, got {type(options).__name__}")
        self.cell = cell or CellConfig()
        self.solver, self.options = solver, options
        self.caches = PlannerCaches() if caches is None else caches
        self.models = self.caches.models(self.cell)

    def chain(self, behavior: Behavior | str, task: Task, q, qd, *, done=(), guess=None,
              t0: float | None = None) -> Plan:
        """Solve the behaviour's segments after those ``done`` (already solved), from (q, q̇).

        Args:
            behavior: A :class:`~flipkit.behaviors.spec.Behavior` or its name.
            task: What it is for; a segment's spec may refine it for the segments after it
                (``after_solve``: the scoop predicts where the burger lies on the blade).
            q, qd: Start state of the first segment to solve (rad, rad/s).
            done: Segments kept from an earlier plan, in order.
            guess: Optional ``guess(name, nlp, q, qd) -> x0`` warm-starting each segment's
                solve (:func:`solve_stretched`).
            t0: ``time.perf_counter()`` when planning began (the plan's wall time counts
                from it); default now.

        Returns:
            The verified plan; on a segment failure the chain stops there and
            ``plan.failure`` names the segment, its worst constraint group and the violation.

        Raises:
            FlipkitError: The first segment to solve cannot be built (e.g. its initial
                guess), with nothing solved before it. AtlasError: ``guess`` refuses (a
                stale atlas).
        """
        t0 = time.perf_counter() if t0 is None else t0
        behavior = library.behavior(behavior) if isinstance(behavior, str) else behavior
        segments, failure = list(done), None
        for spec in behavior.steps[len(segments):]:
            try:
                nlp, result = self._solve(spec, task, q, qd, behavior.stretch, guess)
            except AtlasError:
                raise
            except FlipkitError as exc:
                if not segments:
                    raise
                failure = f"{spec.name}: cannot build the initial guess ({exc})"
                break
            seg = Segment.from_solution(nlp, result)
            if spec.record is not None:
                spec.record(seg, task, self.models)
            segments.append(seg)
            if not result.success:
                failure = solver_failure(spec.name, nlp, result)
                break
            if spec.after_solve is not None:
                task = spec.after_solve(seg, task, self.models, self.options)
            q, qd = seg.q[-1], seg.qd[-1]
        plan = Plan.from_segments(behavior.name, self.cell, segments, location=task.location,
                                  heading=task.heading, cone=self.options.cone, status="failed")
        return finish_plan(plan, failure, t0, self.cell, self.caches.meshes)

    def _solve(self, spec, task: Task, q, qd, stretch: bool, guess):
        def build(options):
            return transcribe(spec, self.models, q, qd, options=options, task=task,
                              patterns=self.caches.patterns)

        if not stretch:
            nlp = build(self.options)
            return nlp, solve_segment(nlp, self.solver, caches=self.caches)
        seed = None if guess is None else (lambda nlp: guess(spec.name, nlp, q, qd))
        stretched = getattr(guess, "stretched", None)  # atlas seeds know (Seeding.stretched)
        first = (lambda nlp: False) if stretched is None else \
            (lambda nlp: stretched(spec.name, nlp))
        return solve_stretched(build, self.options, self.solver, seed, stretch_first=first,
                               caches=self.caches)


__all__ = ["SOLVERS", "Planner", "finish_plan", "solve_segment", "solve_stretched",
           "solver_failure"]
