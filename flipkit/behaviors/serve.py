"""Serve: carry the picked-up burger to a spot on the side table, tilt it off, return home.

The paper's cell places finished burgers "on a side table" (Sec. I, Fig. 1); the paper gives
no constraints for it. flipkit's serve is go to burger, scoop, pickup (eqs. 22–25, as they
are) and three subbehaviours of its own, each a collocation segment:

* ``carry`` (like translate, eq. 9): from the pickup's end, friction cone on every node, to
  the blade flat and level :data:`CARRY_CLEARANCE` above the place pose, heading
  ψ = atan2(y, x) of the spot (radially outward from the base), at rest.
* ``place`` — a **tilt-off**: the blade comes down and pitches its tip down to
  :data:`PLACE_PITCH` with the tip :data:`PLACE_TIP_GAP` above the table, at rest. The cone
  holds on nodes i ≤ :data:`PLACE_CONE_FRACTION` N (the burger rides the descent); after
  them the pitch passes the friction angle and the burger slides off the tip onto the table.
* ``return_home``: first a withdrawal — for nodes 1..:data:`WITHDRAW_NODES` the blade keeps
  its attitude (±:data:`WITHDRAW_ANGLE_BAND`) and slides back in its own plane
  (±:data:`WITHDRAW_BAND` off it) by at least :data:`WITHDRAW_DISTANCE` — so a burger still on
  the tip is pulled out from under, not flung; then to q_home at rest.

Why a tilt-off. A set-down-and-withdraw drags the burger with the blade (static friction
holds it to the blade, nothing holds it to the table); a slide-off by a fast backward jerk
(tablecloth trick) needs blade accelerations ≫ μ g and its drag distance grows with μ.
Tilted past the friction angle, the burger leaves by gravity alone: the pitch only has to
exceed atan μ for every μ the cell may have (0.70 rad = 40°: tan = 0.84 > 0.8, the top of
the burger.mu range), and with the tip just above the table the burger slides a few
centimetres at most before its front edge meets the table, so it runs out little.

Where it lands: the burger's centre ends about a burger radius plus :data:`PLACE_RUNOUT`
beyond the tip along the heading, so the tip is put at spot − (d/2 + runout)·(cos ψ, sin ψ).
The runout is a planning allowance, not a simulation parameter (see its comment).
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.behaviors.targets import Pose
from flipkit.config import CellConfig
from flipkit.errors import UnreachableError
from flipkit.model.orientation import rpy
from flipkit.transcription.constraints.kinematic import KinematicBlock, Quantity

SERVE_SUBBEHAVIORS = ("go_to_burger", "scoop", "pickup", "carry", "place", "return_home")
SERVE_ONLY = SERVE_SUBBEHAVIORS[3:]
PLACE_PITCH = 0.70  # rad, tip down at the end of the place (tan 0.70 = 0.84 > μ's range 0.2–0.8)
PLACE_TIP_GAP = 0.005  # m, blade tip above the table at the end of the place
PLACE_CONE_FRACTION = 0.7  # the cone holds on place nodes i ≤ 0.7 N
# m, the burger's centre ends this far beyond (tip + d/2) along the heading. Estimate: sliding
# s ≤ l/2 − d/2 = 3 cm down the 40° blade and running out on a table of friction μ_t ≈ μ it
# covers s (sin θ − μ cos θ)/μ_t ≈ 0.5 s ≤ 1.5 cm; 1 cm is the middle of that.
PLACE_RUNOUT = 0.01
CARRY_CLEARANCE = 0.06  # m, the carry ends with the blade centre this far above the place pose
WITHDRAW_NODES = 5  # return_home nodes 1..5 withdraw the blade in its own plane
WITHDRAW_DISTANCE = 0.06  # m, at least this far back along −x of the blade by node 5
WITHDRAW_BAND = 0.005  # m, off the blade's start plane / start line while withdrawing
WITHDRAW_ANGLE_BAND = 0.05  # rad, rpy about the place end's while withdrawing
# Duration bounds (s): Σu² drives T to the upper bound. The carry covers up to ~1 m under the
# cone (planned μ 0.4: ≤ 3.9 m/s² sideways); the return unrolls the heading back to q_home's.
T_BOUNDS = {"carry": (0.6, 1.6), "place": (0.3, 0.8), "return_home": (0.5, 1.5)}
CARRIES_BURGER = {"carry": True, "place": True, "return_home": False}


def check_table_spot(cell: CellConfig, spot) -> np.ndarray:
    """The table spot (x, y) (m) as an array, or :class:`UnreachableError` (one line).

    The whole burger must lie on the table: the spot is at least a burger radius inside the
    table's edges (:class:`~flipkit.config.TableConfig`)."""
    xy = np.asarray(spot, dtype=float).ravel() if np.ndim(spot) else np.array([spot], float)
    if xy.shape != (2,) or not np.all(np.isfinite(xy)):
        raise UnreachableError(f"table spot must be two finite numbers (m), got {spot!r}")
    tb, r = cell.table, cell.burger.diameter / 2
    lo = np.array([tb.x_range[0], tb.y_range[0]]) + r
    hi = np.array([tb.x_range[1], tb.y_range[1]]) - r
    if np.any(xy < lo - 1e-9) or np.any(xy > hi + 1e-9):
        raise UnreachableError(
            f"table spot ({xy[0]:.3f}, {xy[1]:.3f}) m is off the table: a burger there must lie "
            f"on it, x in [{lo[0]:.3f}, {hi[0]:.3f}], y in [{lo[1]:.3f}, {hi[1]:.3f}] m")
    return xy


def heading(spot) -> float:
    """Heading ψ (rad) of the blade at the table: radially outward from the base, toward the spot."""
    return float(math.atan2(spot[1], spot[0]))


def place_end(cell: CellConfig, spot) -> Pose:
    """End of the place: tip :data:`PLACE_TIP_GAP` above the table, pitched :data:`PLACE_PITCH`
    tip down, heading :func:`heading`, the tip d/2 + :data:`PLACE_RUNOUT` short of the spot."""
    psi, th, l = heading(spot), PLACE_PITCH, cell.spatula.length
    u = np.array([math.cos(psi), math.sin(psi)])
    tip = np.asarray(spot, float) - (cell.burger.diameter / 2 + PLACE_RUNOUT) * u
    centre = tip - l / 2 * math.cos(th) * u
    z = cell.table.height + PLACE_TIP_GAP + l / 2 * math.sin(th)
    return Pose((float(centre[0]), float(centre[1]), float(z)), (0.0, th, psi))


def carry_end(cell: CellConfig, spot) -> Pose:
    """End of the carry: the blade flat and level :data:`CARRY_CLEARANCE` above the place
    pose's centre, heading :func:`heading`."""
    p = place_end(cell, spot).p
    return Pose((p[0], p[1], p[2] + CARRY_CLEARANCE), (0.0, 0.0, heading(spot)))


def table_floor(cell: CellConfig, N: int) -> np.ndarray:
    """Lowest blade edge height (m) at nodes 0..N of a serve-only segment: the table's top
    (the blade never goes below it; the grill is lower)."""
    return np.full(N + 1, max(cell.table.height, cell.grill.height))


class InStartFrame(Quantity):
    """Blade-centre position in a fixed frame (R0, p0): R0ᵀ (p − p0) (m), ∂/∂q = R0ᵀ ∂p/∂q."""

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


def serve_blocks(name: str, L, robot, q_start, spot, ctx) -> tuple[list, Pose | None]:
    """Path blocks of a serve-only segment and its end pose (None for return_home)."""
    if name == "carry":
        return [], carry_end(robot.cell, spot)
    if name == "place":
        return [], place_end(robot.cell, spot)
    st = robot.placement(q_start)
    nodes = range(1, WITHDRAW_NODES + 1)
    lo, hi = withdraw_bounds(L.N)
    o0, band = rpy(st.rotation), WITHDRAW_ANGLE_BAND
    return [KinematicBlock("withdraw", L, InStartFrame(st.rotation, st.translation), nodes, lo, hi),
            KinematicBlock("withdraw_attitude", L, "rpy", nodes, o0 - band, o0 + band)], None


def cone_nodes(name: str, N: int) -> list[int]:
    """Nodes where a serve-only segment enforces the friction cone."""
    if name == "carry":
        return list(range(N + 1))
    if name == "place":
        return [i for i in range(N + 1) if i <= PLACE_CONE_FRACTION * N + 1e-9]
    return []


__all__ = ["SERVE_SUBBEHAVIORS", "SERVE_ONLY", "PLACE_PITCH", "PLACE_TIP_GAP", "PLACE_RUNOUT",
           "PLACE_CONE_FRACTION", "T_BOUNDS", "CARRIES_BURGER", "check_table_spot", "heading",
           "place_end", "carry_end", "table_floor", "InStartFrame", "withdraw_bounds",
           "serve_blocks", "cone_nodes"]
