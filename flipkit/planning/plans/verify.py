"""Independent residual check of a plan: recomputed from the plan's arrays alone.

Nothing here uses :mod:`flipkit.transcription.nlp` or
:mod:`flipkit.transcription.constraints`; kinematics and dynamics come from pinocchio through
:class:`~flipkit.model.robot.Robot` rebuilt from the plan file (each segment with the payload
bodies it lists), targets from :mod:`flipkit.behaviors.targets`, and from
:mod:`flipkit.behaviors` only the specs' duration bounds, floors (``blade_floor``) and exempt
shape pairs, SCOOP_PRESS and SCOOP_TIP_BAND, and the serve's targets from :mod:`flipkit.behaviors.serve` (place and carry
poses, tip point, predicted rest point, withdrawal bounds). Check groups (a row's violation is ≥ 0, 0 when satisfied):

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
endpoints          end pose / rest / q_home per behaviour; translate: rest at  tol
                   both ends, o_x = o_y = 0 and the ``goal`` if recorded;
                   serve: carry and place end poses from the recorded spot
behavior_path      go to burger: the tip behind the rim over the descent, then  tol
                   low and not past the scoop's start (behaviors.approach);
                   scoop tip height h_g − SCOOP_PRESS ± SCOOP_TIP_BAND; flip
                   normal, x axis, height band; place: tip at its final
                   point ± PIVOT_BAND from node 0.7 N; return_home withdrawal
                   (in the blade's start frame, attitude band)
continuity         (q, q̇) of segment k's last node = segment k+1's first       tol
cone               margin ≥ 0 at cone_nodes ∪ the behaviour's cone nodes       10·tol
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


from flipkit.behaviors.approach import approach_limits, descent_node, slide_node
from flipkit.behaviors.library import FLIP_NAMES, SERVE_NAMES, SUBBEHAVIORS
from flipkit.behaviors.options import SCOOP_PRESS, SCOOP_TIP_BAND, T_STRETCH
from flipkit.config.task import APPROACH_LOW
from flipkit.behaviors.transcribe import blade_floor
from flipkit.behaviors import serve as sv
from flipkit.behaviors import targets as tg
from flipkit.model.contact import make_cone, specific_force
from flipkit.errors import ConfigError, FlipkitError
from flipkit.model.orientation import rpy
from flipkit.model.singular import SINGULARITY_MARGIN, branch_violation
from flipkit.config import CellConfig
from flipkit.planning.plans.cell_in_use import check_record, checked_cell
from flipkit.planning.plans.plan_file import Plan
from flipkit.planning.plans.hermite import hermite_extremes
from flipkit.planning.plans.verify_clearance import CellGeometry, check_space
from flipkit.planning.plans.verify_flight import check_flight
from flipkit.planning.plans.verify_safety import check_safety
# the report's types, importable from here as before
from flipkit.transcription.constraints.kinematic import BLADE_CORNERS
from flipkit.planning.plans.verify_report import (GROUPS, TOL, TOL_RANGE,  # noqa: F401
                                                  GroupResult, VerificationReport)
from flipkit.errors import VerificationError

TIME_TOL = 1e-9  # s, node times against i T / N
INTERPOLANT_TOL = (100.0, 1000.0)  # × tol: the solver's row scales 0.01 (q̇) and 0.001 (q̈)
def _outside(x, lo, hi) -> np.ndarray:
    """Distance of x outside the box [lo, hi] (0 inside)."""
    return np.maximum(np.maximum(np.asarray(lo) - x, x - np.asarray(hi)), 0.0)


def _angle(a, b) -> np.ndarray:
    """|a − b| wrapped to [0, π] (rad)."""
    return np.abs((np.asarray(a) - np.asarray(b) + np.pi) % (2 * np.pi) - np.pi)


def _point(st, r_local) -> np.ndarray:
    """World position (m) of the blade point at r_local in the spatula frame."""
    return st.p + st.R @ np.asarray(r_local, float)


def _point_height(st, r_local) -> float:
    """World height (m) of the blade point at r_local in the spatula frame."""
    return float(_point(st, r_local)[2])


def verify_plan(plan: Plan, tol: float = TOL, space=None, *, cell=None,
                where: str = "plan") -> VerificationReport:
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
    # A flip plan is the five subbehaviours in order (a plan cut short by a failed segment
    # must not pass); a translate plan has at least one segment.
    names = [s.name for s in plan.segments]
    expected = {"flip": list(FLIP_NAMES), "serve": list(SERVE_NAMES)}.get(
        plan.behavior)
    missing = (len(expected) - sum(a == b for a, b in zip(names, expected))
               if expected is not None else int(not names))
    report.add("completeness", max(len(names) - 1, 0) if names else None, [float(missing)], 0.5)
    robots, geometry = {}, None  # one model per payload list; one geometry (kinematics only)
    for k, seg in enumerate(plan.segments):
        bodies = tuple(seg.payload)
        if bodies not in robots:
            robots[bodies] = plan.robot_for(seg, cell)
        geometry = geometry or CellGeometry(robots[bodies], cell)
        _check_segment(report, k, seg, robots[bodies], plan, cell, tol)
        geometry.robot = robots[bodies]
        check_space(report, k, seg, robots[bodies], cell, geometry, tol)
        check_safety(report, k, seg, robots[bodies], tol)
        if k:
            prev = plan.segments[k - 1]
            jump = np.abs(np.concatenate([prev.q[-1] - seg.q[0], prev.qd[-1] - seg.qd[0]]))
            report.add("continuity", k, jump, tol, 0)
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


def _check_segment(report, k, seg, robot, plan, cell, tol) -> None:
    """Time grid, dynamics, limits, defects, clearance, cone and behaviour of segment k."""
    N, T, add = seg.N, seg.T, report.add
    add("time_grid", k, np.abs(seg.t - np.linspace(0.0, T, N + 1)), TIME_TOL)
    T_lo, T_hi = SUBBEHAVIORS[seg.name].duration
    qdd_max = robot.qdd_bound(SUBBEHAVIORS[seg.name].free_motion)
    add("time_grid", k, _outside(T, T_lo, T_STRETCH * T_hi), tol)
    dyn_tol = tol * robot.u_max / 10
    tau = np.array([robot.inverse_dynamics(seg.q[i], seg.qd[i], seg.qdd[i])
                    for i in range(N + 1)])
    report.add_nodes("dynamics", k, np.abs(tau - seg.u), dyn_tol)
    for group, x, lo, hi, scale in (
            ("q_limits", seg.q, robot.q_min, robot.q_max, 1.0),
            ("qd_limits", seg.qd, -robot.qd_max, robot.qd_max, 1.0),
            ("qdd_limits", seg.qdd, -qdd_max, qdd_max, 10.0),
            ("u_limits", seg.u, -robot.u_max, robot.u_max, robot.u_max / 10)):
        report.add_nodes(group, k, _outside(np.asarray(x), lo, hi), tol * scale)
    _check_interpolant(report, k, seg, robot, qdd_max, tol)
    report.add_nodes("singularity", k, branch_violation(seg.q, plan.robot["q_home"],
                                                        SINGULARITY_MARGIN), tol)
    mid = np.arange(1, N, 2)  # Hermite–Simpson midpoints; a = i − 1, b = i + 1
    dt = (seg.t[mid + 1] - seg.t[mid - 1])[:, None]
    rows = []
    for x, xd in ((np.asarray(seg.q), np.asarray(seg.qd)), (np.asarray(seg.qd), np.asarray(seg.qdd))):
        xa, xi, xb, da, di, db = x[mid - 1], x[mid], x[mid + 1], xd[mid - 1], xd[mid], xd[mid + 1]
        rows += [xi - (xa + xb) / 2 - dt * (da - db) / 8, xb - xa - dt * (da + 4 * di + db) / 6]
    report.add_nodes("defects", k, np.abs(np.concatenate(rows, axis=1)), tol, mid)

    on_blade = (seg.landing or seg.placing or {}).get(
        "burger_on_blade" if seg.landing else "on_blade", (0.0, 0.0))
    under_burger = [(*on_blade, 0.0)] if np.any(on_blade) else []
    centre, at_burger = robot.states(seg.q, seg.qd, seg.qdd, under_burger)
    states = [centre.take(i) for i in range(N + 1)]
    l, w = cell.spatula.length / 2, cell.spatula.width / 2
    floor = blade_floor(seg.name, cell, N)
    for i, st in enumerate(states[1:], 1):  # node 0 is the previous segment's last node
        heights = [_point_height(st, (a * l, b * w, 0)) for a, b in BLADE_CORNERS]
        add("grill_clearance", k, np.maximum(floor[i] - np.array(heights), 0.0), tol, i)
    cone = make_cone(plan.cone, cell.burger.mu, cell.gravity)
    release = seg.release["node"] if seg.release else 0
    required = {"translate": range(N + 1), "pickup": range(N + 1),
                "scoop": tg.scoop_cone_nodes(cell, N),
                "flip": [i for i in range(N + 1) if i <= max(tg.FLIP_CONE_FRACTION * N, release - 1)],
                "carry": range(N + 1),
                "place": [i for i in range(N + 1) if i <= sv.PLACE_CONE_FRACTION * N + 1e-9]}
    for i in sorted(set(seg.cone_nodes) | set(required.get(seg.name, ()))):
        # the flip's cone holds where the burger lies on the blade
        st = at_burger[0].take(i) if at_burger else states[i]
        add("cone", k, max(-cone.margin(st), 0.0), 10 * tol, i)
    if seg.name == "flip" and seg.release and seg.landing and plan.cone == "physical":
        # the burger leaves the blade at the release node: no normal force there
        st = at_burger[0].take(release) if at_burger else states[release]
        f = specific_force(st.R, st.a, cell.gravity)
        add("release", k, abs(f[2]), 10 * tol, release)
    _check_behavior(report, k, seg, robot, plan, cell, states, tol)


def _check_interpolant(report, k, seg, robot, qdd_max, tol) -> None:
    """q̇ and q̈ limits on the cubic Hermite interpolant between every two nodes, exactly, at
    its extremes (:func:`~flipkit.planning.plans.hermite.hermite_extremes`)."""
    start, end, qd = hermite_extremes(seg.t, seg.q, seg.qd)
    n = np.arange(seg.N)
    for i, qdd in enumerate((start, end)):
        # node of the interval's start (i = 0) or end (i = 1)
        report.add_nodes("interpolant", k, _outside(qdd, -qdd_max, qdd_max),
                         INTERPOLANT_TOL[1] * tol, n + i)
    report.add_nodes("interpolant", k, _outside(qd, -robot.qd_max, robot.qd_max),
                     INTERPOLANT_TOL[0] * tol, n)


def _check_behavior(report, k, seg, robot, plan, cell, states, tol) -> None:
    """Endpoint and path constraints of the segment's behaviour (paper eqs. 9, 22–27)."""
    N, add, end = seg.N, report.add, states[-1]
    hg, pb = cell.grill.height, plan.burger["location"]

    def pose(target: tg.Pose) -> None:
        add("endpoints", k, np.abs(end.p - np.asarray(target.p)), tol, N)
        add("endpoints", k, _angle(rpy(end.R), target.o), tol, N)

    if seg.name in ("translate", "go_to_burger", "turn_back"):
        add("endpoints", k, np.abs(seg.qd[-1]), tol, N)  # at rest at the end
    if seg.name == "translate":
        add("endpoints", k, np.abs(seg.qd[0]), tol, 0)
        add("endpoints", k, _angle(rpy(end.R)[:2], 0.0), tol, N)  # flat
        if seg.goal is not None:
            pose(seg.goal)
    elif seg.name == "go_to_burger":
        pose(tg.scoop_ready(cell, pb))
        rim, start = approach_limits(cell, pb)  # the tip behind the rim, then low (approach)
        for i in range(descent_node(N), N + 1):
            tip = _point(states[i], (cell.spatula.length / 2, 0.0, 0.0))
            if i < slide_node(N):
                add("behavior_path", k, [max(tip[0] - rim, 0.0)], tol, i)
            else:
                add("behavior_path", k, [max(tip[0] - start, 0.0),
                                         max(tip[2] - hg - APPROACH_LOW, 0.0)], tol, i)
    elif seg.name == "scoop":
        pose(tg.scoop_end(cell, pb))
        for i, st in enumerate(states):  # tip pressed into the grill, within the band
            tip = _point_height(st, (cell.spatula.length / 2, 0, 0))
            add("behavior_path", k, _outside(tip, hg - SCOOP_PRESS - SCOOP_TIP_BAND,
                                             hg - SCOOP_PRESS + SCOOP_TIP_BAND), tol, i)
    elif seg.name == "pickup":
        pose(tg.pickup_end(cell, pb))
    elif seg.name == "flip":
        add("behavior_path", k, _outside(end.R[:, 2], *tg.FLIP_NORMAL_BOUNDS), tol, N)
        lo, hi = tg.FLIP_HEIGHT_BAND
        add("behavior_path", k, _outside(end.p[2], hg + lo, hg + hi), tol, N)
        for i, st in enumerate(states):
            add("behavior_path", k, _outside(st.R[:, 0], *tg.FLIP_XAXIS_BOUNDS), tol, i)
        check_flight(report, k, seg, robot, cell, states)
    elif seg.name in ("turn_back", "return_home"):
        add("endpoints", k, np.abs(seg.q[-1] - robot.q_home), tol, N)
    if seg.name in SERVE_NAMES[3:]:
        _check_serve(report, k, seg, cell, states, tol, pose)


def _check_serve(report, k, seg, cell, states, tol, pose) -> None:
    """Serve's carry, place and return home: end poses from the recorded spot, the spot on
    the table and the predicted rest point at it, the withdrawal (module docstring)."""
    N, add = seg.N, report.add
    add("endpoints", k, np.abs(seg.qd[-1]), tol, N)  # at rest at the end
    if seg.name == "return_home":
        R0, p0 = states[0].R, states[0].p
        lo, hi = sv.withdraw_bounds(N)
        o0 = rpy(R0)
        for row, i in enumerate(range(1, sv.WITHDRAW_NODES + 1)):
            st = states[i]
            add("behavior_path", k, _outside(R0.T @ (st.p - p0), lo[row], hi[row]), tol, i)
            add("behavior_path", k, np.maximum(_angle(rpy(st.R), o0) - sv.WITHDRAW_ANGLE_BAND,
                                               0.0), tol, i)
        return
    if seg.placing is None:
        add("placing", k, [np.inf], 1e-3, N)
        return
    spot, on_blade = np.asarray(seg.placing["spot"]), np.asarray(seg.placing["on_blade"])
    try:
        tg.check_table_spot(cell, spot)
    except FlipkitError:
        add("placing", k, [np.inf], 1e-3, N)
        return
    target = (sv.carry_end if seg.name == "carry" else sv.place_end)(cell, spot, on_blade)
    pose(target)
    if seg.name == "place":  # the tilt pivots about the tip's final point
        tip = sv.tip_point(cell, target)
        half = np.array([cell.spatula.length / 2, 0.0, 0.0])
        for i in sv.pivot_nodes(N):
            miss = np.abs(states[i].p + states[i].R @ half - tip) - sv.PIVOT_BAND
            add("behavior_path", k, np.maximum(miss, 0.0), tol, i)
        end = states[-1]
        rest = sv.predicted_rest(cell, end.p, rpy(end.R)[2], on_blade)
        add("placing", k, [np.linalg.norm(rest - spot)], 1e-3, N)


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
