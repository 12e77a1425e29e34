"""Flip (26) and turn back (27), and the pickup-and-flip behaviour.

The flip keeps the burger in contact up to the release node r = ⌈release_fraction · N⌉ (the
paper's cone on i ≤ 0.6 N, extended to r − 1), where the contact force falls to zero; after
it the burger flies ballistically, clear of the blade, and lands flat on the spot
(:mod:`flipkit.transcription.constraints.flight`), with every scenario of its place on the
blade. It ends moving, with room to brake, and its last
state, coasting for the turn back's first node interval, keeps the space margin too. The
turn back returns to q_home at rest, above any flipped burger on the grill.
"""

from __future__ import annotations

import numpy as np

from flipkit.behaviors import targets as tg
from flipkit.behaviors.checks import flip_end_set
from flipkit.behaviors.clearance import FLIP_END_ALLOWANCE, tool_leaves_grill
from flipkit.behaviors.guesses import flip_guess, turn_back_guess
from flipkit.behaviors.options import FLIGHT_MARGIN
from flipkit.behaviors.pick import GO_TO_BURGER, PICKUP, SCOOP
from flipkit.behaviors.spec import Behavior, Subbehavior
from flipkit.config import CellConfig
from flipkit.model.contact import make_cone
from flipkit.transcription.constraints import KinematicBlock
from flipkit.transcription.constraints.quantities import Cone
from flipkit.transcription.constraints.flight import FlightClearance, Landing, ScenarioLanding


def release_node(ctx) -> int:
    """The flip's release node r (0 for the paper's flip without a landing)."""
    return ctx.options.release_node() if ctx.options.landing else 0


def flip_cone(ctx) -> list[int]:
    """Contact up to the node before the release node (at least the paper's 0.6 N): at the
    release node the contact force is zero (:func:`release_blocks`)."""
    r = release_node(ctx)
    return [i for i in range(ctx.layout.n_nodes) if i <= max(r - 1, tg.FLIP_CONE_FRACTION * ctx.layout.N)]


def release_blocks(ctx) -> list:
    """A decisive release wherever the burger lies: the cone at every scenario's place on
    the nodes before the release node r (the nominal place's is the segment's own cone), at
    node r − 1 the normal specific force f_z ≥ ``options.release_press`` at the nominal
    place and at every scenario's, and f_z = 0 at node r at the nominal place, so the burger
    leaves the blade at node r, where the flight model (:class:`~flipkit.transcription.
    constraints.flight.Landing`) starts it (:data:`~flipkit.config.task.RELEASE_PRESS`).
    The press and the release need the ``physical`` cone (its first row is f_z); the
    ``paper`` cone gets the scenario cones alone."""
    L, cell, task, o = ctx.layout, ctx.cell, ctx.task, ctx.options
    r = release_node(ctx)
    if r < 1:
        return []
    form = make_cone(o.cone, o.cone_mu(cell.burger.mu, True), cell.gravity)
    before = [i for i in flip_cone(ctx) if i < r]
    press = o.release_press if o.cone == "physical" else 0.0
    blocks = []
    for k, place in enumerate(task.scenarios):
        lo = np.zeros((len(before), form.rows))
        lo[-1, 0] = press  # node r − 1 is the last of ``before``
        blocks.append(KinematicBlock(f"cone_scenario_{k}", L, Cone(form, (*place, 0.0)),
                                     before, lo, np.inf, scale=0.1))
    if press > 0:
        lo = np.zeros((1, form.rows))
        lo[0, 0] = press
        blocks.append(KinematicBlock("release_press", L, Cone(form, (*task.blade_point(), 0.0)),
                                     [r - 1], lo, np.inf, scale=0.1))
    if o.cone == "physical":  # only f_z is held: the friction rows have no force to bound
        lo, hi = np.full((1, form.rows), -np.inf), np.full((1, form.rows), np.inf)
        lo[0, 0] = hi[0, 0] = 0.0
        blocks.append(KinematicBlock("release", L, Cone(form, (*task.blade_point(), 0.0)),
                                     [r], lo, hi, scale=0.1))
    return blocks


def flip_path(ctx) -> list:
    """Release (:func:`release_blocks`), flight clearance and landing (nominal and
    scenarios), then the end set of
    eq. (26): the blade's normal, its x axis on every node, the height at the end."""
    L, cell, task, o = ctx.layout, ctx.cell, ctx.task, ctx.options
    r, hg, bg = release_node(ctx), cell.grill.height, cell.burger
    blocks = []
    if o.landing:
        spot = (tg.landing_spot(cell, ctx.location) if task.land is None
                else tg.check_spot(cell, task.land))
        margin = np.full(L.N - r, FLIGHT_MARGIN)
        margin[0] = 0.0  # the burger has only just left the blade at node r + 1
        on_blade = task.blade_point()
        blocks += [Landing(L, r, spot, o.r_land, thickness=bg.thickness, diameter=bg.diameter,
                           grill_height=hg, gravity=cell.gravity, on_blade=on_blade),
                   FlightClearance(L, r, margin, thickness=bg.thickness, diameter=bg.diameter,
                                   gravity=cell.gravity, on_blade=on_blade)]
        if len(task.scenarios):
            blocks.append(ScenarioLanding(L, r, spot, o.r_scenario, task.scenarios,
                                          thickness=bg.thickness, diameter=bg.diameter,
                                          grill_height=hg, gravity=cell.gravity))
        blocks += release_blocks(ctx)
    (lo_n, hi_n), (lo_x, hi_x), band = tg.FLIP_NORMAL_BOUNDS, tg.FLIP_XAXIS_BOUNDS, tg.FLIP_HEIGHT_BAND
    frame = task.frame()  # the end set is the paper's, along the scoop heading
    return blocks + [
        KinematicBlock("flip_normal", L, "normal", [L.N], lo_n, hi_n, frame=frame),
        KinematicBlock("flip_xaxis", L, "xaxis", range(1, L.n_nodes), lo_x, hi_x, frame=frame),
        KinematicBlock("flip_height", L, "height", [L.N], hg + band[0], hg + band[1]),
    ]


def above_burger(cell: CellConfig, N: int) -> np.ndarray:
    """The blade's edges above a flipped burger lying anywhere on the grill (m)."""
    return np.full(N + 1, cell.grill.height + cell.burger.thickness + FLIGHT_MARGIN)


TURN_BACK = Subbehavior(
    "turn_back", duration=(0.4, 0.75), carries_burger=False, free_motion=True, end="home",
    floor=above_burger, guess=turn_back_guess, role="home", atlas_anchor="blend",
    doc="eq. (27): back to q_home at rest")
FLIP = Subbehavior(
    "flip", duration=(0.2, 0.9), carries_burger=True, end="moving", needs=("location",),
    exempt=tool_leaves_grill, path=flip_path, cone=flip_cone, cone_on_blade=True,
    guess=flip_guess, end_allowance=FLIP_END_ALLOWANCE, coast_into=TURN_BACK.name,
    role="release", records=("release", "landing"), checks=(flip_end_set,),
    atlas_anchor="shift",
    doc="eq. (26) with release, flight and landing")
# The burger is sensed on the blade after the scoop, at rest on the grill; a re-plan keeps the
# go to burger, scoop and pickup (the pickup does not depend on where the burger lies).
PICKUP_AND_FLIP = Behavior("flip", (GO_TO_BURGER, SCOOP, PICKUP, FLIP, TURN_BACK),
                           sensed="scoop", replanned="release")
