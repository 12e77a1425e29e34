"""Go to burger (22), scoop (23–24) and pickup (25): the paper's first three subbehaviours,
shared by the flip and the serve; and where the scoop leaves the burger on the blade.

The scoop slides the blade under the burger with its tip pressed SCOOP_PRESS into the grill
(the blade flexes from its neck, and its spring presses the tip onto the grill) within
±SCOOP_TIP_BAND, straight (a lateral and attitude band: a blade that drifts sideways or yaws
pushes the burger), and ends at rest with the tip pressed and the blade's back edge on the
grill's surface (:func:`~flipkit.behaviors.targets.scoop_end`): any downward or pitching
velocity there would push it through the grill on pickup. The blade's neck never goes below
the grill's surface (:func:`pressed_floor`). It brakes within friction once the burger is over the blade.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from flipkit.behaviors import targets as tg
from flipkit.behaviors.clearance import tool_at_grill
from flipkit.behaviors.approach import approach_guess, approach_path, arrival_floor
from flipkit.behaviors.checks import approach_tip, scoop_tip
from flipkit.behaviors.guesses import task_path_guess
from flipkit.behaviors.options import (SCOOP_ANGLE_BAND, SCOOP_LATERAL_BAND, SCOOP_PRESS,
                                       SCOOP_TIP_BAND)
from flipkit.behaviors.spec import Subbehavior, Task
from flipkit.config import CellConfig, ScoopUncertainty
from flipkit.model.scoop import ScoopPath, overhang_share
from flipkit.transcription.constraints import KinematicBlock


def pressed_floor(cell: CellConfig, N: int) -> np.ndarray:
    """The floor of the blade's corners (m), (N + 1) × 4 in the order of
    :data:`~flipkit.model.robot.BLADE_CORNERS` (tip left, tip right,
    back left, back right): the tip's corners may be pressed SCOOP_PRESS into the grill (less
    the tip's band), where the blade flexes; the back corners, at the blade's neck, never go
    below the grill's surface (a blade flexes from its neck, not at it)."""
    tip = cell.grill.height - SCOOP_PRESS - SCOOP_TIP_BAND
    return np.tile(tg.tip_pressed(cell, tip), (N + 1, 1))


def scoop_path(ctx) -> list:
    """The tip on the grill (eq. 24), pressed in, within ±SCOOP_TIP_BAND, on nodes 1..N−1;
    the blade straight under the burger (lateral and attitude bands). With q held to a
    degree-6 polynomial by the outputs (18), tip equalities on every node plus the end pose
    and rest would leave a square, generically infeasible system: hence the band. The bands
    are stated in the scoop heading's frame (:meth:`~flipkit.behaviors.spec.Task.frame`)."""
    L, hg, pb = ctx.layout, ctx.cell.grill.height, np.asarray(ctx.location)
    frame, inner = ctx.task.frame(), range(1, L.N)
    tip = {"length": ctx.cell.spatula.length, "width": ctx.cell.spatula.width}
    band = np.array([np.inf, SCOOP_LATERAL_BAND, np.inf])
    ang = np.array([SCOOP_ANGLE_BAND, np.inf, SCOOP_ANGLE_BAND])
    return [KinematicBlock("scoop_tip", L, "tip_height", inner, hg - SCOOP_PRESS - SCOOP_TIP_BAND,
                           hg - SCOOP_PRESS + SCOOP_TIP_BAND, ctx=tip),
            KinematicBlock("scoop_lateral", L, "position", inner, pb - band, pb + band,
                           frame=frame),
            KinematicBlock("scoop_attitude", L, "rpy", inner, -ang, ang, frame=frame)]


def scoop_scenarios(segment, location, models,
                    uncertainty: ScoopUncertainty = ScoopUncertainty()) -> tuple:
    """Where the solved ``segment`` (a scoop: ``t``, ``q``, ``qd``) leaves the burger on the
    blade, and the spread; ``models``: the cell's :class:`~flipkit.behaviors.models.Models`.

    The friction model of :mod:`flipkit.model.scoop` with the cell's nominal patty and grill
    gives the place (x, y) (m, blade frame). How much of the patty's overhang the tip carries
    depends on how high the blade's top face rides above the grill
    (:func:`~flipkit.model.scoop.overhang_share`). The predicted place is for the blade resting
    on the grill, its top face the blade's thickness above it: a steel grill does not yield,
    and the scoop commands no part of the blade below the surface but the tip, by the blade's
    own flex, so the tip rides on the grill. A top face flush with the grill (the blade sunk
    into it) is the other end, kept as uncertainty. The scenarios bound the spread over that
    and what else the cell does not know
    (:class:`~flipkit.config.ScoopUncertainty`): both ends of the overhang, combined with the
    burger-blade friction at both ends of its range and the burger put ± k σ along the scoop
    (the extremes of x), and ± k σ sideways (y, which the scoop does not change).

    Returns:
        ``(predicted, scenarios)``: (2,) and a list of four (x, y), clipped to the blade.
    """
    cell = models.cell
    path = ScoopPath(models.bare, segment.t, segment.q, segment.qd, location,
                     grill_height=cell.grill.height)
    kw = {"diameter": cell.burger.diameter, "mu_grill": cell.physics.mu_grill,
          "rim": cell.physics.burger_edge_radius}
    mu, d = cell.burger.mu, uncertainty.placement
    b = cell.burger
    ends = (0.0, overhang_share(cell.physics.burger_modulus, b.thickness, b.density,
                                cell.physics.blade_thickness))
    nominal = path.outcome(mu_blade=mu, overhang=ends[1], **kw)
    xs = [path.outcome(mu_blade=mu * f, shift=(s, 0.0), overhang=e, **kw)[0]
          for e in ends for f in uncertainty.mu_scale for s in (-d, d)]
    half = cell.spatula.half_extent
    scenarios = [(min(xs), nominal[1]), (max(xs), nominal[1]),
                 (nominal[0], nominal[1] - d), (nominal[0], nominal[1] + d)]
    return np.clip(nominal, -half, half), [np.clip(v, -half, half) for v in scenarios]


def predict_on_blade(segment, task: Task, models, options) -> Task:
    """After the scoop: a task whose burger place is not known yet gets the scoop model's
    prediction, and with ``options.robust`` the scenarios of its spread."""
    if task.on_blade is not None:
        return task
    predicted, scenarios = scoop_scenarios(segment, task.location, models)
    return task.with_(on_blade=predicted, scenarios=tuple(scenarios) if options.robust else ())


GO_TO_BURGER = Subbehavior(
    "go_to_burger", duration=(0.3, 0.5), carries_burger=False, free_motion=True, end="rest",
    needs=("location",), floor=arrival_floor, approach=True, pressed=True, exempt=tool_at_grill,
    path=approach_path,
    end_pose=lambda ctx: tg.scoop_ready(ctx.cell, ctx.location, heading=ctx.task.heading),
    guess=approach_guess, role="approach", checks=(approach_tip,),
    doc="eq. (22): to the scoop's start, tip pressed into the grill before the burger")
SCOOP = Subbehavior(
    "scoop", duration=(0.2, 0.6), carries_burger=False, end="rest", needs=("location",),
    floor=pressed_floor, pressed=True, exempt=tool_at_grill, path=scoop_path,
    end_pose=lambda ctx: tg.scoop_end(ctx.cell, ctx.location, heading=ctx.task.heading),
    cone=lambda ctx: tg.scoop_cone_nodes(ctx.cell, ctx.layout.N),
    guess=partial(task_path_guess, tip_pressed=True), after_solve=predict_on_blade,
    role="scoop", checks=(scoop_tip,),
    doc="eqs. (23–24): slide under the burger, tip on the grill")
PICKUP = Subbehavior(
    "pickup", duration=(0.2, 0.25), carries_burger=True, end="moving", needs=("location",),
    floor=pressed_floor, pressed=True, exempt=tool_at_grill,
    end_pose=lambda ctx: tg.pickup_end(ctx.cell, ctx.location, ctx.task.heading),
    cone=lambda ctx: list(range(ctx.layout.n_nodes)), guess=task_path_guess,
    role="lift", doc="eq. (25): lift the burger 5 cm, tipped back")
