"""The paper's success judges (Sec. V): scoop, pickup and flip, applied to a :class:`BurgerRun`;
and flipkit's serve judge (the burger rests on the side table, top up, near its spot)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flipkit.behaviors.targets import landing_spot
from flipkit.errors import ConfigError
from flipkit.simulation.run import BLADE_GAP_TOL, GRILL_SEPARATION, BurgerRun, half_extent

UPSIDE_DOWN_Z = -0.9  # up-axis z below this: lying on its other side (within ~26°)
LANDING_TOL = 0.05  # m, in x and in y (paper Sec. V)
FLIP_CONTACT_FRACTION = 0.6  # of the flip duration (paper Sec. V)
SCOOP_OVERLAP = 0.5  # of the burger's area over the blade (paper Sec. V)


def _vogel_disc(n: int = 400) -> np.ndarray:
    """n equal-area, deterministic points filling the unit disc (sunflower pattern), n×2."""
    k = np.arange(n) + 0.5
    r, th = np.sqrt(k / n), k * np.pi * (3.0 - np.sqrt(5.0))
    return np.column_stack((r * np.cos(th), r * np.sin(th)))


_DISC = _vogel_disc()


@dataclass(frozen=True)
class ScoopVerdict:
    """Scoop: ``ok`` if ≥ half the burger's area is over the blade, on its carrying side.

    Attributes:
        ok: Success. overlap: Fraction of the burger's disc over the blade rectangle (0–1).
        above: Burger centre on the carrying side of the blade (blade-frame z > 0).
    """

    ok: bool
    overlap: float
    above: bool


@dataclass(frozen=True)
class PickupVerdict:
    """Pickup: ``ok`` if, at the end of the pickup, the burger is off the grill and resting on
    the blade.

    Attributes:
        ok: Success.
        off_grill: No burger–grill contact in the last :data:`CONTACT_WINDOW` and the burger's
            lowest point more than :data:`GRILL_SEPARATION` above the grill.
        on_spatula: Centre over the blade rectangle (carrying side), lowest point within
            :data:`BLADE_GAP_TOL` of the carrying face, and some burger–blade contact in the
            last :data:`CONTACT_WINDOW`.
        clearance: Height of the burger's lowest point above the grill (m).
        gap: Height of the burger's lowest point above the blade's carrying face (m).
        over_blade: Centre over the blade rectangle, on its carrying side.
        spatula_contact: Fraction of the window's samples with burger–blade contact.
    """

    ok: bool
    off_grill: bool
    on_spatula: bool
    clearance: float
    gap: float
    over_blade: bool
    spatula_contact: float


@dataclass(frozen=True)
class FlipVerdict:
    """Flip: contact ≥ 60 % of the flip, then upside down on the grill within 5 cm in x and y.

    Attributes:
        ok: Success. contact_fraction: Fraction of flip samples with the burger on the blade
            (:meth:`BurgerRun.on_blade`: in contact, or resting within
            :data:`BLADE_GAP_TOL` of the face while the contact flag flickers off).
        upside_down: Up axis pointing down (z < −0.9) at the end. on_grill: Some burger–grill
            contact in the last :data:`CONTACT_WINDOW` of the run. offset: Landing offset
            (x, y) from the designated spot (m). up_z: World z of the burger's up axis at the end.
    """

    ok: bool
    contact_fraction: float
    upside_down: bool
    on_grill: bool
    offset: tuple
    up_z: float


def overlap_fraction(run: BurgerRun, k: int) -> float:
    """Fraction of the burger's disc lying over the blade rectangle at sample k.

    The disc (equal-area sample points in the burger's mid-plane) is projected along the
    blade normal onto the blade plane.
    """
    pts = np.column_stack((_DISC * run.burger_diameter / 2, np.zeros(len(_DISC))))
    world = run.burger_pos[k] + pts @ run.burger_rot[k].T
    local = (world - run.spatula_pos[k]) @ run.spatula_rot[k]
    inside = (np.abs(local[:, 0]) <= run.blade_length / 2) & (
        np.abs(local[:, 1]) <= run.blade_width / 2)
    return float(inside.mean())


def judge_scoop(run: BurgerRun, bounds) -> ScoopVerdict:
    """Judge the scoop segment ``bounds = (t_start, t_end)`` (s) at its end."""
    k = run.index(bounds[1])
    overlap = overlap_fraction(run, k)
    above = bool(run.in_blade_frame()[k, 2] > 0)
    return ScoopVerdict(ok=bool(overlap >= SCOOP_OVERLAP and above), overlap=overlap, above=above)


def judge_pickup(run: BurgerRun, bounds) -> PickupVerdict:
    """Judge the pickup segment ``bounds = (t_start, t_end)`` (s) at its end.

    Geometry at the last sample, contact over the last :data:`CONTACT_WINDOW` (within the
    segment): a flickering contact flag neither fails a burger resting on the blade nor passes
    one still touching the grill.
    """
    k = run.index(bounds[1])
    win = run.window(bounds[1], start=bounds[0])
    clearance = float(run.grill_clearance()[k])
    gap, over = float(run.blade_gap()[k]), bool(run.over_blade()[k])
    touching = run.touch_spatula[win]
    off = bool(not run.touch_grill[win].any() and clearance > GRILL_SEPARATION)
    on = bool(over and abs(gap) <= BLADE_GAP_TOL and touching.any())
    return PickupVerdict(ok=off and on, off_grill=off, on_spatula=on, clearance=clearance,
                         gap=gap, over_blade=over, spatula_contact=float(touching.mean()))


def judge_flip(run: BurgerRun, bounds, spot) -> FlipVerdict:
    """Judge the flip segment ``bounds = (t_start, t_end)`` (s) and the landing at the run's end.

    The run must last until the burger has landed (see ``hold`` of :meth:`BurgerSim.simulate`).

    Args:
        run: The simulation.
        bounds: Flip segment start and end times (s).
        spot: Designated landing spot (x, y) (m), e.g. :func:`flipkit.behaviors.targets.landing_spot`.
    """
    sel = (run.t >= bounds[0] - 1e-9) & (run.t <= bounds[1] + 1e-9)
    if not np.any(sel):
        raise ConfigError(f"flip bounds {tuple(bounds)} contain no sample of the run")
    frac = float(np.mean(run.on_blade()[sel]))
    up_z = float(run.up_z[-1])
    offset = run.burger_pos[-1, :2] - np.asarray(spot, float)[:2]
    down, grill = up_z < UPSIDE_DOWN_Z, bool(run.touch_grill[run.window(run.t[-1])].any())
    near = bool(np.all(np.abs(offset) <= LANDING_TOL))
    return FlipVerdict(ok=bool(frac >= FLIP_CONTACT_FRACTION and down and grill and near),
                       contact_fraction=frac, upside_down=bool(down), on_grill=grill,
                       offset=tuple(float(x) for x in offset), up_z=up_z)


def landing_target(plan) -> np.ndarray:
    """Where a flip plan lands its burger (x, y) (m), the spot :func:`judge_flip` judges
    against: the flip segment's planned ``landing["target"]`` (``flipkit plan flip --land X Y``
    lands elsewhere than the default), else :func:`~flipkit.behaviors.targets.landing_spot`
    of the plan's burger."""
    flip = plan.step("release")
    if flip.landing:
        return np.asarray(flip.landing["target"], float)[:2]
    return np.asarray(landing_spot(plan.cell(), np.asarray(plan.burger["location"], float)),
                      float)[:2]


SERVE_TOL = 0.03  # m: the burger's centre rests within 3 cm of the table spot (ours)
UPRIGHT_Z = 0.9  # up-axis z above this: top face up (within ~26°, as UPSIDE_DOWN_Z)
REST_WINDOW = 0.1  # s: "resting" = moved less than REST_MOTION over the run's last 0.1 s
REST_MOTION = 0.001  # m


@dataclass(frozen=True)
class ServeVerdict:
    """Serve: the burger rests on the table, top face up, within :data:`SERVE_TOL` of the spot.

    Attributes:
        ok: Success. offset: Final centre (x, y) minus the spot (m); distance: its norm (m).
        upright: Up axis z > :data:`UPRIGHT_Z` at the end. up_z: That z.
        on_table: Lowest point within :data:`BLADE_GAP_TOL` of the table's top and the centre
            over the table area. at_rest: Moved < :data:`REST_MOTION` over the last
            :data:`REST_WINDOW`. off_blade: Not resting on the blade at the end.
    """

    ok: bool
    offset: tuple
    distance: float
    upright: bool
    up_z: float
    on_table: bool
    at_rest: bool
    off_blade: bool


def judge_serve(run: BurgerRun, spot, table) -> ServeVerdict:
    """Judge a serve at the run's end (the run must last until the burger has settled).

    Args:
        run: The simulation. spot: The table spot (x, y) (m).
        table: The :class:`~flipkit.config.TableConfig` (height, area).
    """
    p, up_z = run.burger_pos[-1], float(run.up_z[-1])
    offset = p[:2] - np.asarray(spot, float)[:2]
    bottom = p[2] - float(half_extent(up_z, run.burger_diameter, run.burger_thickness))
    inside = (table.x_range[0] <= p[0] <= table.x_range[1]
              and table.y_range[0] <= p[1] <= table.y_range[1])
    on_table = bool(inside and abs(bottom - table.height) <= BLADE_GAP_TOL)
    win = run.window(run.t[-1], REST_WINDOW)
    moved = float(np.max(np.linalg.norm(run.burger_pos[win] - p, axis=1)))
    off_blade = not bool(run.on_blade()[-1])
    distance = float(np.linalg.norm(offset))
    upright = up_z > UPRIGHT_Z
    return ServeVerdict(ok=bool(distance <= SERVE_TOL and upright and on_table
                                and moved < REST_MOTION and off_blade),
                        offset=tuple(float(x) for x in offset), distance=distance,
                        upright=bool(upright), up_z=up_z, on_table=on_table,
                        at_rest=bool(moved < REST_MOTION), off_blade=bool(off_blade))

