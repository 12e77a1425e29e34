"""Task-space targets of the subbehaviours (paper Sec. IV.C, eqs. 22–27), shared by the
joint-space collocation and the end-effector-space baseline. The values they use (the
scoop's pitch, the pickup's offset, the flip's end set, ...) are :mod:`flipkit.config.task`'s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flipkit.config import CellConfig
from flipkit.config.task import (FLIP_CONE_FRACTION, FLIP_HEIGHT_BAND,  # noqa: F401
                                 FLIP_NORMAL_BOUNDS, FLIP_XAXIS_BOUNDS, HEADING_LIMIT, PICKUP_OFFSET,
                                 PICKUP_PITCH, SCOOP_PITCH, SCOOP_PRESS, SCOOP_START_MARGIN)
from flipkit.config.checks import real_vector
from flipkit.errors import UnreachableError
from flipkit.model.task_frame import TaskFrame


@dataclass(frozen=True)
class Pose:
    """Spatula pose target: blade-centre position (m) and rpy o (rad)."""

    p: tuple
    o: tuple


BURGER_HEIGHT_TOL = 0.01  # m: |z − h_g| of a burger location accepted as on the grill


def check_burger_height(cell: CellConfig, z: float, what: str = "burger location") -> None:
    """Refuse a burger height ``z`` (m) more than :data:`BURGER_HEIGHT_TOL` from the grill's
    surface h_g, with :class:`UnreachableError` naming ``what`` and the height to give."""
    h = cell.grill.height
    if abs(z - h) > BURGER_HEIGHT_TOL:
        raise UnreachableError(f"{what}: z = {z:g} m is not on the grill surface: give z = "
                               f"{h:g} m (h_g; within +-{BURGER_HEIGHT_TOL:g} m accepted)")


def check_table_spot(cell: CellConfig, spot) -> np.ndarray:
    """The table spot (x, y) (m) as an array, or :class:`UnreachableError` (one line).

    The whole burger must lie on the table: the spot is at least a burger radius inside the
    table's edges (:class:`~flipkit.config.TableConfig`)."""
    xy = real_vector("table spot", spot, 2, "m", UnreachableError)
    tb, r = cell.table, cell.burger.diameter / 2
    lo = np.array([tb.x_range[0], tb.y_range[0]]) + r
    hi = np.array([tb.x_range[1], tb.y_range[1]]) - r
    if np.any(xy < lo - 1e-9) or np.any(xy > hi + 1e-9):
        raise UnreachableError(
            f"table spot ({xy[0]:.3f}, {xy[1]:.3f}) m is off the table: a burger there must lie "
            f"on it, x in [{lo[0]:.3f}, {hi[0]:.3f}], y in [{lo[1]:.3f}, {hi[1]:.3f}] m")
    return xy


def check_location(cell: CellConfig, location) -> np.ndarray:
    """The burger location as an array, or :class:`UnreachableError` if not on the grill."""
    loc = real_vector("burger location", location, 3, "m", UnreachableError)
    g = cell.grill
    if not g.contains(loc[:2]):
        raise UnreachableError(
            f"burger location ({loc[0]:.3f}, {loc[1]:.3f}) is outside the grill area "
            f"x in [{g.x_range[0]}, {g.x_range[1]}], y in [{g.y_range[0]}, {g.y_range[1]}] m")
    check_burger_height(cell, float(loc[2]))
    return loc


def headed(pose: Pose, pb, heading: float) -> Pose:
    """A pose stated along the paper's +x, turned by the scoop ``heading`` (rad) about the
    burger ``pb`` (:class:`~flipkit.model.task_frame.TaskFrame`)."""
    if heading == 0.0:
        return pose
    return Pose(*TaskFrame(heading, np.asarray(pb, float)[:2]).pose(pose.p, pose.o))


def default_heading(cell: CellConfig, pb) -> float:
    """The scoop heading (rad) a plan takes when none is given: radially outward from the
    arm's base axis through the burger. Along it the base's turn and the tool's yaw move
    together, so the wrists barely turn during the scoop; along the paper's +x at the grill's
    near corner, the wrists must undo the base's turn as the blade slides
    (``docs/heading.md``)."""
    base = np.asarray(cell.robot.base_in_world, float)[:2, 3]
    return float(math.atan2(pb[1] - base[1], pb[0] - base[0]))


def turned_heading(cell: CellConfig, pb, turn: float) -> float:
    """The default heading at ``pb`` turned by ``turn`` (rad), held within
    ±:data:`~flipkit.config.task.HEADING_LIMIT` of +x (a turn past it stops at it)."""
    psi = default_heading(cell, pb) + float(turn)
    return float(min(max(psi, -HEADING_LIMIT), HEADING_LIMIT))


def check_heading(heading) -> float:
    """A scoop heading (rad) as a float, or :class:`UnreachableError`: finite and within
    ±:data:`~flipkit.config.task.HEADING_LIMIT` of the paper's +x (the flip's end set,
    eq. 26, keeps the blade pointing away from the arm)."""
    psi = real_vector("scoop heading", [heading], 1, "rad", UnreachableError)[0]
    if abs(psi) > HEADING_LIMIT + 1e-12:
        raise UnreachableError(f"scoop heading {math.degrees(psi):.1f} deg is outside "
                               f"[-{math.degrees(HEADING_LIMIT):.0f}, "
                               f"{math.degrees(HEADING_LIMIT):.0f}] deg of the world's +x")
    return float(psi)


def scoop_ready(cell: CellConfig, pb, press: float = SCOOP_PRESS, heading: float = 0.0) -> Pose:
    """End of go-to-burger / start of scoop (eqs. 22–23): tip :data:`SCOOP_START_MARGIN`
    before the burger's near edge, pressed ``press`` (m) into the grill (0: on its surface,
    the paper's eq. 24), along the scoop ``heading`` (rad)."""
    d, l, oy = cell.burger.diameter, cell.spatula.length, SCOOP_PITCH
    z = cell.grill.height - press  # on the grill (Table I's z differs from h_g by ≤ 1 mm)
    x = pb[0] - d / 2 - SCOOP_START_MARGIN - l / 2 * math.cos(oy)
    return headed(Pose((x, pb[1], z + l / 2 * math.sin(oy)), (0.0, oy, 0.0)), pb, heading)


def scoop_cone_nodes(cell: CellConfig, N: int) -> list[int]:
    """Scoop nodes with the friction cone: where the burger's centre is over the blade.

    The scoop ends at rest with the burger on the blade, so the blade brakes under it; braked
    harder than friction allows, the burger slides on toward the tip (in the simulated cell
    most of a scoop's drag happens in its last instants, after the blade is under the
    burger). The blade's tip passes under the burger's centre once the blade
    centre is within l/2 of p^b; on the straight scoop path of length
    d/2 + SCOOP_START_MARGIN + (l/2) cos o_y* that is the last (l/2)/length of the path,
    which the smoothstep timing of the initial guess (and of the Bezier outputs near it)
    covers from the first node where 3s² − 2s³ ≥ 1 − (l/2)/length. Before it the burger lies
    on the grill, and the pitched blade (o_y* = 18°) would not hold it.
    """
    d, l = cell.burger.diameter, cell.spatula.length
    length = d / 2 + SCOOP_START_MARGIN + l / 2 * math.cos(SCOOP_PITCH)
    covered = 1.0 - (l / 2) / length
    s = np.arange(N + 1) / N
    return [int(i) for i in np.flatnonzero(s * s * (3 - 2 * s) >= covered - 1e-12)]


def scoop_end(cell: CellConfig, pb, press: float = SCOOP_PRESS, heading: float = 0.0) -> Pose:
    """End of scoop (eq. 23): the blade centred under the burger, its tip pressed ``press``
    (m) into the grill and its back edge, the neck, on the grill's surface: pitched
    asin(press / l) tip down (1.1° for 3 mm on a 16 cm blade), the pose of a blade that
    flexes from its neck (the paper's blade lies flat on the grill); heading ``heading`` (rad)."""
    hg, l = cell.grill.height, cell.spatula.length  # Table I's z differs from h_g by ≤ 1 mm
    pitch = math.asin(press / l)
    return headed(Pose((float(pb[0]), float(pb[1]), hg - press / 2), (0.0, pitch, 0.0)), pb,
                  heading)


def tip_pressed(cell: CellConfig, tip_floor: float) -> np.ndarray:
    """The floors (m) of the blade's four corners (tip left, tip right, back left, back
    right: :data:`~flipkit.model.robot.BLADE_CORNERS`) when the tip
    may go down to ``tip_floor``: the back corners, at the neck the blade flexes from, stay
    on the grill's surface."""
    hg = cell.grill.height
    return np.array([tip_floor, tip_floor, hg, hg])


def pickup_end(cell: CellConfig, pb, heading: float = 0.0) -> Pose:
    """End of pickup (eq. 25): 2 cm forward (along the scoop ``heading``, rad), 5 cm up,
    slightly tipped back."""
    return headed(Pose(tuple(float(pb[k] + PICKUP_OFFSET[k]) for k in range(3)),
                       (0.0, PICKUP_PITCH, 0.0)), pb, heading)


def check_spot(cell: CellConfig, spot) -> np.ndarray:
    """A landing spot (x, y) (m) on the grill as an array, or :class:`UnreachableError`."""
    xy = real_vector("landing spot", spot, 2, "m", UnreachableError)
    g = cell.grill
    if not g.contains(xy):
        raise UnreachableError(
            f"landing spot ({xy[0]:.3f}, {xy[1]:.3f}) is outside the grill area "
            f"x in [{g.x_range[0]}, {g.x_range[1]}], y in [{g.y_range[0]}, {g.y_range[1]}] m")
    return xy


def landing_spot(cell: CellConfig, pb) -> np.ndarray:
    """Designated landing spot of the flipped burger (x, y) (m): where it was picked up."""
    return np.asarray(pb[:2], dtype=float)
