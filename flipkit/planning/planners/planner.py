"""Planning front end: translate, pickup-and-flip and batches of burgers, checked plans.

Each entry point chains a behaviour's segments with a :class:`~flipkit.planning.planners.chain.Planner`
(specs of :mod:`flipkit.behaviors.library`, solved with the SQP or IPOPT), wraps them in a
:class:`~flipkit.planning.plans.plan_file.Plan` and runs the independent check
:func:`~flipkit.planning.plans.verify.verify_plan`. A plan's ``status`` is
``"solved"`` only if every segment's solver converged *and* the check passes; otherwise it
is ``"failed"`` and the attribute ``plan.failure`` (not written to the file) holds a one-line
reason, e.g. ``"pickup: cone violated by 3.2e-04 (sqp: stalled)"``. Every plan returned also
carries ``plan.report`` (the verification report) and ``plan.wall_time_s`` (s, the whole
call: IK, building, solving, checking).

Bad input (non-finite or out-of-area positions, poses out of reach, joint vectors of the
wrong size or outside the limits) raises a one-line :class:`~flipkit.errors.FlipkitError`
before anything is solved.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import sys
import time
from dataclasses import replace

import numpy as np
from scipy.spatial import Delaunay, QhullError
from tqdm import tqdm

from flipkit.behaviors import targets as tg
from flipkit.behaviors.library import PICKUP_AND_FLIP
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.spec import Task
from flipkit.behaviors.transcribe import flat_pose
from flipkit.config import CellConfig, SensingUncertainty
from flipkit.config.checks import real_number
from flipkit.errors import ConfigError, FlipkitError, UnreachableError
from flipkit.model.goal_check import check_goal
from flipkit.model.ik import solve_pose
from flipkit.planning.planners.atlas import check_atlas, seeding
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.chain import Planner
from flipkit.planning.planners.inputs import (MAX_BATCH, check_approach_height, resolve_heading,
                                              check_joint_vector, check_on_blade,
                                              check_position, check_replan, check_start)
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify_flight import LANDING_TOL, TILT_MIN_DEG, recompute_landing

REST_TOL = 1e-6  # rad: a motion ending this close to the rest configuration ends at it


def plan_translate(start, goal, *, cell: CellConfig | None = None, solver: str = "auto",
                   q_start=None, yaw: float = 0.0,
                   options: SegmentOptions = SegmentOptions(),
                   caches: PlannerCaches | None = None) -> Plan:
    """Carry the burger on a flat spatula from ``start`` to ``goal`` (paper eq. 9), at rest
    at both ends.

    Args:
        start: Blade-centre start position (m); the start configuration is the IK solution
            near q_home for a flat spatula with heading ``yaw``. May be ``None`` if
            ``q_start`` is given.
        goal: Blade-centre goal position (m); the spatula ends flat with heading ``yaw``.
        cell: The cell (default :class:`~flipkit.config.CellConfig`).
        solver: ``"auto"`` (default: the SQP, then IPOPT from the same start where the SQP
            fails), ``"sqp"`` or ``"ipopt"``.
        q_start: Start configuration (rad) instead of the IK one; must lie within the joint
            limits and, if ``start`` is given too, put the blade within 1 mm of it.
        yaw: Heading o_z of the spatula (rad).
        options: Transcription options.
        caches: What the planner reuses and adds to
            (:class:`~flipkit.planning.planners.caches.PlannerCaches`): pass the same one to
            every plan of a loop; default: new ones, for this plan alone.

    Raises:
        ConfigError: Malformed input. UnreachableError: A position outside the task area or
            out of reach. InvalidChoiceError: Unknown solver.
    """
    t0 = time.perf_counter()
    planner = Planner(cell, solver=solver, options=options, caches=caches)
    cell, robot = planner.cell, planner.models.loaded
    p_goal = check_position("translate goal", goal, cell)
    yaw = real_number("yaw", yaw, "rad")
    if q_start is None:
        if start is None:
            raise ConfigError("translate needs a start position or a start configuration")
        p_start = check_position("translate start", start, cell)
        try:
            q0 = solve_pose(robot, p_start, (0.0, 0.0, yaw), robot.q_home)
        except UnreachableError as exc:
            raise UnreachableError(f"translate start: {exc}") from None
    else:
        q0 = check_joint_vector("start configuration", q_start, robot.q_min, robot.q_max, "rad")
        if start is not None:
            gap = np.linalg.norm(robot.position(q0) - check_position("translate start", start, cell))
            if gap > 1e-3:
                raise ConfigError(f"start configuration puts the blade {gap * 1e3:.1f} mm from "
                                  "the start position; give one of them")
    o = planner.options
    try:  # every IK branch against the NLP's joint bounds and the cell, cheaper than any NLP
        check_goal(robot, planner.models.shapes, cell, p_goal, (0.0, 0.0, yaw), q_start=q0,
                   singularity_margin=o.singularity_margin, clearance=o.arm_clearance)
    except UnreachableError as exc:
        raise UnreachableError(f"translate {exc}") from None  # "translate goal (...): ..."
    try:
        return planner.chain("translate", Task(goal=flat_pose(p_goal, yaw)), q0,
                             np.zeros(robot.nq), t0=t0)
    except UnreachableError as exc:  # the initial guess's IK can still fail
        raise UnreachableError(f"translate goal: {exc}") from None


def plan_flip(location, q_start=None, qd_start=None, *, cell: CellConfig | None = None,
              solver: str = "auto", land=None, on_blade=None,
              options: SegmentOptions = SegmentOptions(), atlas=None,
              approach_height=None, heading=None,
              caches: PlannerCaches | None = None) -> Plan:
    """Pick up and flip the burger at ``location``: the five subbehaviours of
    :data:`~flipkit.behaviors.library.FLIP_NAMES` chained by (29) — each segment starts at the
    previous segment's final (q, q̇).

    Args:
        location: Burger location p^b (m), on the grill (:func:`~flipkit.behaviors.targets.check_location`).
        q_start: Start configuration (rad), default q_home.
        qd_start: Start joint velocities (rad/s), default rest.
        land: Landing spot (x, y) (m) on the grill; default where the burger was picked up.
            The flipped burger's centre must land within ``options.r_land`` of it.
        on_blade: Where the burger's centre will sit on the blade (x, y) (blade frame, m)
            when it is released; default ``None``: where the scoop model
            (:func:`~flipkit.behaviors.pick.scoop_scenarios`) says the planned scoop leaves it, and with
            ``options.robust`` every scenario of its spread lands too.
        cell, solver, options, caches: As :func:`plan_translate`.
        atlas: A warm-start :class:`~flipkit.planning.planners.atlas.Atlas` built for ``cell`` and
            ``options``: each segment starts from the atlas's interpolated solution (and
            from its own initial guess if that fails); ``None`` (default): cold starts.
        approach_height: Height (m) above the grill that the go to burger keeps the blade's
            edges until its descent (over other burgers lying on the grill,
            :mod:`flipkit.behaviors.approach`); ``None`` (default): the approach's own floor.
        heading: The scoop heading ψ (rad, :mod:`flipkit.model.task_frame`): the go to
            burger, scoop, pickup and flip run along (cos ψ, sin ψ); ``None`` (default):
            radially outward from the arm's base (:func:`~flipkit.behaviors.targets.default_heading`).
            The atlas holds plans at the default headings; at another heading they still seed
            the solver (the plan is verified as every plan is).

    Returns:
        The plan. On a segment failure the chain stops there: the plan holds the segments
        up to and including the failed one, and ``plan.failure`` names it, the worst
        constraint group and its violation.

    Raises:
        UnreachableError: Location off the grill, or the first segment out of reach.
        ConfigError: Malformed start state. InvalidChoiceError: Unknown solver.
        AtlasError: ``atlas`` was built for other options, another cell or other NLPs.
    """
    t0 = time.perf_counter()
    planner = Planner(cell, solver=solver, options=options, caches=caches)
    cell = planner.cell
    check_atlas(atlas, cell, options)
    pb = tg.check_location(cell, location)
    spot = None if land is None else tg.check_spot(cell, land)
    on_blade = None if on_blade is None else check_on_blade(on_blade, cell)
    psi = resolve_heading(cell, pb, heading)
    q, qd = check_start(planner.models.bare, q_start, qd_start)
    task = Task(location=pb, land=spot, on_blade=on_blade,
                approach_height=check_approach_height(approach_height), heading=psi)
    return planner.chain("flip", task, q, qd,
                         guess=seeding(atlas, pb, psi), t0=t0)


def covers(landing: dict, on_blade) -> bool:
    """Whether ``on_blade`` (x, y) (m) lies in the convex hull of a robust flip's landing
    scenarios (``landing["scenarios"]``); ``False`` without scenarios or with a degenerate
    hull."""
    points = np.array([row["burger_on_blade"] for row in landing.get("scenarios", ())], float)
    if len(points) < 3:
        return False
    try:
        hull = Delaunay(points)
    except QhullError:  # collinear scenarios: no area to be inside of
        return False
    return bool(hull.find_simplex(np.asarray(on_blade, float)[:2]) >= 0)


def landing_miss(flip, on_blade, models) -> float:
    """How far (m) the solved ``flip`` segment lands a burger lying at ``on_blade`` (x, y)
    (m, blade frame) from its target: its own release state and a ballistic flight
    (:func:`~flipkit.planning.plans.verify_flight.recompute_landing`); ``inf`` when the
    burger would not land upside down (within the verification's tolerance) or has no
    release."""
    pred = recompute_landing(models.loaded, flip, models.cell, on_blade)
    if pred is None or pred["tilt_deg"] < TILT_MIN_DEG - LANDING_TOL["deg"]:
        return math.inf
    return float(np.hypot(*(pred["point"][:2] - np.asarray(flip.landing["target"], float))))


def promise(plan: Plan) -> float:
    """The radius (m) within which a solved flip plan promises to land a burger lying at any
    of its scenarios' places: the scenarios' ``r_land`` (``r_scenario``), or the nominal
    ``r_land`` of a plan without scenarios."""
    landing = plan.step("release").landing
    return max((row["r_land"] for row in landing.get("scenarios", ())),
               default=landing["r_land"])


def keeps_promise(plan: Plan, on_blade, models) -> bool:
    """Whether a solved flip plan, as it is, lands a burger measured at ``on_blade`` (x, y)
    (m) within :func:`promise`: the place lies in its scenarios' hull (:func:`covers`), or
    its own release and flight land it so (:func:`landing_miss`)."""
    flip = plan.step("release")
    return (covers(flip.landing, on_blade)
            or landing_miss(flip, on_blade, models) <= promise(plan))


def sensed_scenarios(cell: CellConfig, on_blade,
                     sensing: SensingUncertainty = SensingUncertainty()) -> tuple:
    """The places a burger measured at ``on_blade`` (x, y) (m, blade frame) may lie at:
    ``sensing.reach`` from it along the blade and across it, clipped to the blade."""
    x, y = (float(v) for v in on_blade)
    d = sensing.reach
    half = cell.spatula.half_extent
    return tuple(np.clip(p, -half, half) for p in ((x - d, y), (x + d, y), (x, y - d), (x, y + d)))


def replan_flip(plan: Plan, on_blade, *, solver: str = "auto",
                options: SegmentOptions = SegmentOptions(), keep: bool = True,
                sensing: SensingUncertainty = SensingUncertainty(),
                caches: PlannerCaches | None = None) -> Plan:
    """Re-plan pickup, flip and turn back of a solved flip plan for a burger measured at
    ``on_blade`` on the blade after the scoop (sense, plan, act).

    The scoop ends at rest with the blade flat on the grill and the burger on it, so the cell
    can measure where the burger lies on the blade (a scoop drags it forward by centimetres)
    and wait there while this runs. Go to burger, scoop and pickup are kept (the
    pickup's constraints do not depend on where the burger lies); the flip is solved again
    with the release state of a burger at ``on_blade``, to the plan's landing target, then the
    turn back from its end, each SQP started from the plan's own solution of that segment (the
    burger moved by centimetres on the blade: the old flip is close to the new one); the result
    is checked like any plan. The measurement errs, so a robust plan's new flip is robust too
    (unless ``options.robust`` is off): it also lands the places ``sensing.reach`` (1 cm) from
    the measured one within ``r_scenario`` (:func:`sensed_scenarios`).

    A robust plan promises a landing within ``r_scenario`` of the spot for every scenario of
    the burger's place. The plan is returned as it is, with no solve, when the measured place
    keeps that promise: it lies in the convex hull of the scenarios (the landing is close to
    affine in that place over centimetres, :func:`covers`), or the plan's own release and
    flight land it within ``r_scenario`` (:func:`landing_miss`). A plan without scenarios is
    kept only when the measured place lands within its ``r_land``.

    Args:
        plan: A solved flip plan. on_blade: (x, y) of the burger's centre in the blade frame
            (m). solver, options, caches: As :func:`plan_flip` (``r_land`` from the plan's
            landing).
        keep: Return ``plan`` itself where it already lands the measured place (default);
            ``False`` always solves.
        sensing: The camera's error that the re-plan's scenarios span.

    Raises:
        ConfigError: ``plan`` is not a solved flip plan, or ``on_blade`` is off the blade.
    """
    t0 = time.perf_counter()
    cell, on_blade = check_replan(plan, "flip", on_blade)
    flip = plan.step("release")
    planner = Planner(cell, solver=solver,
                      options=replace(options, r_land=flip.landing["r_land"], cone=plan.cone),
                      caches=caches)
    if keep and keeps_promise(plan, on_blade, planner.models):
        return plan
    done = [s for s in plan.segments if s.name in PICKUP_AND_FLIP.kept()]
    before = {s.name: s for s in plan.segments}
    robust = options.robust and bool(flip.landing.get("scenarios"))

    def own(name, nlp, q, qd):  # the plan's own segment as the warm start
        s = before[name]
        return nlp.layout.pack(s.q, s.qd, s.qdd, s.u, s.alpha, s.T)

    task = Task(location=np.asarray(plan.burger["location"], float),
                heading=plan.burger["heading"],
                land=np.asarray(flip.landing["target"]), on_blade=on_blade,
                scenarios=sensed_scenarios(cell, on_blade, sensing) if robust else ())
    return planner.chain("flip", task, done[-1].q[-1], done[-1].qd[-1], done=done, guess=own,
                         t0=t0)


def plan_batch(locations, q_start=None, *, cell: CellConfig | None = None, solver: str = "auto",
               progress: bool = True, options: SegmentOptions = SegmentOptions(),
               executor=None, atlas=None, caches: PlannerCaches | None = None) -> list[Plan]:
    """Pickup-and-flip plans for up to :data:`MAX_BATCH` burgers, one after the other.

    Burger k starts where the last *solved* plan ended (a solved flip ends at q_home at
    rest, and an end within :data:`~flipkit.planning.kitchen.motions.REST_TOL` of it is taken as
    q_home itself); a failed plan is not executed, so it does not move the start of the next
    one. Since every solved plan ends at q_home, the burgers after the first are independent:
    with an ``executor`` (worker processes or Dask) they are planned at once, from q_home, and
    a burger whose start that assumption got wrong (every plan before it failed, and the
    batch started elsewhere) is planned again, here, from the right start. The burgers are
    dealt to one task per worker (:func:`plan_flips`; the executor's ``workers``, else one
    task per burger), so that each worker compiles the subproblems once.

    Args:
        locations: Burger locations p^b (m), in order.
        q_start: Start configuration of the first burger (rad), default q_home.
        progress: Show a tqdm progress bar (stderr).
        cell, solver, options, atlas: As :func:`plan_flip` (``atlas`` warm-starts every
            burger's chain; default cold starts).
        executor: Optional :class:`concurrent.futures.Executor` to plan in parallel.
        caches: As :func:`plan_flip`, for the burgers planned in this process.

    Raises:
        ConfigError: No location, more than :data:`MAX_BATCH`, or a malformed start.
        UnreachableError: A location off the grill (named by its index, from 1).
    """
    planner = Planner(cell, solver=solver, options=options, caches=caches)  # checks the solver
    cell, home = planner.cell, planner.models.bare.q_home
    locs = list(locations)
    if not 1 <= len(locs) <= MAX_BATCH:
        raise ConfigError(f"a batch takes 1 to {MAX_BATCH} burger locations, got {len(locs)}")
    checked = []
    for k, loc in enumerate(locs, 1):
        try:
            checked.append(tg.check_location(cell, loc))
        except UnreachableError as exc:
            raise UnreachableError(f"burger {k}: {exc}") from None
    check_atlas(atlas, cell, options)
    kw = {"cell": cell, "solver": solver, "options": options, "atlas": atlas}
    ahead = None if executor is None else _deal(executor, [
        (pb, q_start if k == 0 else home) for k, pb in enumerate(checked)], kw)
    kw = {**kw, "caches": planner.caches}  # the burgers planned here (the workers' kw stays)
    q, qd, plans = q_start, None, []
    bar = tqdm(checked, desc="burgers", unit="burger", disable=not progress)
    for k, pb in enumerate(bar, 1):
        try:
            start_ok = ahead is not None and (k == 1 or any(p.status == "solved" for p in plans)
                                              or q_start is None)
            plan = _ahead_or_here(ahead[k - 1], k, pb, q, qd, kw) if start_ok else \
                plan_flip(pb, q, qd, **kw)
        except FlipkitError as exc:
            raise type(exc)(f"burger {k}: {exc}") from None
        plans.append(plan)
        bar.set_postfix_str(f"burger {k}: {plan.status}")
        if plan.status == "solved":
            q, qd = plan.segments[-1].q[-1], plan.segments[-1].qd[-1]
            if max(np.abs(q - home).max(), np.abs(qd).max()) <= REST_TOL:
                q, qd = home, None  # at rest at q_home, to the solver's tolerance
    return plans


def plan_flips(jobs, kw: dict) -> list:
    """:func:`plan_flip` of each ``(location, q_start)`` of ``jobs`` with the keywords ``kw``,
    all with one :class:`~flipkit.planning.planners.caches.PlannerCaches` (a worker's task of
    :func:`plan_batch`). A job that raises :class:`~flipkit.errors.FlipkitError` gets the
    error in its place, so that the others' plans are kept."""
    caches, out = PlannerCaches(), []
    for location, q_start in jobs:
        try:
            out.append(plan_flip(location, q_start, None, caches=caches, **kw))
        except FlipkitError as exc:
            out.append(exc)
    return out


def _deal(executor, jobs: list, kw: dict) -> list[tuple]:
    """Burger k's ``(future, place)``: the ``jobs`` dealt in turn to one :func:`plan_flips`
    task per worker of ``executor`` (its ``workers``; else one task per job)."""
    tasks = max(1, min(len(jobs), getattr(executor, "workers", None) or len(jobs)))
    futures = [executor.submit(plan_flips, jobs[j::tasks], kw) for j in range(tasks)]
    return [(futures[k % tasks], k // tasks) for k in range(len(jobs))]


def _ahead_or_here(ahead: tuple, k: int, pb, q, qd, kw: dict) -> Plan:
    """Burger ``k``'s plan made ahead by a worker (``ahead``: its task's future and its place
    there), or, if that worker died (its pool broke: the OOM killer, a crash in native code,
    a signal), made here from the same start, with one line on stderr.

    Raises:
        FlipkitError: The worker's planning of burger ``k`` raised it.
    """
    future, place = ahead
    try:
        plan = future.result()[place]
    except cf.BrokenExecutor as exc:
        tqdm.write(f"flipkit: the worker planning burger {k} died ({type(exc).__name__}); "
                   "planning it in this process", file=sys.stderr)
        return plan_flip(pb, q, qd, **kw)
    if isinstance(plan, FlipkitError):
        raise plan
    return plan


SUMMARY_HEADER = ("burger", "location_m", "status", "solve_time_s", "iterations",
                  "max_violation")


def summary_table(plans) -> list[tuple]:
    """One row per plan (:data:`SUMMARY_HEADER`): burger index (from 1), location (m),
    status, solve time (s, sum over segments), iterations (sum) and the largest max scaled
    violation reported by the solvers."""
    rows = []
    for k, plan in enumerate(plans, 1):
        loc = plan.burger["location"]
        rows.append((k, None if loc is None else tuple(float(v) for v in loc), plan.status,
                     sum(s.solver.wall_time_s for s in plan.segments),
                     sum(s.solver.iterations for s in plan.segments),
                     max(s.solver.max_violation for s in plan.segments)))
    return rows


def format_summary(rows) -> str:
    """:func:`summary_table` rows as an aligned text table."""
    lines = [f"{'burger':>6}  {'location (m)':<24}{'status':<8}{'solve s':>9}{'iters':>7}"
             f"{'max viol':>10}"]
    for k, loc, status, t, its, viol in rows:
        where = "-" if loc is None else "(" + ", ".join(f"{v:.3f}" for v in loc) + ")"
        lines.append(f"{k:>6}  {where:<24}{status:<8}{t:>9.2f}{its:>7d}{viol:>10.1e}")
    return "\n".join(lines)


__all__ = ["MAX_BATCH", "REST_TOL", "SUMMARY_HEADER", "covers", "format_summary", "keeps_promise",
           "landing_miss", "plan_batch", "plan_flip", "plan_flips", "plan_translate", "promise",
           "replan_flip",
           "sensed_scenarios", "summary_table"]
