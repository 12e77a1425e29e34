"""Independent residual check of a plan: recomputed from the plan's arrays alone.

Nothing here uses :mod:`flipkit.transcription.nlp` or
:mod:`flipkit.transcription.constraints`; kinematics and dynamics come from pinocchio through
:class:`~flipkit.model.robot.Robot` rebuilt from the plan file (each segment with the payload
bodies it lists), targets from :mod:`flipkit.behaviors.targets`, and from
:mod:`flipkit.behaviors` the segment's spec: its duration bounds, floor (``blade_floor``),
exempt shape pairs and end condition, its ``end_pose`` and ``cone`` hooks asked on the plan's
record (:class:`~flipkit.behaviors.probe.Probe`), its own independent ``checks``
(:mod:`flipkit.behaviors.checks`) and its ``records``; no segment is named here. Each
segment goes through every independent check of
:data:`~flipkit.planning.plans.verify_checks.CHECKS`, the table that also answers, for each
constraint block, the groups its ``check`` names
(:mod:`flipkit.transcription.constraints.registry`). Check groups (a row's violation is ≥ 0,
0 when satisfied):

=================  ==========================================================  ==============
group              what                                                        tolerance
=================  ==========================================================  ==============
time_grid          t_i = iT/N; T within the spec's bounds (upper × T_STRETCH) (s)       1e-9 s; tol
dynamics           RNEA(q_i, q̇_i, q̈_i) − u_i, payload per segment (N·m)        tol·u_max/10
defects            Hermite–Simpson interpolation and Simpson defects (rad,     tol
                   rad/s) at the odd nodes, x = (q, q̇), ẋ = (q̇, q̈)
q/qd/qdd/u_limits  joint limits: positions and torques within the URDF's and the  tol, tol,
                   arm profile's, speeds within the profile's published speed   10·tol,
                   × its speed_margin (:mod:`flipkit.config.arm`), and the      tol·u_max/10
                   acceleration limit (free motions: the cell's
                   free_accel_limit, none by default)
interpolant        q̇ and q̈ limits between the nodes, on the cubic Hermite        100·tol,
                   interpolant of (q, q̇) the controller follows: exact extremes  1000·tol
                   of each interval's polynomial (scipy's coefficients)
endpoints          the spec's end pose / rest / q_home; translate: rest at     tol
                   both ends, o_x = o_y = 0 and the ``goal`` if recorded;
                   serve: carry and place end poses from the recorded spot
behavior_path      the spec's checks: go to burger: the tip behind the rim,     tol
                   then low and not past the scoop's start (behaviors.approach);
                   scoop tip height h_g − SCOOP_PRESS ± SCOOP_TIP_BAND; flip
                   normal, x axis, height band; place: tip at its final
                   point ± PIVOT_BAND from node 0.7 N; return_home withdrawal
                   (in the blade's start frame, attitude band)
continuity         (q, q̇) of segment k's last node = segment k+1's first       tol
cone               margin ≥ 0 at cone_nodes ∪ the spec's cone nodes            10·tol
                   (flip: nodes ≤ max(0.6 N, release node − 1); carry: all;
                   place: nodes ≤ 0.7 N)
grill_clearance    the blade's four corners' heights ≥ the segment's floor (m):  tol
                   h_g, pressed SCOOP_PRESS into it on scoop and pickup,
                   a burger's thickness above it on turn back (blade_floor)
placing            serve: the table spot on the table, and the rest point        1 mm
                   predicted from the place's end pose (FK) at the spot
                   (:func:`flipkit.behaviors.serve.predicted_rest`)
release            flip: normal specific force zero at the release node, at the     10·tol
                   burger's recorded place (m/s²)
landing            flip: landing recomputed (:mod:`flipkit.planning.plans.verify_flight`):    0.1 mm,
                   within r_land, tilt ≥ 175°, and equal to the recorded one   0.01°, 0.1 ms
flight_clearance   flip: coal distance blade–flying burger ≥ 0 after release   0.1 mm
arm_clearance      every link (URDF collision hull), the handle and the blade  tol
                   keep cell.space.margin (2 cm) from grill, table and walls,
                   but the pairs the segment exempts (the spec's exempt);
                   coal distances, :mod:`flipkit.planning.plans.verify_clearance` (m)
orientation        pitch o_y within cell.limits.pitch_range (rad), eq. (4)     tol
safety_limits      the blade's and flange's fastest speed and the arm's momentum tol·limit
                   within the cell's safety preset, at the nodes and inside
                   each interval (:mod:`flipkit.planning.plans.verify_safety`)
singularity        q3 and q5 at every node within the band of q_home held      tol
                   SINGULARITY_MARGIN (0.2 rad) from sin q = 0: the planner's
                   bounds (:func:`flipkit.model.singular.branch_bounds`) (rad)
=================  ==========================================================  ==============

``tol`` (:data:`TOL` = 1e-5) is in the solver's scaled units, so every group's tolerance is
10 × the SQP feasibility tolerance (1e-6) on the same rows: the solver divides dynamics rows
and torques by u_max/10 and q̈ and the cone rows by 10, multiplies the interpolant's velocity
rows by 0.01 and its acceleration rows by 0.001, and leaves everything else unscaled. The
duration bounds are today's specs' (``duration``): a plan written under other bounds fails
``time_grid``.
Task-space position, velocity and acceleration bounds (cell.limits) are not checked. The
checks run in the cell the plan will run in — :class:`~flipkit.config.CellConfig`'s
defaults, or the ``cell`` given (``flipkit verify --cell FILE``) — never in the plan's own
record of its cell, which is only compared with it: a record that differs is refused by
field (:mod:`flipkit.planning.plans.cell_in_use`). The pitch range, the cell's boxes and
margin, the side table, the grill, the acceleration bounds and the arm's profile are that
cell's.

``tol`` is bounded to :data:`TOL_RANGE` (at most 10 × :data:`TOL`): a looser tolerance would
pass a burger or a pose centimetres off. The landing's own bounds do not scale with it: a
flip's ``target`` lies on the grill and its ``r_land`` within :data:`~flipkit.config.task.R_LAND_RANGE`,
every scenario's within [r_land, R_LAND_RANGE[1]] (group ``landing``).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from flipkit.behaviors.library import BEHAVIORS, SUBBEHAVIORS
from flipkit.behaviors.probe import Probe, RecordedOptions
from flipkit.behaviors.spec import Task
from flipkit.config import CellConfig
from flipkit.errors import ConfigError, VerificationError
from flipkit.planning.plans.cell_in_use import check_record, checked_cell
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.verify_checks import CHECKS, INTERPOLANT_TOL, SegmentView
from flipkit.planning.plans.verify_clearance import CellGeometry
from flipkit.planning.plans.verify_report import (GROUPS, TOL, TOL_RANGE, GroupResult,
                                                  VerificationReport)
from flipkit.transcription.layout import Layout


def verify_plan(plan: Plan, tol: float = TOL, space=None, *, cell=None,
                where: str = "plan", meshes=None) -> VerificationReport:
    """Check every segment of ``plan`` and the joints between them, in the cell it will run in.

    Args:
        plan: The plan (e.g. :meth:`Plan.load`).
        tol: Tolerance in the solver's scaled units, within :data:`TOL_RANGE` (see the
            module docstring).
        space: Walls and margin (:class:`~flipkit.config.space.SpaceConfig`) to check
            ``arm_clearance`` against in place of the cell's: a what-if check of the plan in
            another space, whose record's space is then not compared.
        cell: The cell the plan will run in (:class:`~flipkit.config.CellConfig`); default
            the defaults. The plan's record of its cell must match it.
        where: How a refusal names the plan (its file).
        meshes: The arm's link meshes, loaded before
            (:class:`~flipkit.model.collision.ArmMeshes`; a planner passes its own); default:
            loaded from the plan's URDF for this check. The check places them with its own
            models of the plan's arm.

    Raises:
        CellMismatchError: The plan's record of its cell differs from ``cell`` (one line
            naming the fields).
        PlanFileError: The plan's model cannot be rebuilt (URDF missing, payload mismatch).
        ConfigError: ``plan`` is not a :class:`Plan`, ``tol`` is not a number in
            :data:`TOL_RANGE` or ``cell`` not a CellConfig.
    """
    check_arguments(plan, tol, cell)
    cell = cell or CellConfig()
    if space is not None:  # a what-if space: the record's own is not compared with it
        cell = replace(cell, space=space)
    check_record(plan, cell, where, compare_space=space is None)
    cell = checked_cell(plan, cell)
    report = VerificationReport(tol, [s.name for s in plan.segments])
    if plan.cone == "paper":
        report.groups["cone"].unit = "1"  # cosine margin, dimensionless
    # A plan is its behaviour's steps in order (a plan cut short by a failed segment must not
    # pass); a plan of an open-ended behaviour (translate) has at least one segment.
    names = [s.name for s in plan.segments]
    behavior = BEHAVIORS.get(plan.behavior)
    expected = None if behavior is None or behavior.open_ended else list(behavior.names)
    missing = (len(expected) - sum(a == b for a, b in zip(names, expected))
               if expected is not None else int(not names))
    report.add("completeness", max(len(names) - 1, 0) if names else None, [float(missing)], 0.5)
    robots, geometry = {}, None  # one model per payload list; one geometry (kinematics only)
    for k, seg in enumerate(plan.segments):
        bodies = tuple(seg.payload)
        if bodies not in robots:
            robots[bodies] = plan.robot_for(seg, cell)
        geometry = geometry or CellGeometry(robots[bodies], cell, meshes)
        view = _view(report, k, seg, robots[bodies], plan, cell, tol, geometry)
        for check in CHECKS:  # every independent check, in order (verify_checks)
            check.run(view)
    return report


def check_arguments(plan, tol, cell) -> None:
    """Refuse arguments of :func:`verify_plan` of the wrong type or range (one line)."""
    if (isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating))
            or not (math.isfinite(tol) and TOL_RANGE[0] <= tol <= TOL_RANGE[1])):
        raise ConfigError(f"tol must be a number in [{TOL_RANGE[0]:g}, {TOL_RANGE[1]:g}] "
                          f"(scaled units), got {tol!r}")
    if not isinstance(plan, Plan):
        raise ConfigError(f"plan: expected a Plan (Plan.load(path)), got "
                          f"{type(plan).__name__}")
    if cell is not None and not isinstance(cell, CellConfig):
        raise ConfigError(f"cell: expected a CellConfig, got {type(cell).__name__}")


def _view(report, k, seg, robot, plan, cell, tol, geometry) -> SegmentView:
    """Segment k as the checks see it: the blade's states at the nodes (at its centre and at
    the burger's recorded place) and the spec's :class:`~flipkit.behaviors.probe.Probe`."""
    on_blade = (seg.landing or seg.placing or {}).get(
        "burger_on_blade" if seg.landing else "on_blade", (0.0, 0.0))
    under_burger = [(*on_blade, 0.0)] if np.any(on_blade) else []
    centre, at_burger = robot.states(seg.q, seg.qd, seg.qdd, under_burger)
    states = [centre.take(i) for i in range(seg.N + 1)]
    probe = _probe(report, k, seg, robot, plan, cell, states, tol)
    return SegmentView(report, k, seg, robot, plan, cell, tol, geometry, states, at_burger, probe)


def _probe(report, k, seg, robot, plan, cell, states, tol) -> Probe:
    """The spec's view of segment k (:class:`~flipkit.behaviors.probe.Probe`): the task and
    options rebuilt from the plan's record."""
    placing, landing = seg.placing or {}, seg.landing or {}
    pb = plan.burger["location"]
    on_blade = placing.get("on_blade", landing.get("burger_on_blade"))
    task = Task(location=pb, goal=seg.goal, spot=placing.get("spot"), on_blade=on_blade,
                heading=plan.burger["heading"])
    options = RecordedOptions(landing=seg.release is not None,
                              release=seg.release["node"] if seg.release else 0)
    return Probe(SUBBEHAVIORS[seg.name], seg, Layout(robot.nq, seg.N), cell, task,
                 None if pb is None else np.asarray(pb, float), options, robot, states, tol,
                 lambda group, v, t, node: report.add(group, k, v, t, node))


def require_verified(plan: Plan, where, behaviors=None, *, force: bool = False,
                     tol: float = TOL, cell=None) -> VerificationReport:
    """The gate before anything runs a plan (simulates, renders, exports it): the plan is of
    one of ``behaviors``, ``solved`` (unless ``force``) and passes :func:`verify_plan`.

    Args:
        plan: The plan. where: How messages name it (its file).
        behaviors: The behaviours accepted (``None``: any).
        force: Accept a plan whose status is not ``solved`` (it must still verify).
        tol: Verification tolerance (scaled units, :data:`TOL`).
        cell: The cell the plan will run in (:func:`verify_plan`); default the defaults.

    Returns:
        The passing report.

    Raises:
        VerificationError: The plan is of another behaviour, not solved, was planned for
            another cell (:class:`~flipkit.planning.plans.cell_in_use.CellMismatchError`)
            or fails a check group (one line naming the file, the group, its segment and
            amount).
    """
    wanted = "" if behaviors is None else " " + " or ".join(behaviors)
    if (behaviors is not None and plan.behavior not in behaviors) or (
            plan.status != "solved" and not force):
        raise VerificationError(f"{where}: plan status is {plan.status!r}, behavior "
                                f"{plan.behavior!r}; this needs a solved{wanted} plan")
    report = verify_plan(plan, tol=tol, cell=cell, where=str(where))
    if not report.ok:
        raise VerificationError(f"{where}: {report.summary()}; refused (`flipkit verify "
                                f"{where}` lists every check)")
    return report


def load_verified(path, behaviors=None, *, force: bool = False, tol: float = TOL) -> Plan:
    """:meth:`Plan.load` then :func:`require_verified`: a plan file that may be run.

    Raises:
        PlanFileError: As :meth:`Plan.load`. VerificationError: As :func:`require_verified`.
    """
    plan = Plan.load(path)
    require_verified(plan, path, behaviors, force=force, tol=tol)
    return plan


# the report's types and the interpolant's tolerances, importable from here
__all__ = ["GROUPS", "INTERPOLANT_TOL", "TOL", "TOL_RANGE", "GroupResult", "VerificationReport",
           "check_arguments", "load_verified", "require_verified", "verify_plan"]
