"""Serve: carry the picked-up burger to a spot on the side table, tilt it off, return home.

The paper's cell places finished burgers "on a side table" (Sec. I, Fig. 1); the paper gives
no constraints for it. flipkit's serve is go to burger, scoop, pickup (eqs. 22–25, as they
are) and three subbehaviours of its own, each a collocation segment:

* ``carry`` (like translate, eq. 9): from the pickup's end, friction cone on every node, to
  the blade flat and level :data:`CARRY_CLEARANCE` above the place pose, heading
  ψ = atan2(y, x) of the spot (radially outward from the base), at rest.
* ``place`` — a **tilt-and-withdraw**: the blade comes down and pitches its tip down to
  :data:`PLACE_PITCH` with the tip :data:`PLACE_TIP_GAP` above the table, at rest. The cone
  holds on nodes i ≤ :data:`PLACE_CONE_FRACTION` N (the burger rides the descent); from
  node ⌈0.7 N⌉ on the tip holds its final point (±:data:`PIVOT_BAND`) and the blade tilts
  about it, so the pitch passes the friction angle with the tip in place: the burger slides
  down the blade until its front edge meets the table, and rests there, front edge on the
  table, back on the blade. (Without the pivot the solver's place may swing the blade low
  and back, tilt it early and come forward again, pushing a burger that slid off early past
  its spot.)
* ``return_home``: first the withdrawal — for nodes 1..:data:`WITHDRAW_NODES` the blade keeps
  its attitude (±:data:`WITHDRAW_ANGLE_BAND`) and slides back in its own plane
  (±:data:`WITHDRAW_BAND` off it) by at least :data:`WITHDRAW_DISTANCE` (a blade length less
  its overlap with a burger at its tip): gravity along the 40° blade beats friction
  (tan θ > μ), so the burger stays where it is while the blade is pulled out from under it,
  and lies down flat about its front edge. Then the blade rises above the burger's top and
  goes to q_home at rest.

Why this move. A set-down-and-withdraw on a flat blade drags the burger with the blade
(static friction holds it to the blade, nothing holds it to the table); a slide-off by a fast
backward jerk (tablecloth trick) needs blade accelerations ≫ μ g and its drag distance grows
with μ; a tilt-off from a height lets the burger tumble. Tilted past the friction angle for
every μ the cell may have (0.70 rad = 40°: tan = 0.84 > 0.8, the top of the burger.mu range)
with the tip just above the table, the burger ends with its front edge on the table, and the
withdrawal lets it down where it is: its final place is geometry, not a sliding distance.

Where it lands (:func:`predicted_rest`): with the burger's centre at x_b along the blade
and y_b across it, its front edge overhangs the tip by x_eff + d/2 − l/2, with
x_eff = max(x_b, l/2 − d/2) (a burger further back slides down until its front edge is at
the tip). That edge meets the table there, about (x_eff + d/2 − l/2) beyond the tip, and the
burger lies down about it when the blade is pulled out: its centre comes to rest d/2 behind
it, x_eff − (l/2)(1 − cos θ) ahead of the blade centre along the heading and y_b across.
A burger that slid s = x_eff − x_b down the blade arrives moving: with the energy
m g (sin θ − μ cos θ) s it gained spent against the table's friction μ_t m g, it runs out
s (sin θ − μ cos θ)/μ_t further (μ the burger's nominal friction on the blade, μ_t the
table's: a steel tray like the grill, ``physics.mu_grill``). Without this term the rest point
would lie short of where a sliding burger comes to rest in the simulated cell.
The planner puts the blade so that this point is the spot; ``on_blade`` is where the burger
sits on the blade (default the centre; sensed during the carry, :func:`flipkit.planning.planners.serve.replan_serve`).
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.behaviors.targets import Pose
from flipkit.config import CellConfig
from flipkit.config.task import (BURGER_CLEARANCE, CARRY_CLEARANCE, PIVOT_BAND,  # noqa: F401
                                 PLACE_CONE_FRACTION, PLACE_PITCH, PLACE_TIP_GAP,
                                 WITHDRAW_ANGLE_BAND, WITHDRAW_BAND, WITHDRAW_DISTANCE,
                                 WITHDRAW_NODES)
from flipkit.errors import UnreachableError
from flipkit.model.orientation import rpy
from flipkit.model.robot import skew
from flipkit.transcription.constraints.kinematic import KinematicBlock
from flipkit.transcription.constraints.quantities import Quantity
from flipkit.model.ik import solve_pose
from flipkit.model.orientation import rpy_matrix


def heading(spot) -> float:
    """Heading ψ (rad) of the blade at the table: radially outward from the base, toward the spot."""
    return float(math.atan2(spot[1], spot[0]))


def rest_offset(cell: CellConfig, on_blade=(0.0, 0.0)) -> tuple[float, float]:
    """Where the placed burger comes to rest relative to the blade centre at the place's end
    (m): (along the heading, across it) — module docstring."""
    th, l, r = PLACE_PITCH, cell.spatula.length, cell.burger.diameter / 2
    x_eff = max(float(on_blade[0]), l / 2 - r)
    slide = x_eff - float(on_blade[0])  # m down the blade before the front edge is at the tip
    mu, mu_t = cell.burger.mu, cell.physics.mu_grill
    runout = slide * max(math.sin(th) - mu * math.cos(th), 0.0) / mu_t
    return x_eff - l / 2 * (1 - math.cos(th)) + runout, float(on_blade[1])


def place_end(cell: CellConfig, spot, on_blade=(0.0, 0.0)) -> Pose:
    """End of the place: tip :data:`PLACE_TIP_GAP` above the table, pitched :data:`PLACE_PITCH`
    tip down, heading :func:`heading`, placed so that the burger at ``on_blade`` (x, y on the
    blade, m) comes to rest at ``spot`` (:func:`rest_offset`)."""
    psi, th, l = heading(spot), PLACE_PITCH, cell.spatula.length
    u, v = np.array([math.cos(psi), math.sin(psi)]), np.array([-math.sin(psi), math.cos(psi)])
    along, across = rest_offset(cell, on_blade)
    centre = np.asarray(spot, float) - along * u - across * v
    z = cell.table.height + PLACE_TIP_GAP + l / 2 * math.sin(th)
    return Pose((float(centre[0]), float(centre[1]), float(z)), (0.0, th, psi))


def predicted_rest(cell: CellConfig, p, psi: float, on_blade=(0.0, 0.0)) -> np.ndarray:
    """Predicted rest point (x, y) (m) of the burger placed by a blade ending at centre ``p``
    with heading ``psi`` (rad), the burger at ``on_blade`` (:func:`rest_offset`)."""
    along, across = rest_offset(cell, on_blade)
    u, v = np.array([math.cos(psi), math.sin(psi)]), np.array([-math.sin(psi), math.cos(psi)])
    return np.asarray(p, float)[:2] + along * u + across * v


def carry_end(cell: CellConfig, spot, on_blade=(0.0, 0.0)) -> Pose:
    """End of the carry: the blade flat and level :data:`CARRY_CLEARANCE` above the place
    pose's centre, heading :func:`heading`."""
    p = place_end(cell, spot, on_blade).p
    return Pose((p[0], p[1], p[2] + CARRY_CLEARANCE), (0.0, 0.0, heading(spot)))


def table_floor(cell: CellConfig, N: int) -> np.ndarray:
    """Lowest blade edge height (m) at nodes 0..N of the carry and place: the table's top
    (the blade never goes below it; the grill is lower)."""
    return np.full(N + 1, max(cell.table.height, cell.grill.height))


def withdrawn_floor(cell: CellConfig, N: int) -> np.ndarray:
    """Return home's floor (m): the table's top, and after the withdrawal the placed burger's
    top plus :data:`BURGER_CLEARANCE`."""
    floor = table_floor(cell, N)
    floor[WITHDRAW_NODES + 1:] = cell.table.height + cell.burger.thickness + BURGER_CLEARANCE
    return floor


class TipPoint(Quantity):
    """World position (m) of the blade tip p + R (l/2, 0, 0) and its ∂/∂q = ∂p/∂q − [R r]× J_ω."""

    no_symbolic_form = "no SX form is stated: the place, which applies it, is solved by the SQP"

    def __call__(self, st, ctx):
        r = st.R @ np.array([ctx["length"] / 2, 0.0, 0.0])
        return st.p + r, st.dp_dq - skew(r) @ st.Jw


def tip_point(cell: CellConfig, pose: Pose) -> np.ndarray:
    """World position (m) of the blade tip at ``pose``."""
    return np.asarray(pose.p, float) + rpy_matrix(pose.o) @ np.array(
        [cell.spatula.length / 2, 0.0, 0.0])


def pivot_nodes(N: int) -> list[int]:
    """Place nodes where the tip holds its final point (the tilt pivots about it): after the
    cone nodes."""
    return [i for i in range(N + 1) if i >= PLACE_CONE_FRACTION * N - 1e-9]


class InStartFrame(Quantity):
    """Blade-centre position in a fixed frame (R0, p0): R0ᵀ (p − p0) (m), ∂/∂q = R0ᵀ ∂p/∂q."""

    no_symbolic_form = ("no SX form is stated: return home, which applies it, is solved by "
                        "the SQP")

    def __init__(self, R0, p0):
        self.R0, self.p0 = np.asarray(R0, float), np.asarray(p0, float)

    def __call__(self, st, ctx):
        return self.R0.T @ (st.p - self.p0), self.R0.T @ st.dp_dq


def withdraw_bounds(N: int) -> tuple[np.ndarray, np.ndarray]:
    """Bounds (lo, hi) on :class:`InStartFrame` at return_home nodes 1..WITHDRAW_NODES: back
    along the blade's −x (by WITHDRAW_DISTANCE at the last), within WITHDRAW_BAND of its plane
    and line."""
    n, b = WITHDRAW_NODES, WITHDRAW_BAND
    lo, hi = np.tile([-np.inf, -b, -b], (n, 1)), np.tile([0.0, b, b], (n, 1))
    hi[-1, 0] = -WITHDRAW_DISTANCE
    return lo, hi


def place_pivot(ctx) -> list:
    """The place's pivot: the tip within PIVOT_BAND of its final point from node ⌈0.7 N⌉ on."""
    end = place_end(ctx.cell, ctx.task.spot, ctx.task.blade_point())
    tip, b = tip_point(ctx.cell, end), PIVOT_BAND
    return [KinematicBlock("place_pivot", ctx.layout, TipPoint(), pivot_nodes(ctx.layout.N),
                           tip - b, tip + b, ctx={"length": ctx.cell.spatula.length})]


def withdrawal(ctx) -> list:
    """Return home's first WITHDRAW_NODES nodes: the blade slides back in its own plane,
    attitude kept (:func:`withdraw_bounds`)."""
    st = ctx.robot.placement(ctx.q_start)
    nodes = range(1, WITHDRAW_NODES + 1)
    lo, hi = withdraw_bounds(ctx.layout.N)
    o0, band = rpy(st.rotation), WITHDRAW_ANGLE_BAND
    return [KinematicBlock("withdraw", ctx.layout, InStartFrame(st.rotation, st.translation),
                           nodes, lo, hi),
            KinematicBlock("withdraw_attitude", ctx.layout, "rpy", nodes, o0 - band, o0 + band)]


def placing_record(cell: CellConfig, spot, on_blade=(0.0, 0.0)) -> dict:
    """The ``placing`` record of the carry and place segments: the table ``spot`` (x, y) (m),
    ``on_blade`` (x, y) (m, blade frame) where the burger was planned to sit, the blade's
    ``heading`` and ``pitch`` at the place's end (rad) (:func:`place_end`)."""
    end = place_end(cell, spot, on_blade)
    return {"spot": [float(v) for v in spot], "on_blade": [float(v) for v in on_blade],
            "heading": float(end.o[2]), "pitch": float(end.o[1])}


def reach(robot, pose: Pose, seeds=()) -> np.ndarray:
    """An IK solution of ``pose`` from the first of ``seeds``, then q_home, that reaches it.

    Raises:
        UnreachableError: None does.
    """
    for seed in (*seeds, robot.q_home):
        try:
            return solve_pose(robot, pose.p, pose.o, seed)
        except UnreachableError as exc:
            error = exc
    raise error


