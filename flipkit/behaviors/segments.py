"""Constraint sets of the behaviours (paper Sec. IV.C): translate (9), go to burger (22),
scoop (23–24), pickup (25), flip (26), turn back (27), each chained by (29); in every segment
the task-space limits of Constraint 1 (eq. 4: position, velocity, acceleration, pitch) and the
whole arm's space limits (the cell's boxes, :data:`TOOL_SHAPES`).

:func:`build_segment` turns a behaviour name, a start state and the task (locations) into an
:class:`~flipkit.transcription.nlp.NLP`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flipkit.behaviors import serve as sv
from flipkit.behaviors import targets as tg
from flipkit.behaviors.guesses import initial_guess
from flipkit.transcription.layout import Layout
from flipkit.config import CellConfig
from flipkit.transcription.constraints import BezierOutput, Dynamics, FixedValues, HermiteSimpson, KinematicBlock
from flipkit.transcription.constraints.braking import BrakingMargin
from flipkit.transcription.constraints.clearance import ArmClearance, CoastingClearance
from flipkit.behaviors.clearance import (AT_GRILL, AT_TABLE, FLIP_END_ALLOWANCE, FLIP_TOOL_FRACTION,
                                         TOOL_SHAPES, clearance_excluded)
from flipkit.transcription.constraints.flight import FlightClearance, Landing, ScenarioLanding
from flipkit.transcription.constraints.kinematic import Cone
from flipkit.model.contact import make_cone
from flipkit.errors import ConfigError, InvalidChoiceError
from flipkit.model.collision import ArmShapes
from flipkit.model.singular import SINGULARITY_MARGIN, branch_bounds
from flipkit.transcription.constraints.interpolant import InterpolantLimits
from flipkit.transcription.nlp import NLP
from flipkit.model.robot import Robot

BEHAVIORS = ("translate",) + tg.SUBBEHAVIORS + sv.SERVE_ONLY
# Duration bounds (s). The cost Σu² drives T to its upper bound (DESIGN.md), so the chain
# executes in the sum of the upper bounds: 3.4 s (it was 4.0 s; the paper's Fig. 7: < 3 s).
# Measured minima (a time term in the cost, SQP, Table I locs 0, 1, 5, 8, 9): go to burger
# 0.53–0.72 s (pan at 2.16 rad/s from q_home), scoop 0.35–0.56 s, pickup 0.20–0.22 s, the
# landing flip 0.6 s, turn back 0.94 s and more (it unrolls the wrist ~2.6 rad at ≤ 3.2 rad/s
# and 20 rad/s²: ≥ 0.97 s from rest). Their worst cases add up to 3.0 s, and a uniform
# 0.7/0.55/0.25/0.6/0.9 s failed 10 of 10 turn backs and 2 scoops; 0.75/0.6/0.25/0.6/1.1 s
# solved the ten Table I locations with the SQP, but IPOPT's flip at (0.76, 0.09) ends where
# a 1.1 s turn back is infeasible and a 1.2 s one is not. Session 7 (scoop cone, coasting
# clearance), SQP, the ten Table I locations: 0.7/0.5/0.25/0.55/1.0 s (3.0 s in all) fit 3 of
# the 10 chains; 5 turn backs needed more than 1.0 s, 3 scoops more than 0.5 s, 1 flip more
# than 0.55 s (each then took T_STRETCH × its bound: 3.25–3.75 s).
T_BOUNDS = {"translate": (0.6, 2.0), "go_to_burger": (0.3, 0.75), "scoop": (0.2, 0.6),
            "pickup": (0.2, 0.25), "flip": (0.2, 0.6), "turn_back": (0.4, 1.2), **sv.T_BOUNDS}
# A segment infeasible within its duration bound is planned once more with the upper bound
# stretched by T_STRETCH (planning/planner.py): the bounds are a preference for a fast chain,
# not a physical limit (the joint limits, dynamics and cone are). Measured: the scoop at
# (0.630, −0.347) — where a burger flipped at Table I location 1 can land — runs wrist 2 at
# 0.34–0.43 rad from its singularity and has no solution within 0.6 s; it has one in 0.8 s.
T_STRETCH = 1.5
BRAKING_FRACTION = 0.5  # share of q̈_max assumed for braking at a moving segment end
# Scoop (eq. 24): the blade tip stays on the grill, pressed into it by a commanded SCOOP_PRESS
# that the grill's contact absorbs (the arm's PD then presses the blade onto the grill, and a
# grill up to SCOOP_PRESS lower than modelled still meets the tip), within ±SCOOP_TIP_BAND.
SCOOP_PRESS = tg.SCOOP_PRESS  # m, commanded depth of the tip below the grill surface
SCOOP_TIP_BAND = 0.0005  # m, the tip's band about h_g − SCOOP_PRESS: never above h_g + 0.5 mm
RELEASE_FRACTION = 0.7  # flip release node r = ceil(0.7 N): contact on 70 % of the flip
# m, default radius of the landing disc about the target spot: the plan aims at the spot,
# keeping the whole of the paper's 5 cm success square for what the plan cannot know.
R_LAND = 0.005
# m: radius within which every scenario of the burger's place on the blade must land: 1 cm
# inside the paper's success square (5 cm in x and y), which holds the disc.
R_SCENARIO = 0.04
FLIGHT_MARGIN = 0.002  # m, blade plane below the flying burger from node r + 2 on
# Friction safety factor of the planned cone: the burger–blade friction is known to ±20 %
# (the Table I trials draw it × U(0.8, 1.2)); planned at the nominal μ, the cone is active and
# 40 of 45 simulated flip failures (replanned, feed-forward) had μ × 0.81–0.95 (measured).
MU_SAFETY = 0.8
SCOOP_LATERAL_BAND = 0.01  # m: |p_y − p^b_y| during the scoop
SCOOP_ANGLE_BAND = 0.05  # rad: |o_x|, |o_z| during the scoop
CARRIES_BURGER = {"translate": True, "go_to_burger": False, "scoop": False, "pickup": True,
                  "flip": True, "turn_back": False, **sv.CARRIES_BURGER}


@dataclass(frozen=True)
class SegmentOptions:
    """Transcription options.

    Attributes:
        N: Intervals per segment (paper: 20, i.e. 21 nodes).
        epsilon: Output convergence rate ε of eq. (18) (1/s).
        cone: Friction-cone form, ``physical`` (eq. 5) or ``paper`` (eq. 20).
        r_land: Flip: radius (m) of the disc about the target spot where the burger's centre
            must land (:class:`~flipkit.transcription.constraints.flight.Landing`).
        r_scenario: Flip: radius (m) within which the landing of every scenario of the
            burger's place on the blade must come down (``scenarios`` of :func:`build_segment`).
        robust: Flip: the planners land every scenario of the scoop's outcome spread
            (:class:`~flipkit.config.ScoopUncertainty`), not only the predicted one.
        release_fraction: Flip: the release node is ⌈release_fraction · N⌉; the cone holds up
            to it, the flying burger clears the blade after it.
        mu_safety: The friction cone is planned with μ × mu_safety (a friction safety
            factor): the friction a burger actually has is uncertain, and a plan that uses the
            nominal μ to its limit lets a less sticky burger slide.
        landing: Flip: impose the release, flight and landing (default). ``False`` gives the
            paper's flip (26) alone, cone on i ≤ 0.6 N — a baseline whose burgers miss
            (``flipkit verify`` then fails its ``landing`` group).
        stretch: Allow the duration up to T_STRETCH × the upper bound of T_BOUNDS (the
            planner's second attempt at a segment infeasible within its bound).
        arm_clearance: Impose the whole arm's space limits (coal distances to the cell's
            boxes). ``False`` leaves them out: the problem that exact-derivative solvers
            (FATROP, exact-Hessian IPOPT; :mod:`flipkit.transcription.ocp_graph`) and the SQP
            can all be given, for the solver comparison of ``bench``.
        singularity_margin: Keep q3 and q5 this far (rad) from the elbow and wrist
            singularities, on the home configuration's side (:mod:`flipkit.model.singular`);
            0 lets the plan cross them.
    """

    N: int = 20
    epsilon: float = 10.0
    cone: str = "physical"
    r_land: float = R_LAND
    r_scenario: float = R_SCENARIO
    robust: bool = True
    release_fraction: float = RELEASE_FRACTION
    landing: bool = True
    mu_safety: float = MU_SAFETY
    stretch: bool = False
    arm_clearance: bool = True
    singularity_margin: float = SINGULARITY_MARGIN

    def __post_init__(self):
        if self.epsilon <= 0 or not np.isfinite(self.epsilon):
            raise ConfigError(f"epsilon must be positive, got {self.epsilon!r}")
        if not (np.isfinite(self.r_land) and 0 < self.r_land <= 0.1):
            raise ConfigError(f"r_land must be in (0, 0.1] m, got {self.r_land!r}")
        if not (np.isfinite(self.r_scenario) and self.r_land <= self.r_scenario <= 0.1):
            raise ConfigError(f"r_scenario must be in [r_land, 0.1] m, got {self.r_scenario!r}")
        if not (np.isfinite(self.mu_safety) and 0 < self.mu_safety <= 1):
            raise ConfigError(f"mu_safety must be in (0, 1], got {self.mu_safety!r}")
        if not (np.isfinite(self.release_fraction) and 0.3 <= self.release_fraction <= 0.9):
            raise ConfigError(f"release_fraction must be in [0.3, 0.9], got "
                              f"{self.release_fraction!r}")
        make_cone(self.cone, 0.5)  # validates the name
        if not (np.isfinite(self.singularity_margin) and 0 <= self.singularity_margin < 1.5):
            raise ConfigError(f"singularity_margin must be in [0, 1.5) rad, got "
                              f"{self.singularity_margin!r}")

    def release_node(self) -> int:
        """The flip's release node r = ⌈release_fraction · N⌉."""
        return int(np.ceil(self.release_fraction * self.N - 1e-9))


class Models:
    """The two dynamics models of a cell: bare spatula, and spatula carrying the burger."""

    def __init__(self, cell: CellConfig):
        self.cell = cell
        self.bare = Robot(cell, with_burger=False)
        self.loaded = Robot(cell, with_burger=True)
        self.shapes = ArmShapes(self.bare, cell)  # kinematics only: the payload does not matter

    def for_segment(self, name: str) -> Robot:
        return self.loaded if CARRIES_BURGER[name] else self.bare


def grill_floor(name: str, cell: CellConfig, N: int) -> np.ndarray:
    """Lowest height (m) of the blade's tip, heel and side edges at each node 0..N.

    Above the grill, but: the scoop presses the blade SCOOP_PRESS into it (the grill's contact
    absorbs it), the pickup lifts it out from there, going to the burger the blade comes down
    onto the grill only at the last node (the scoop's start pose presses the tip in), and the
    turn back stays clear of a flipped burger lying anywhere on the grill.
    """
    if name in sv.SERVE_ONLY:
        return sv.table_floor(name, cell, N)
    hg = cell.grill.height
    pressed = hg - SCOOP_PRESS - SCOOP_TIP_BAND
    floor = np.full(N + 1, {"scoop": pressed, "pickup": pressed,
                            "turn_back": hg + cell.burger.thickness + FLIGHT_MARGIN}.get(name, hg))
    if name == "go_to_burger":
        floor[-1] = pressed
    return floor


def build_segment(name: str, models: Models, q_start, qd_start=None, *, location=None,
                  goal: tg.Pose | None = None, land=None, on_blade=(0.0, 0.0), spot=None,
                  scenarios=(), options: SegmentOptions = SegmentOptions()) -> NLP:
    """The NLP of one behaviour segment.

    Args:
        name: One of :data:`BEHAVIORS`.
        models: Robot models of the cell.
        q_start, qd_start: Start state (rad, rad/s); q̇ defaults to rest.
        location: Burger location p^b (m) for the subbehaviours of pickup-and-flip.
        goal: End pose for ``translate``.
        land: Flip: landing spot (x, y) (m); default where the burger was picked up
            (:func:`~flipkit.behaviors.targets.landing_spot`).
        on_blade: Flip: where the burger's centre sits on the blade (x, y) in the blade frame
            (m), for its release state; serve: for where it comes to rest on the table;
            default the blade centre.
        spot: Serve (carry, place): the table spot (x, y) (m) (:mod:`flipkit.behaviors.serve`).
        scenarios: Flip: other places (x, y) (m, blade frame) the burger may lie on the blade;
            each must land within ``options.r_scenario`` of the spot too
            (:class:`~flipkit.transcription.constraints.flight.ScenarioLanding`).
        options: Transcription options.
    """
    if name not in BEHAVIORS:
        raise InvalidChoiceError("behaviour", name, BEHAVIORS)
    cell, robot = models.cell, models.for_segment(name)
    L = Layout(robot.nq, options.N)
    q_start = np.asarray(q_start, float)
    qd_start = np.zeros(robot.nq) if qd_start is None else np.asarray(qd_start, float)
    last, all_nodes = L.N, range(L.n_nodes)
    # q_0 and q̇_0 are fixed by the start state, so constraints on them alone at node 0
    # would only repeat it (and break constraint qualification); they start at node 1.
    moving = range(1, L.n_nodes)
    ctx = {"length": cell.spatula.length, "width": cell.spatula.width}
    lim, hg = cell.limits, cell.grill.height
    p_floor = np.array(lim.p_min, float)  # the scoop's press takes the blade centre below h_g
    if name in ("go_to_burger", "scoop", "pickup"):
        p_floor[2] -= SCOOP_PRESS + SCOOP_TIP_BAND
    q_lo, q_hi = branch_bounds(robot.q_min, robot.q_max, robot.q_home, q_start,
                               options.singularity_margin)
    blocks = [
        Dynamics(L, robot.u_max / 10), HermiteSimpson(L), BezierOutput(L, options.epsilon),
        InterpolantLimits(L, robot.qd_max, robot.qdd_max),
        FixedValues("start_state", L, np.concatenate([L.iq(0), L.iqd(0)]),
                    np.concatenate([q_start, qd_start])),
        KinematicBlock("task_position", L, "position", moving, p_floor, lim.p_max),
        KinematicBlock("task_velocity", L, "velocity", moving, -lim.v_max, lim.v_max),
        KinematicBlock("task_acceleration", L, "acceleration", all_nodes, -lim.a_max, lim.a_max,
                       scale=0.1),
    ]
    blocks.append(KinematicBlock("grill_clearance", L, "blade_heights", moving,
                                 grill_floor(name, cell, L.N)[1:, None], np.inf, ctx=ctx))
    margins = np.full(L.N, cell.space.margin)  # nodes 1..N
    if name == "flip":
        margins[-1] += FLIP_END_ALLOWANCE
    if options.arm_clearance:
        blocks.append(ArmClearance(L, models.shapes, moving,
                                   lambda i: clearance_excluded(name, i, L.N), margins))
        if name == "flip":
            # The turn back starts with the flip's end velocity; coasting for its first node
            # interval (at its longest) the arm must still keep the margin (CoastingClearance).
            blocks.append(CoastingClearance(L, models.shapes, last,
                                            T_BOUNDS["turn_back"][1] / L.N,
                                            clearance_excluded(name, last, L.N),
                                            cell.space.margin))
    # Orientation limits (Constraint 1, eq. 4): the pitch; roll and yaw are free (TaskLimits).
    blocks.append(KinematicBlock("task_orientation", L, "pitch", moving, *lim.pitch_range))
    # the burger's contact acceleration is that of the blade point under its centre
    on_point = ((*np.asarray(on_blade, float)[:2], 0.0) if name in ("flip", "carry", "place")
                else None)
    cone = Cone(make_cone(options.cone, cell.burger.mu * options.mu_safety, cell.gravity),
                on_point)
    cone_nodes: list[int] = []
    # The scoop ends at rest too (our addition): the blade lies flat on the grill at its end,
    # so any downward or pitching velocity there would push it through the grill on pickup.
    rest_at_end = name in ("translate", "go_to_burger", "scoop", "turn_back", "carry", "place",
                           "return_home")
    pose, pb = None, None
    if name in sv.SERVE_ONLY:
        if spot is None and name != "return_home":
            raise ConfigError(f"{name} needs the table spot")
        more, pose = sv.serve_blocks(name, L, robot, q_start, spot, on_blade)
        blocks += more
        cone_nodes = sv.cone_nodes(name, L.N)
    elif name == "translate":
        if goal is None:
            raise ConfigError("translate needs a goal pose")
        pose, cone_nodes = goal, list(all_nodes)
    else:
        if location is None:
            raise ConfigError(f"{name} needs the burger location")
        pb = tg.check_location(cell, location)
        if name == "go_to_burger":
            pose = tg.scoop_ready(cell, pb)
        elif name == "scoop":
            pose = tg.scoop_end(cell, pb)
            # The tip stays on the grill (eq. 24), pressed SCOOP_PRESS into it, within a band
            # of ±SCOOP_TIP_BAND: with q held to a degree-6 polynomial by the outputs (18), 19
            # tip equalities plus the end pose and rest leave a square, generically infeasible
            # system. Go-to-burger leaves the tip pressed at node 0; at node N the flat end
            # pose presses the whole blade.
            blocks.append(KinematicBlock("scoop_tip", L, "tip_height", range(1, L.N),
                                         hg - SCOOP_PRESS - SCOOP_TIP_BAND,
                                         hg - SCOOP_PRESS + SCOOP_TIP_BAND, ctx=ctx))
            # Slide straight under the burger (our addition): without it the blade drifts
            # sideways and yaws on the way and pushes the burger (seen in MuJoCo).
            band = np.array([np.inf, SCOOP_LATERAL_BAND, np.inf])
            blocks.append(KinematicBlock("scoop_lateral", L, "position", range(1, L.N),
                                         np.asarray(pb) - band, np.asarray(pb) + band))
            ang = np.array([SCOOP_ANGLE_BAND, np.inf, SCOOP_ANGLE_BAND])
            blocks.append(KinematicBlock("scoop_attitude", L, "rpy", range(1, L.N), -ang, ang))
            # Brake within friction once the burger is over the blade (our addition).
            cone_nodes = tg.scoop_cone_nodes(cell, L.N)
        elif name == "pickup":
            pose, cone_nodes = tg.pickup_end(cell, pb), list(all_nodes)
        elif name == "flip":
            # Contact up to the release node r (the paper's cone on i ≤ 0.6 N, extended to r),
            # ballistic flight after it (flipkit.transcription.constraints.flight explains the choice).
            r = options.release_node() if options.landing else 0
            cone_nodes = [i for i in all_nodes if i <= max(r, tg.FLIP_CONE_FRACTION * L.N)]
            spot = tg.landing_spot(cell, pb) if land is None else tg.check_spot(cell, land)
            bg = cell.burger
            margin = np.full(L.N - r, FLIGHT_MARGIN)
            margin[0] = 0.0  # the burger has only just left the blade at node r + 1
            if options.landing:
                blocks += [
                    Landing(L, r, spot, options.r_land, thickness=bg.thickness,
                            grill_height=hg, gravity=cell.gravity, on_blade=on_blade),
                    FlightClearance(L, r, margin, thickness=bg.thickness,
                                    diameter=bg.diameter, gravity=cell.gravity,
                                    on_blade=on_blade),
                ]
                if len(scenarios):
                    blocks.append(ScenarioLanding(L, r, spot, options.r_scenario, scenarios,
                                                  thickness=bg.thickness, grill_height=hg,
                                                  gravity=cell.gravity))
            lo_n, hi_n = tg.FLIP_NORMAL_BOUNDS
            lo_x, hi_x = tg.FLIP_XAXIS_BOUNDS
            band = tg.FLIP_HEIGHT_BAND
            blocks += [
                KinematicBlock("flip_normal", L, "normal", [last], lo_n, hi_n),
                KinematicBlock("flip_xaxis", L, "xaxis", moving, lo_x, hi_x),
                KinematicBlock("flip_height", L, "height", [last], hg + band[0], hg + band[1]),
            ]
    if pose is not None:
        blocks.append(KinematicBlock("end_pose", L, "position", [last], pose.p, pose.p))
        blocks.append(KinematicBlock("end_orientation", L, "rpy", [last], pose.o, pose.o))
    if name in ("turn_back", "return_home"):
        blocks.append(FixedValues("end_state", L, np.concatenate([L.iq(last), L.iqd(last)]),
                                  np.concatenate([robot.q_home, np.zeros(robot.nq)])))
    elif rest_at_end:
        blocks.append(FixedValues("end_rest", L, L.iqd(last), np.zeros(robot.nq)))
    if not rest_at_end:
        # Stopping distance at half the acceleration limit: the next segment's polynomial
        # motion cannot realise a bang-bang stop (measured: at the full 20 rad/s² flips ended
        # on the margin and 5 of 10 turn-backs from them were infeasible).
        blocks.append(BrakingMargin(L, last, q_lo, q_hi,
                                    BRAKING_FRACTION * np.asarray(robot.qdd_max)))
    if cone_nodes:
        blocks.append(KinematicBlock("cone", L, cone, cone_nodes, 0.0, np.inf, scale=0.1))

    T_lo, T_hi = T_BOUNDS[name]
    if options.stretch:
        T_hi *= T_STRETCH
    x0 = initial_guess(name, L, robot, q_start, qd_start, T_hi, pose, pb, cell, rest_at_end)

    lb, ub, scale = (np.empty(L.n) for _ in range(3))
    per_node = [(q_lo, q_hi, 1.0), (-robot.qd_max, robot.qd_max, 1.0),
                (-robot.qdd_max, robot.qdd_max, 10.0), (-robot.u_max, robot.u_max, robot.u_max / 10)]
    for i in all_nodes:
        for f, (lo, hi, s) in zip((L.iq, L.iqd, L.iqdd, L.iu), per_node):
            lb[f(i)], ub[f(i)], scale[f(i)] = lo, hi, s
    for j in range(robot.nq):
        ia = L.ialpha(j)
        lb[ia], ub[ia], scale[ia] = robot.q_min[j] - 1.0, robot.q_max[j] + 1.0, 1.0
    lb[L.T_index], ub[L.T_index], scale[L.T_index] = T_lo, T_hi, 1.0
    return NLP(name, L, robot, blocks, lb, ub, scale, x0, cone_nodes)


def flat_pose(position, yaw: float = 0.0) -> tg.Pose:
    """Spatula flat and level at ``position`` (m) with heading ``yaw`` (rad)."""
    return tg.Pose(tuple(float(v) for v in position), (0.0, 0.0, float(yaw)))


__all__ = ["AT_GRILL", "AT_TABLE", "BEHAVIORS", "T_STRETCH", "FLIP_END_ALLOWANCE", "FLIP_TOOL_FRACTION", "T_BOUNDS",
           "TOOL_SHAPES", "SegmentOptions", "Models", "build_segment", "clearance_excluded",
           "flat_pose", "grill_floor"]
