"""A subbehaviour spec and a start state, transcribed into a segment NLP.

Every segment gets the collocation of the paper (dynamics, Hermite–Simpson with defect
variables, Bezier outputs of eq. 18, interpolant limits), its start state, the task-space
limits of Constraint 1 (eq. 4: position, velocity, acceleration, pitch), the blade's floor,
the whole arm's space limits (coal distances to the cell's boxes), and the end condition:
at rest, at q_home at rest, or moving with room to brake at half the acceleration limit (the
next segment's polynomial motion cannot realise a bang-bang stop). The spec adds its own
path constraints, end pose, friction-cone nodes and initial guess
(:class:`~flipkit.behaviors.spec.Subbehavior`).
"""

from __future__ import annotations

import numpy as np

from flipkit.behaviors import targets as tg
from flipkit.behaviors.approach import descent_node
from flipkit.behaviors.library import subbehavior
from flipkit.behaviors.models import Models
from flipkit.behaviors.options import (BRAKING_FRACTION, SCOOP_PRESS, SCOOP_TIP_BAND, T_STRETCH,
                                       SegmentOptions)
from flipkit.behaviors.spec import Context, Subbehavior, Task
from flipkit.model.contact import make_cone
from flipkit.model.singular import branch_bounds
from flipkit.transcription.constraints import (BezierOutput, Dynamics, FixedValues,
                                               HermiteSimpson, KinematicBlock)
from flipkit.transcription.constraints.base import Patterns
from flipkit.transcription.constraints.braking import BrakingMargin
from flipkit.transcription.constraints.clearance import ArmClearance, CoastingClearance
from flipkit.transcription.constraints.coasting_floor import CoastingFloor
from flipkit.transcription.constraints.interpolant import InterpolantLimits
from flipkit.transcription.constraints.quantities import Cone
from flipkit.transcription.layout import Layout
from flipkit.transcription.nlp import NLP


def transcribe(spec: Subbehavior | str, models: Models, q_start, qd_start=None, *,
               options: SegmentOptions = SegmentOptions(), task: Task | None = None,
               patterns: Patterns | None = None, **fields) -> NLP:
    """The NLP of one segment.

    Args:
        spec: A :class:`~flipkit.behaviors.spec.Subbehavior` or its name.
        models: Robot models of the cell.
        q_start, qd_start: Start state (rad, rad/s); q̇ defaults to rest.
        options: Transcription options.
        task: What the segment is for; or its fields as keywords (``location``, ``goal``,
            ``land``, ``on_blade``, ``spot``, ``scenarios``).
        patterns: The blocks' sparsity patterns filled so far, taken from and added to
            (:class:`~flipkit.transcription.constraints.base.Patterns`); default: the
            blocks fill their own.

    Raises:
        InvalidChoiceError: Unknown name. ConfigError: A task field the spec needs is
            missing. UnreachableError: The location is off the grill, or the guess's IK fails.
    """
    spec = subbehavior(spec) if isinstance(spec, str) else spec
    task = Task(**fields) if task is None else task.with_(**fields)
    spec.check(task)
    cell, robot = models.cell, models.for_spec(spec)
    L = Layout(robot.nq, options.N, patterns=patterns)
    q_start = np.asarray(q_start, float)
    qd_start = np.zeros(robot.nq) if qd_start is None else np.asarray(qd_start, float)
    location = tg.check_location(cell, task.location) if "location" in spec.needs else None
    ctx = Context(spec, L, robot, cell, q_start, qd_start, task, options, location)
    q_lo, q_hi = branch_bounds(robot.q_min, robot.q_max, robot.q_home, q_start,
                               options.singularity_margin)
    blocks = _common(ctx, models, q_lo, q_hi)
    blocks += spec.path(ctx)
    pose = spec.end_pose(ctx)
    if pose is not None:
        blocks.append(KinematicBlock("end_pose", L, "position", [L.N], pose.p, pose.p))
        blocks.append(KinematicBlock("end_orientation", L, "rpy", [L.N], pose.o, pose.o))
    if spec.end == "home":
        blocks.append(FixedValues("end_state", L, np.concatenate([L.iq(L.N), L.iqd(L.N)]),
                                  np.concatenate([robot.q_home, np.zeros(robot.nq)])))
    elif spec.end == "rest":
        blocks.append(FixedValues("end_rest", L, L.iqd(L.N), np.zeros(robot.nq)))
    else:
        blocks.append(BrakingMargin(L, L.N, q_lo, q_hi,
                                    BRAKING_FRACTION * np.asarray(robot.qdd_max)))
    cone_nodes = spec.cone(ctx)
    if cone_nodes:
        on_point = (*task.blade_point(), 0.0) if spec.cone_on_blade else None
        mu = options.cone_mu(cell.burger.mu, spec.carries_burger)
        cone = Cone(make_cone(options.cone, mu, cell.gravity),
                    on_point)
        blocks.append(KinematicBlock("cone", L, cone, cone_nodes, 0.0, np.inf, scale=0.1))
    T_lo, T_hi = spec.duration
    if options.stretch:
        T_hi *= T_STRETCH
    x0 = spec.guess(ctx, T_hi, pose)
    lb, ub, scale = _bounds(L, robot, q_lo, q_hi, T_lo, T_hi, robot.qdd_bound(spec.free_motion))
    return NLP(spec.name, L, robot, blocks, lb, ub, scale, x0, cone_nodes)


def blade_floor(spec: Subbehavior | str, cell, N: int, task=None) -> np.ndarray:
    """Lowest height (m) of the blade's four corners at nodes 0..N, (N + 1) × 4 in the order
    of :data:`~flipkit.model.robot.BLADE_CORNERS`: the spec's floor
    (per node, or per node and corner), the grill's surface by default; on an approach
    (``spec.approach``) at least ``task.approach_height`` above the grill until its descent
    (:func:`~flipkit.behaviors.approach.descent_node`) when the task sets one."""
    spec = subbehavior(spec) if isinstance(spec, str) else spec
    floor = np.full((N + 1, 4), cell.grill.height)
    if spec.floor is not None:  # per node, or per node and corner
        own = np.array(spec.floor(cell, N), float)
        floor[:] = own if own.ndim == 2 else own[:, None]
    height = None if task is None else task.approach_height
    if spec.approach and height is not None:
        d = descent_node(N)
        floor[:d] = np.maximum(floor[:d], cell.grill.height + float(height))
    return floor


def _common(ctx: Context, models: Models, q_lo, q_hi) -> list:
    """The blocks of every segment, in the order the constraint vector has them."""
    L, robot, cell, spec, o = ctx.layout, ctx.robot, ctx.cell, ctx.spec, ctx.options
    moving, lim = range(1, L.n_nodes), cell.limits
    # q_0 and q̇_0 are fixed by the start state, so constraints on them alone at node 0
    # would only repeat it (and break constraint qualification); they start at node 1.
    p_floor = np.array(lim.p_min, float)
    if spec.pressed:  # the scoop's press takes the blade centre below h_g
        p_floor[2] -= SCOOP_PRESS + SCOOP_TIP_BAND
    blade = {"length": cell.spatula.length, "width": cell.spatula.width}
    blocks = [
        Dynamics(L, robot.u_max / 10), HermiteSimpson(L), BezierOutput(L, o.epsilon),
        InterpolantLimits(L, robot.qd_max, robot.qdd_bound(spec.free_motion)),
        FixedValues("start_state", L, np.concatenate([L.iq(0), L.iqd(0)]),
                    np.concatenate([ctx.q_start, ctx.qd_start])),
        KinematicBlock("task_position", L, "position", moving, p_floor, lim.p_max),
        KinematicBlock("task_velocity", L, "velocity", moving, -lim.v_max, lim.v_max),
        KinematicBlock("task_acceleration", L, "acceleration", range(L.n_nodes), -lim.a_max,
                       lim.a_max, scale=0.1),
        KinematicBlock("grill_clearance", L, "blade_heights", moving,
                       blade_floor(spec, cell, L.N, ctx.task)[1:], np.inf, ctx=blade),
    ]
    following = None if spec.coast_into is None else subbehavior(spec.coast_into)
    # a segment that ends moving: the next one's first node interval at its longest (its
    # bound stretched) is how long the arm coasts into it
    coast = None if following is None else T_STRETCH * following.duration[1] / L.N
    if o.arm_clearance:
        margins = np.full(L.N, cell.space.margin)  # nodes 1..N
        margins[-1] += spec.end_allowance
        blocks.append(ArmClearance(L, models.shapes, moving, lambda i: spec.exempt(i, L.N),
                                   margins))
        if coast is not None:
            blocks.append(CoastingClearance(L, models.shapes, L.N, coast,
                                            spec.exempt(L.N, L.N), cell.space.margin))
    if coast is not None:  # the next segment's blade floor at its first node, coasting
        blocks.append(CoastingFloor(L, L.N, coast,
                                    float(blade_floor(following, cell, L.N, ctx.task)[1].max()),
                                    cell.spatula.length, cell.spatula.width))
    # Orientation limits (Constraint 1, eq. 4): the pitch; roll and yaw are free.
    blocks.append(KinematicBlock("task_orientation", L, "pitch", moving, *lim.pitch_range))
    return blocks


def _bounds(L: Layout, robot, q_lo, q_hi, T_lo: float, T_hi: float, qdd_max):
    """Variable bounds and scales: joint limits per node (accelerations within ``qdd_max``,
    rad/s²), the Bezier coefficients ±1 rad beyond the joint range, the duration."""
    lb, ub, scale = (np.empty(L.n) for _ in range(3))
    per_node = [(q_lo, q_hi, 1.0), (-robot.qd_max, robot.qd_max, 1.0),
                (-qdd_max, qdd_max, 10.0), (-robot.u_max, robot.u_max, robot.u_max / 10)]
    for i in range(L.n_nodes):
        for f, (lo, hi, s) in zip((L.iq, L.iqd, L.iqdd, L.iu), per_node):
            lb[f(i)], ub[f(i)], scale[f(i)] = lo, hi, s
    for j in range(robot.nq):
        ia = L.ialpha(j)
        lb[ia], ub[ia], scale[ia] = robot.q_min[j] - 1.0, robot.q_max[j] + 1.0, 1.0
    lb[L.T_index], ub[L.T_index], scale[L.T_index] = T_lo, T_hi, 1.0
    return lb, ub, scale


def flat_pose(position, yaw: float = 0.0) -> tg.Pose:
    """Spatula flat and level at ``position`` (m) with heading ``yaw`` (rad)."""
    return tg.Pose(tuple(float(v) for v in position), (0.0, 0.0, float(yaw)))
