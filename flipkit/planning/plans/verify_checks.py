"""``verify``'s independent checks of one segment, one entry of :data:`CHECKS` per check.

Each entry names the groups of the report it fills
(:data:`~flipkit.planning.plans.verify_report.GROUPS`) and a function of a
:class:`SegmentView`; :func:`~flipkit.planning.plans.verify.verify_plan` runs every entry, in
order, on every segment. A constraint block names the groups that check it
(:class:`~flipkit.transcription.constraints.registry.Check`), and
``tests/test_constraint_registry.py`` holds every such group to an entry here. The checks
recompute from the plan's arrays (pinocchio through :class:`~flipkit.model.robot.Robot`,
coal, scipy) and never call a constraint block's rows: this module and the ones it calls
(:mod:`~flipkit.planning.plans.verify_clearance`, :mod:`~flipkit.planning.plans.verify_flight`,
:mod:`~flipkit.planning.plans.verify_safety`) import nothing from
:mod:`flipkit.transcription.constraints`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.behaviors.options import T_STRETCH
from flipkit.behaviors.probe import Probe, angle, outside
from flipkit.behaviors.transcribe import blade_floor
from flipkit.model.contact import make_cone, specific_force
from flipkit.model.orientation import rpy
from flipkit.model.robot import BLADE_CORNERS
from flipkit.model.singular import SINGULARITY_MARGIN, branch_violation
from flipkit.planning.plans.hermite import hermite_extremes
from flipkit.planning.plans.verify_clearance import check_space
from flipkit.planning.plans.verify_flight import check_flight
from flipkit.planning.plans.verify_safety import check_safety

TIME_TOL = 1e-9  # s, node times against i T / N
INTERPOLANT_TOL = (100.0, 1000.0)  # × tol: the solver's row scales 0.01 (q̇) and 0.001 (q̈)


@dataclass
class SegmentView:
    """Segment k of a plan as the checks see it.

    Attributes:
        report: The :class:`~flipkit.planning.plans.verify_report.VerificationReport`.
        k: The segment's index. seg: The segment. robot: Its model (its payload).
        plan: The plan. cell: The cell it runs in. tol: The tolerance (scaled units).
        geometry: The cell's collision geometry
            (:class:`~flipkit.planning.plans.verify_clearance.CellGeometry`).
        states: The blade centre's state at every node; ``at_burger``: the states at the
            burger's recorded place on the blade (empty when it lies at the centre).
        probe: The spec's view of the segment (:class:`~flipkit.behaviors.probe.Probe`).
    """

    report: object
    k: int
    seg: object
    robot: object
    plan: object
    cell: object
    tol: float
    geometry: object
    states: list
    at_burger: list
    probe: Probe

    @property
    def qdd_max(self) -> np.ndarray:
        """The segment's joint acceleration limit (rad/s²)."""
        return self.robot.qdd_bound(SUBBEHAVIORS[self.seg.name].free_motion)


@dataclass(frozen=True)
class GroupCheck:
    """One independent check: the report's groups it fills and the function filling them."""

    groups: tuple[str, ...]
    run: Callable[[SegmentView], None]


def time_grid(v: SegmentView) -> None:
    """t_i = iT/N; T within the spec's duration bounds (upper × T_STRETCH)."""
    seg = v.seg
    v.report.add("time_grid", v.k, np.abs(seg.t - np.linspace(0.0, seg.T, seg.N + 1)), TIME_TOL)
    T_lo, T_hi = SUBBEHAVIORS[seg.name].duration
    v.report.add("time_grid", v.k, outside(seg.T, T_lo, T_STRETCH * T_hi), v.tol)


def dynamics(v: SegmentView) -> None:
    """RNEA(q_i, q̇_i, q̈_i) − u_i at every node (pinocchio)."""
    seg, robot = v.seg, v.robot
    tau = np.array([robot.inverse_dynamics(seg.q[i], seg.qd[i], seg.qdd[i])
                    for i in range(seg.N + 1)])
    v.report.add_nodes("dynamics", v.k, np.abs(tau - seg.u), v.tol * robot.u_max / 10)


def joint_limits(v: SegmentView) -> None:
    """Positions, speeds, accelerations and torques within the model's limits."""
    seg, robot, qdd_max = v.seg, v.robot, v.qdd_max
    for group, x, lo, hi, scale in (
            ("q_limits", seg.q, robot.q_min, robot.q_max, 1.0),
            ("qd_limits", seg.qd, -robot.qd_max, robot.qd_max, 1.0),
            ("qdd_limits", seg.qdd, -qdd_max, qdd_max, 10.0),
            ("u_limits", seg.u, -robot.u_max, robot.u_max, robot.u_max / 10)):
        v.report.add_nodes(group, v.k, outside(np.asarray(x), lo, hi), v.tol * scale)


def interpolant(v: SegmentView) -> None:
    """q̇ and q̈ limits on the cubic Hermite interpolant between every two nodes, exactly, at
    its extremes (:func:`~flipkit.planning.plans.hermite.hermite_extremes`)."""
    seg, qdd_max = v.seg, v.qdd_max
    start, end, qd = hermite_extremes(seg.t, seg.q, seg.qd)
    n = np.arange(seg.N)
    for i, qdd in enumerate((start, end)):
        # node of the interval's start (i = 0) or end (i = 1)
        v.report.add_nodes("interpolant", v.k, outside(qdd, -qdd_max, qdd_max),
                           INTERPOLANT_TOL[1] * v.tol, n + i)
    v.report.add_nodes("interpolant", v.k, outside(qd, -v.robot.qd_max, v.robot.qd_max),
                       INTERPOLANT_TOL[0] * v.tol, n)


def singularity(v: SegmentView) -> None:
    """q3 and q5 within the band of q_home held SINGULARITY_MARGIN from sin q = 0."""
    v.report.add_nodes("singularity", v.k, branch_violation(v.seg.q, v.plan.robot["q_home"],
                                                            SINGULARITY_MARGIN), v.tol)


def defects(v: SegmentView) -> None:
    """Hermite–Simpson interpolation and Simpson defects at the odd nodes, recomputed."""
    seg = v.seg
    mid = np.arange(1, seg.N, 2)  # Hermite–Simpson midpoints; a = i − 1, b = i + 1
    dt = (seg.t[mid + 1] - seg.t[mid - 1])[:, None]
    rows = []
    for x, xd in ((np.asarray(seg.q), np.asarray(seg.qd)),
                  (np.asarray(seg.qd), np.asarray(seg.qdd))):
        xa, xi, xb, da, di, db = x[mid - 1], x[mid], x[mid + 1], xd[mid - 1], xd[mid], xd[mid + 1]
        rows += [xi - (xa + xb) / 2 - dt * (da - db) / 8, xb - xa - dt * (da + 4 * di + db) / 6]
    v.report.add_nodes("defects", v.k, np.abs(np.concatenate(rows, axis=1)), v.tol, mid)


def grill_clearance(v: SegmentView) -> None:
    """The blade's four corners' heights ≥ the segment's floor, nodes 1..N."""
    l, w = v.cell.spatula.length / 2, v.cell.spatula.width / 2
    floor = blade_floor(v.seg.name, v.cell, v.seg.N)
    for i, st in enumerate(v.states[1:], 1):  # node 0 is the previous segment's last node
        heights = [float((st.p + st.R @ np.array([a * l, b * w, 0.0]))[2])
                   for a, b in BLADE_CORNERS]
        v.report.add("grill_clearance", v.k, np.maximum(floor[i] - np.array(heights), 0.0),
                     v.tol, i)


def cone(v: SegmentView) -> None:
    """The cone margin ≥ 0 at the recorded cone nodes and the spec's."""
    form = make_cone(v.plan.cone, v.cell.burger.mu, v.cell.gravity)
    for i in sorted(set(v.seg.cone_nodes) | set(v.probe.spec.cone(v.probe))):
        # the flip's cone holds where the burger lies on the blade
        st = v.at_burger[0].take(i) if v.at_burger else v.states[i]
        v.report.add("cone", v.k, max(-form.margin(st), 0.0), 10 * v.tol, i)


def release(v: SegmentView) -> None:
    """No normal force at the release node, where the burger leaves the blade."""
    seg, probe = v.seg, v.probe
    node = probe.options.release
    if "release" in probe.spec.records and seg.release and seg.landing and v.plan.cone == "physical":
        st = v.at_burger[0].take(node) if v.at_burger else v.states[node]
        f = specific_force(st.R, st.a, v.cell.gravity)
        v.report.add("release", v.k, abs(f[2]), 10 * v.tol, node)


def behavior(v: SegmentView) -> None:
    """What the segment's spec declares (paper eqs. 9, 22–27 and the serve's): its end
    condition, its end pose (the spec's ``end_pose`` hook on the plan's record), its own
    independent ``checks`` (:mod:`flipkit.behaviors.checks`), and the flight of a segment that
    records a landing (:mod:`flipkit.planning.plans.verify_flight`)."""
    probe = v.probe
    spec, seg, robot, states, N = probe.spec, probe.seg, probe.robot, probe.states, probe.seg.N
    if spec.at_rest:
        probe.add("endpoints", np.abs(seg.qd[-1]), N)
    if spec.end == "home":
        probe.add("endpoints", np.abs(seg.q[-1] - robot.q_home), N)
    target = spec.end_pose(probe) if probe.has_task() else None
    if target is not None:
        probe.add("endpoints", np.abs(states[-1].p - np.asarray(target.p)), N)
        probe.add("endpoints", angle(rpy(states[-1].R), target.o), N)
    for check in spec.checks:
        check(probe)
    if "landing" in spec.records:
        check_flight(v.report, v.k, seg, robot, probe.cell, states)


def space(v: SegmentView) -> None:
    """The whole arm's clearance (coal) and the pitch range
    (:func:`~flipkit.planning.plans.verify_clearance.check_space`)."""
    v.geometry.robot = v.robot
    check_space(v.report, v.k, v.seg, v.robot, v.cell, v.geometry, v.tol)


def safety(v: SegmentView) -> None:
    """The tool's speed and the arm's momentum within the safety preset."""
    check_safety(v.report, v.k, v.seg, v.robot, v.tol)


def continuity(v: SegmentView) -> None:
    """(q, q̇) of the previous segment's last node = this segment's first."""
    if v.k:
        prev, seg = v.plan.segments[v.k - 1], v.seg
        jump = np.abs(np.concatenate([prev.q[-1] - seg.q[0], prev.qd[-1] - seg.qd[0]]))
        v.report.add("continuity", v.k, jump, v.tol, 0)


CHECKS = (
    GroupCheck(("time_grid",), time_grid),
    GroupCheck(("dynamics",), dynamics),
    GroupCheck(("q_limits", "qd_limits", "qdd_limits", "u_limits"), joint_limits),
    GroupCheck(("interpolant",), interpolant),
    GroupCheck(("singularity",), singularity),
    GroupCheck(("defects",), defects),
    GroupCheck(("grill_clearance",), grill_clearance),
    GroupCheck(("cone",), cone),
    GroupCheck(("release",), release),
    GroupCheck(("endpoints", "behavior_path", "placing", "landing", "landing_scenarios",
                "flight_clearance"), behavior),
    GroupCheck(("arm_clearance", "orientation"), space),
    GroupCheck(("safety_limits",), safety),
    GroupCheck(("continuity",), continuity),
)
