"""Where a scoop leaves the burger on the blade: a friction model of the scoop.

Why the burger ends up ahead of the blade centre. The scoop slides the blade along the grill
under the burger and stops with its centre under p^b. While the tip advances under the patty,
the patty's weight is shared between the blade and the grill. The blade's face drags the
patty forward with friction μ_b·f·m·g (f the share on the blade); the grill holds it back
with up to μ_g·(1 − f)·m·g. At first the grill wins and the blade slides under a still patty.
Once μ_b·f > μ_g·(1 − f) the patty starts to move, but it must be accelerated to the blade's
speed by friction alone, at most (μ_b·f − μ_g·(1 − f))·g, so it keeps slipping back over the
blade for v²/(2a) (centimetres at a scoop's 0.5 m/s) before it rides with it. From then on
it travels with the blade, and the rest of the scoop carries it past p^b. The patty ends
ahead of the blade centre by (l/2) − (how far the tip had passed its centre when it
stuck), so by a few centimetres; the faster the scoop, the later it sticks and the smaller
the offset. When the blade brakes to rest faster than μ_b·g, the patty slides on toward the
tip, which the model also follows.

The model (no parameter fitted to a trial): one dimension along the blade's heading at the
end of the scoop; the blade tip's path from the planned scoop (q, q̇ through a cubic Hermite
spline); the share f is the fraction of the patty's footprint (a disc of diameter d) over
the blade, [tip − l, tip], while the tip is low enough to slip under the patty's rounded rim
(within ``rim`` of the grill), else 0; Coulomb friction with one coefficient per pair
(static = kinetic), μ_b = ``burger.mu`` on the blade and μ_g = ``physics.mu_grill`` on the
grill; semi-implicit time steps of :data:`STEP_S` with the stick-slip transitions resolved
within a step. Sideways (blade y) the patty is not moved: its offset is where p^b lies from
the final blade centre.

The patty's overhang. Where the tip has slipped under the patty and lifts it by δ (the
height of the blade's top face above the grill), the part of the patty beyond the tip does
not fall onto the grill at once: as a heavy beam (bending stiffness E I, weight q per
length) lifted by δ at the tip it lies clear of the grill over ℓ = (24 E I δ / q)^¼, and the
tip carries q ℓ / 2 of it, as if the blade's footprint reached ℓ / 2 beyond the tip
(:func:`overhang_share`; for a patty of thickness h and density ρ, ℓ = (2 E h² δ / (ρ g))^¼,
2.0 cm for 15 mm of 50 kPa patty lifted by a 1 mm blade). δ lies between 0 (the blade's top
face flush with the grill, the tip sunk into it) and the blade's thickness (the blade resting
on the grill); which it is depends on how the arm presses the blade and how the blade and
grill yield, which the model does not know, so ``outcome`` takes the overhang as a parameter
and the planner spans its range (:func:`~flipkit.behaviors.pick.scoop_scenarios`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from flipkit.errors import ConfigError

# s: integration step of the friction model. Stick-slip transitions are resolved within a step,
# so the step only sets how finely the blade's speed is sampled: a finer step moves the
# outcome by a fraction of a millimetre (docs/history.md).
STEP_S = 1e-3
GRAVITY = 9.81  # m/s²


def footprint_share(centre: float, radius: float, lo: float, hi: float) -> float:
    """Fraction of a disc's area (centre, radius along the axis, m) within lo ≤ x ≤ hi."""
    def below(x):
        u = min(max((x - centre) / radius, -1.0), 1.0)
        return (math.asin(u) + u * math.sqrt(1.0 - u * u)) / math.pi + 0.5
    return max(below(hi) - below(lo), 0.0)


def overhang_share(modulus: float, thickness: float, density: float, lift: float) -> float:
    """How far beyond the tip (m) the blade carries a patty it lifts by ``lift`` (m): half the
    length ℓ = (2 E h² δ / (ρ g))^¼ over which the patty's overhang, a heavy beam of modulus
    ``modulus`` (Pa), thickness ``thickness`` (m) and density ``density`` (kg/m³), lies clear
    of the grill (module docstring); 0 for ``lift`` = 0."""
    for name, v in (("modulus", modulus), ("thickness", thickness), ("density", density)):
        if not (np.isfinite(v) and v > 0):
            raise ConfigError(f"scoop model: {name} must be positive, got {v!r}")
    if not (np.isfinite(lift) and lift >= 0):
        raise ConfigError(f"scoop model: lift must be >= 0 m, got {lift!r}")
    return 0.5 * (2.0 * modulus * thickness**2 * lift / (density * GRAVITY)) ** 0.25


def _sign(x: float) -> float:
    return (x > 0) - (x < 0)


def _step(xb, vb, vt0, vt1, f, mu_b, mu_g, dt):
    """One step of the patty (position xb, speed vb, m and m/s) under blade speed vt0 → vt1."""
    g, sign = GRAVITY, _sign
    if abs(vb - vt0) < 1e-9 and abs(vb) > 1e-9:  # riding the blade: can friction keep it?
        need = (vt1 - vt0) / dt + mu_g * g * (1 - f) * sign(vb)
        if abs(need) <= mu_b * g * f:
            return xb + vt1 * dt, vt1
    if abs(vb) < 1e-9:  # at rest on the grill: does the blade's drag overcome the grill?
        push = mu_b * g * f * sign(vt0 - vb)
        if abs(push) <= mu_g * g * (1 - f):
            return xb, 0.0
        a = push - mu_g * g * (1 - f) * sign(push)
    else:
        a = mu_b * g * f * sign(vt0 - vb) - mu_g * g * (1 - f) * sign(vb)
    v = vb + a * dt
    if (vb - vt0) * (v - vt1) < 0:  # caught up with the blade within the step
        v = vt1
    if vb * v < 0:  # friction stops the patty; it does not reverse it
        v = 0.0
    return xb + v * dt, v


class ScoopPath:
    """The blade tip's path in a planned scoop, along the heading the scoop ends with.

    Args:
        robot: :class:`~flipkit.model.robot.Robot` (blade pose ``placement``).
        t, q, qd: The scoop's node times (s), joint positions (rad) and velocities (rad/s).
        location: p^b, where the patty lies before the scoop (m, world).
        grill_height: h_g (m).

    Raises:
        ConfigError: Fewer than two increasing node times.
    """

    def __init__(self, robot, t, q, qd, location, *, grill_height: float):
        t, q, qd = (np.asarray(a, float) for a in (t, q, qd))
        if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0):
            raise ConfigError("scoop model: need at least two increasing node times")
        self.length = robot.cell.spatula.length
        self.t = np.append(np.arange(t[0], t[-1], STEP_S), t[-1])
        poses = [robot.placement(x) for x in CubicHermiteSpline(t, q, qd, axis=0)(self.t)]
        end = poses[-1]
        self.heading = end.rotation[:2, 0] / np.linalg.norm(end.rotation[:2, 0])
        self.side = np.array([-self.heading[1], self.heading[0]])  # blade y when flat
        pb = np.asarray(location, float)
        tips = np.array([m.translation + m.rotation[:, 0] * self.length / 2 for m in poses])
        self.tip = (tips[:, :2] - pb[:2]) @ self.heading  # along the heading, from p^b (m)
        self.tip_height = tips[:, 2] - grill_height
        self.speed = np.gradient(self.tip, self.t)
        self.end = end.translation[:2] - pb[:2]  # final blade centre from p^b (m)

    def outcome(self, *, diameter: float, mu_blade: float, mu_grill: float, rim: float,
                shift=(0.0, 0.0), overhang: float = 0.0) -> np.ndarray:
        """The patty's centre on the blade (x, y) (m, blade frame) when the scoop ends.

        Args:
            diameter: Patty diameter d (m). mu_blade, mu_grill: Patty-blade and patty-grill
                friction coefficients.
            rim: Height (m) above the grill below which the tip slips under the patty's rim
                (the rim's rounding radius).
            shift: The patty lying off p^b by (along the heading, sideways) (m).
            overhang: How far beyond the tip the blade carries the patty (m,
                :func:`overhang_share`); 0: only what lies over the blade.

        Raises:
            ConfigError: Non-finite or non-positive parameters.
        """
        for name, v in (("diameter", diameter), ("mu_blade", mu_blade),
                        ("mu_grill", mu_grill), ("rim", rim)):
            if not (np.isfinite(v) and v > 0):
                raise ConfigError(f"scoop model: {name} must be positive, got {v!r}")
        if not (np.isfinite(overhang) and overhang >= 0):
            raise ConfigError(f"scoop model: overhang must be >= 0 m, got {overhang!r}")
        along, aside = (float(v) for v in shift)
        xb, vb, radius, low = along, 0.0, diameter / 2, self.tip_height <= rim
        t, tip, speed = self.t.tolist(), self.tip.tolist(), self.speed.tolist()
        length, low = self.length, low.tolist()
        for k in range(len(t) - 1):
            f = (footprint_share(xb, radius, tip[k] - length, tip[k] + overhang) if low[k]
                 else 0.0)
            if f == 0.0 and vb == 0.0:  # off the blade and at rest: nothing moves it
                continue
            xb, vb = _step(xb, vb, speed[k], speed[k + 1], f, mu_blade, mu_grill,
                           t[k + 1] - t[k])
        centre = xb * self.heading + aside * self.side - self.end
        return np.array([centre @ self.heading, centre @ self.side])


__all__ = ["STEP_S", "ScoopPath", "footprint_share", "overhang_share"]
