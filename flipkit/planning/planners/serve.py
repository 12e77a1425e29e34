"""Planning the serve behaviour: pick a burger up from the grill and tilt it off onto the side
table (:mod:`flipkit.behaviors.serve`), then return home.

:func:`plan_serve` chains go to burger, scoop, pickup, carry, place and return home by (29) —
each segment starts at the previous one's final (q, q̇) — and checks the plan independently
(:func:`~flipkit.planning.plans.verify.verify_plan`) like every planner entry point
(:mod:`flipkit.planning.planners.planner`): status ``solved`` only if every segment converged and the
check passes.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from flipkit.behaviors import serve as sv
from flipkit.behaviors import targets as tg
from flipkit.behaviors.library import SERVE
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.spec import Task
from flipkit.config import CellConfig
from flipkit.errors import FlipkitError, UnreachableError
from flipkit.model.ik import solve_pose
from flipkit.planning.planners.atlas import check_atlas, seeding
from flipkit.planning.planners.caches import PlannerCaches
from flipkit.planning.planners.chain import Planner
from flipkit.planning.planners.inputs import (check_approach_height, check_on_blade,
                                              check_replan, check_start, resolve_heading)
from flipkit.planning.plans.plan_file import Plan


def plan_serve(burger, table_spot, q_start=None, qd_start=None, *, cell: CellConfig | None = None,
               solver: str = "auto", on_blade=None,
               options: SegmentOptions = SegmentOptions(), atlas=None,
               approach_height=None, heading=None, caches: PlannerCaches | None = None) -> Plan:
    """Serve the burger at ``burger`` to ``table_spot``: go to burger, scoop, pickup (eqs.
    22–25), carry with the friction cone throughout, place by a tilt-off, return home.

    Args:
        burger: Burger location p^b (m) on the grill (:func:`~flipkit.behaviors.targets.check_location`).
        table_spot: Where the burger's centre should come to rest on the table (x, y) (m);
            the whole burger must lie on the table (:func:`~flipkit.behaviors.targets.check_table_spot`).
        q_start: Start configuration (rad), default q_home — e.g. where the previous motion
            of a schedule ended. qd_start: Start joint velocities (rad/s), default rest.
        cell: The cell (default :class:`~flipkit.config.CellConfig`).
        solver: ``"auto"`` (default: the SQP, then IPOPT where it fails), ``"sqp"`` or
            ``"ipopt"``.
        on_blade: Where the burger's centre will sit on the blade (x, y) (m, blade frame)
            during the carry and place, if known (:func:`replan_serve` re-plans for a
            sensed one). ``None`` (default): where the scoop model
            (:func:`~flipkit.behaviors.pick.scoop_scenarios`) says the planned scoop leaves
            it, as the flip does.
        options: Transcription options (``N``, ``cone``, ``mu_safety``, ``epsilon``).
        atlas: A pickup-and-flip :class:`~flipkit.planning.planners.atlas.Atlas` built for ``cell``
            and ``options``: go to burger, scoop and pickup (the flip's first three
            segments, the same NLPs) start from its interpolated solutions, carry, place
            and return home from their own guesses; ``None`` (default): cold starts.
        heading: The scoop heading (rad), as :func:`~flipkit.planning.planners.planner.plan_flip`.
        approach_height, caches: As :func:`~flipkit.planning.planners.planner.plan_flip`.

    Returns:
        The :class:`~flipkit.planning.plans.plan_file.Plan`, behaviour ``serve``: status
        ``solved`` (verified) or ``failed`` with ``plan.failure`` one line; on a segment
        failure the chain stops there. ``plan.report`` and ``plan.wall_time_s`` (s) as
        :func:`~flipkit.planning.planners.planner.plan_flip`. It ends at q_home, at rest.

    Raises:
        UnreachableError: Burger off the grill, spot off the table, or the place pose out of
            reach. ConfigError: Malformed start state. InvalidChoiceError: Unknown solver.
        AtlasError: ``atlas`` was built for other options, another cell or other NLPs.
    """
    t0 = time.perf_counter()
    planner = Planner(cell, solver=solver, options=options, caches=caches)
    cell, models = planner.cell, planner.models
    check_atlas(atlas, cell, options)
    pb = tg.check_location(cell, burger)
    spot = tg.check_table_spot(cell, table_spot)
    on_blade = None if on_blade is None else check_on_blade(on_blade, cell)
    q, qd = check_start(models.bare, q_start, qd_start)
    at = (0.0, 0.0) if on_blade is None else on_blade  # the reach check before the scoop
    for what, pose in (("carry end", sv.carry_end(cell, spot, at)),
                       ("place pose", sv.place_end(cell, spot, at))):
        try:  # reachability first, one clear line
            solve_pose(models.loaded, pose.p, pose.o, models.bare.q_home)
        except UnreachableError as exc:
            raise UnreachableError(f"table spot ({spot[0]:.3f}, {spot[1]:.3f}): {what}: "
                                   f"{exc}") from None
    psi = resolve_heading(cell, pb, heading)
    task = Task(location=pb, spot=spot, on_blade=on_blade,
                approach_height=check_approach_height(approach_height), heading=psi)
    return planner.chain("serve", task, q, qd,
                         guess=seeding(atlas, pb, psi), t0=t0)


def replan_serve(plan: Plan, on_blade, *, solver: str = "auto",
                 options: SegmentOptions = SegmentOptions(),
                 caches: PlannerCaches | None = None) -> Plan:
    """Re-plan place and return home of a solved serve plan for a burger measured at
    ``on_blade`` on the blade during the carry (sense, plan, act; as
    :func:`~flipkit.planning.planners.planner.replan_flip`): the re-plan starts where the
    planned carry ends, at rest with the blade flat above the table, so it can run while the
    carry finishes (a cook's serves, :mod:`flipkit.simulation.cook_blade`) or while the arm
    waits there (``flipkit validate``'s serve trials). Go to burger, scoop, pickup and carry
    are kept; the place is moved so that the burger where it really lies comes to rest on the
    spot. The burger is sensed at the carry's end, not after the scoop, because it can still
    shift on the blade during the pickup and carry.

    Args:
        plan: A solved serve plan. on_blade: (x, y) of the burger's centre in the blade frame
            (m). solver, options, caches: As :func:`plan_serve` (the cone form from the plan).

    Raises:
        ConfigError: ``plan`` is not a solved serve plan, or ``on_blade`` is off the blade.
    """
    t0 = time.perf_counter()
    cell, on_blade = check_replan(plan, "serve", on_blade)
    planner = Planner(cell, solver=solver, options=replace(options, cone=plan.cone),
                      caches=caches)
    done = [s for s in plan.segments if s.name in SERVE.kept()]
    task = Task(location=np.asarray(plan.burger["location"], float), spot=table_spot(plan),
                on_blade=on_blade, heading=plan.burger["heading"])
    return planner.chain("serve", task, done[-1].q[-1], done[-1].qd[-1], done=done, t0=t0)


def table_spot(plan: Plan) -> np.ndarray:
    """The table spot (x, y) (m) of a serve plan (its carry or place segment's ``placing``).

    Raises:
        FlipkitError: No segment records one.
    """
    rec = next((s.placing for s in plan.segments if getattr(s, "placing", None)), None)
    if rec is None:
        raise FlipkitError("serve plan: no segment records the table spot (placing.spot)")
    return np.asarray(rec["spot"], float)


__all__ = ["plan_serve", "replan_serve", "table_spot"]
