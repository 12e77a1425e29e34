"""The record of one simulated run: burger and blade time series, and the geometry the judges
read from them (on the blade, off the grill, over the blade rectangle)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# "On the spatula" / "off the grill" are judged geometrically and over a short window, not from
# one sample's contact flag: MuJoCo's burger–blade contact flickers (present, absent, present
# from one 1 ms step to the next) while the blade decelerates upward with the burger resting on
# it at a gap of micrometres, so a single-instant flag reads "not on the spatula" at random
# for milliseconds at a time: "in contact" is read over a window.
CONTACT_WINDOW = 0.05  # s: "in contact" at an instant = some contact in the last 50 ms
BLADE_GAP_TOL = 0.003  # m: burger bottom within 3 mm of the blade's carrying face = resting on it
GRILL_SEPARATION = 0.001  # m: burger bottom more than 1 mm above the grill = lifted off it


def half_extent(axis_z, diameter: float, thickness: float):
    """Extent of a cylinder below its centre along a unit direction n, where ``axis_z`` is the
    cosine between n and the cylinder axis: r·sin θ + (h/2)·|cos θ|."""
    axis_z = np.clip(np.abs(axis_z), 0.0, 1.0)
    return diameter / 2 * np.sqrt(1.0 - axis_z**2) + thickness / 2 * axis_z


def _bridge(t: np.ndarray, flag: np.ndarray, span: float) -> np.ndarray:
    """``flag`` with its False runs filled where they lie between two True samples that are
    at most ``span`` (s) apart (a morphological closing in time)."""
    out = np.asarray(flag, bool).copy()
    on = np.flatnonzero(out)
    for a, b in zip(on[:-1], on[1:]):
        if b > a + 1 and t[b] - t[a] <= span + 1e-9:
            out[a + 1:b] = True
    return out


@dataclass
class BurgerRun:
    """Time series of one simulation (world frame, SI units); N samples.

    Attributes:
        t: Times (s). burger_pos: Burger centre (m), N×3. burger_rot: Burger→world rotation,
            N×3×3 (burger z = the face that was up at the start).
        spatula_pos, spatula_rot: Actual blade pose (carrying-face centre), N×3 and N×3×3.
        touch_spatula, touch_grill: Burger–blade / burger–grill contact present (N bools).
        force_spatula, force_grill: Summed normal contact force of each pair (N), N.
        burger_diameter, burger_thickness, blade_length, blade_width, grill_height: Geometry
            (m) the judges need.
    """

    t: np.ndarray
    burger_pos: np.ndarray
    burger_rot: np.ndarray
    spatula_pos: np.ndarray
    spatula_rot: np.ndarray
    touch_spatula: np.ndarray
    touch_grill: np.ndarray
    force_spatula: np.ndarray
    force_grill: np.ndarray
    burger_diameter: float
    burger_thickness: float
    blade_length: float
    blade_width: float
    grill_height: float

    @property
    def up_z(self) -> np.ndarray:
        """World z component of the burger's up axis (1 upright, −1 upside down), N."""
        return self.burger_rot[:, 2, 2]

    def in_blade_frame(self) -> np.ndarray:
        """Burger centre in the blade frame (m), N×3."""
        d = self.burger_pos - self.spatula_pos
        return np.einsum("nji,nj->ni", self.spatula_rot, d)

    def blade_gap(self) -> np.ndarray:
        """Height of the burger's lowest point above the blade's carrying face, along the
        blade normal (m), N; negative when it sinks into (or lies under) the blade plane."""
        local = self.in_blade_frame()
        axis_z = np.einsum("ni,ni->n", self.burger_rot[:, :, 2], self.spatula_rot[:, :, 2])
        return local[:, 2] - half_extent(axis_z, self.burger_diameter, self.burger_thickness)

    def grill_clearance(self) -> np.ndarray:
        """Height of the burger's lowest point above the grill surface (m), N."""
        return (self.burger_pos[:, 2] - self.grill_height
                - half_extent(self.up_z, self.burger_diameter, self.burger_thickness))

    def over_blade(self) -> np.ndarray:
        """Burger centre over the blade rectangle and on its carrying side (blade frame), N."""
        local = self.in_blade_frame()
        return ((np.abs(local[:, 0]) <= self.blade_length / 2)
                & (np.abs(local[:, 1]) <= self.blade_width / 2) & (local[:, 2] > 0))

    def on_blade(self) -> np.ndarray:
        """Per sample: touching the blade, or resting on it while the contact flag flickers
        off — a flag-off run of at most :data:`CONTACT_WINDOW` between two contacts, with the
        centre over the blade rectangle and the lowest point within :data:`BLADE_GAP_TOL` of
        the carrying face. N bools. A burger leaving the blade is off from its last contact
        on (the run after it is not bounded by a contact)."""
        resting = self.over_blade() & (np.abs(self.blade_gap()) <= BLADE_GAP_TOL)
        return self.touch_spatula | (_bridge(self.t, self.touch_spatula, CONTACT_WINDOW)
                                     & resting)

    def window(self, time: float, length: float = CONTACT_WINDOW, start: float = -np.inf):
        """Samples in ``(time − length, time]`` and at or after ``start`` (s); at least the
        sample :meth:`index` gives, as a boolean mask of N."""
        k = self.index(time)
        sel = (self.t > self.t[k] - length - 1e-9) & (self.t >= start - 1e-9)
        sel[k + 1:] = False
        sel[k] = True
        return sel

    def index(self, time: float) -> int:
        """Index of the last sample at or before ``time`` (s), clipped to the run."""
        return int(np.clip(np.searchsorted(self.t, time + 1e-9) - 1, 0, len(self.t) - 1))

    def touchdown(self, after: float) -> int | None:
        """Index of the burger's first contact with the grill at or after ``after`` (s), e.g.
        the landing of a flip that starts then; ``None`` if it never touches the grill."""
        hits = np.flatnonzero(self.touch_grill & (self.t >= after - 1e-9))
        return int(hits[0]) if hits.size else None
