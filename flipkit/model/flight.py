"""Ballistic flight of a released burger: landing point, landing tilt, clearance to the blade.

flipkit's addition to the paper's flip (eq. 26), which names no landing. The burger rides the
blade while the contact force presses it onto the blade; at the release node it leaves with
the rigid-body state of its centre — half a burger thickness above the blade centre on the
carrying face — and flies ballistically: gravity acts on the centre, and no torque acts on
the burger, which leaves with the blade's angular velocity ω at release. It lands when its
centre is half a thickness above the grill, which is where a burger lying on its other side
has its centre.

The burger is a solid disc (radius r, thickness h): its moment of inertia about its axis is
I_a = m r²/2 and about a diameter I_t = m (3r² + h²)/12, κ = I_a/I_t = 6r²/(3r² + h²) (1.94
for the default patty). In torque-free motion its angular momentum L = I_t ω + (I_a − I_t)
(ω·n) n is constant and so is ω·n (Euler's equations of a symmetric body), so ω = L/I_t −
(κ − 1)(ω·n) n and ṅ = ω × n = (L/I_t) × n: the axis n turns about the fixed direction of L
at the constant rate |L|/I_t, not about ω. ω is along a principal axis only when the blade
does not turn about its own normal at release; a flip's small turn about the normal still
turns the landed face by degrees from where a rotation about ω would put it.

Release state at the blade pose (p, R), velocity v and angular velocity ω (world frame), the
burger's centre over the blade point b = (b_x, b_y, 0) (the blade centre unless the burger
was measured elsewhere on the blade, e.g. after a scoop that dragged it forward):

    c₀ = p + R (b + (h/2) ẑ),   ċ₀ = v + ω × R (b + (h/2) ẑ),   n₀ = R ẑ  (top-face normal)

Flight, with τ the time since release and g = |gravity| along −z:

    c(τ) = c₀ + ċ₀ τ − ½ g τ² ẑ,   n(τ) = Rot(Ω τ) n₀  (Rodrigues),
    Ω = L/I_t = ω + (κ − 1)(ω·n₀) n₀
    t_f = (ċ₀_z + √(ċ₀_z² + 2 g (c₀_z − z_land))) / g,   z_land = h_g + h/2

Everything is one CasADi SX graph (exact first derivatives by algorithmic differentiation):
:func:`landing_function` gives the landing point, tilt and time of flight,
:func:`clearance_function` the signed clearance of the flying burger from the blade plane at a
later blade pose. Both build a new function; :data:`LANDING` and :data:`FLIGHT_CLEARANCE` are
the ones built when this module loads (a few milliseconds), which every caller shares: a CasADi
function is immutable once built, and calling it allocates its own work memory. Rotation inputs
are perturbed by a small world rotation δ, R(δ) = (I + [δ]×) R, so that a derivative with
respect to δ at δ = 0 chains with pinocchio's angular Jacobian (dR = [J_ω dq]× R).
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from flipkit.config.task import TILT_MIN_DEG  # top-face normal this far from +z at landing
from flipkit.errors import ConfigError

_SMOOTH = 1e-6  # ε in √(x + ε): keeps |ω| and the disc's extent differentiable at 0


def _skew(w):
    return ca.vertcat(ca.horzcat(0, -w[2], w[1]), ca.horzcat(w[2], 0, -w[0]),
                      ca.horzcat(-w[1], w[0], 0))


def _release(p, v, R, w, delta, h, bx, by):
    """Centre, centre velocity and top-face normal at release (SX); the burger's centre
    lies over the blade point (bx, by) of the blade frame."""
    Rd = (ca.SX.eye(3) + _skew(delta)) @ R
    n0 = Rd[:, 2]
    arm = Rd @ ca.vertcat(bx, by, h / 2)
    return p + arm, v + ca.cross(w, arm), n0


def spin_ratio(radius, thickness):
    """κ = I_a/I_t of a solid disc: its moment of inertia about its axis over that about a
    diameter (module docstring); works on numbers and on CasADi expressions."""
    return 6 * radius**2 / (3 * radius**2 + thickness**2)


def _axis_rate(w, n0, radius, thickness):
    """Ω = L/I_t = ω + (κ − 1)(ω·n₀) n₀ (SX): the free disc's axis n turns about Ω."""
    return w + (spin_ratio(radius, thickness) - 1) * ca.dot(w, n0) * n0


def _rotate(n, w, tau):
    """Rot(ω τ) n by Rodrigues' formula, smooth at ω = 0 (SX)."""
    a = ca.sqrt(ca.dot(w, w) + _SMOOTH**2)
    k, th = w / a, a * tau
    return n * ca.cos(th) + ca.cross(k, n) * ca.sin(th) + k * ca.dot(k, n) * (1 - ca.cos(th))


def landing_function() -> ca.Function:
    """A new CasADi function ``(x, R, par) → (y, dy/dx)`` (:data:`LANDING` is one).

    ``x`` = (p, v, δ, ω) (12), ``R`` the 3×3 blade rotation, ``par`` = (h, g, z_land, target x,
    target y, bx, by, r) with (bx, by) where the burger's centre sits on the blade (blade frame,
    m) and r the burger's radius (m). ``y`` = (distance of the landing point from the target
    (m), z of the top-face normal at landing (cos of its angle from +z), time of flight (s),
    landing x, landing y).
    """
    x, R, par = ca.SX.sym("x", 12), ca.SX.sym("R", 3, 3), ca.SX.sym("par", 8)
    p, v, delta, w = x[0:3], x[3:6], x[6:9], x[9:12]
    h, g, z_land = par[0], par[1], par[2]
    c0, cd, n0 = _release(p, v, R, w, delta, h, par[5], par[6])
    tf = (cd[2] + ca.sqrt(cd[2] ** 2 + 2 * g * (c0[2] - z_land))) / g
    land = c0[0:2] + cd[0:2] * tf
    dist = ca.sqrt(ca.sumsqr(land - par[3:5]) + _SMOOTH**2)
    nz = _rotate(n0, _axis_rate(w, n0, par[7], h), tf)[2]
    y = ca.vertcat(dist, nz, tf, land)
    return ca.Function("landing", [x, R, par], [y, ca.jacobian(y, x)])


def clearance_function() -> ca.Function:
    """A new CasADi function ``(x, R_r, R_i, par) → (d, ∂d/∂x)``: clearance of the flying
    burger (:data:`FLIGHT_CLEARANCE` is one).

    ``x`` = (p_r, v_r, δ_r, ω_r, τ, p_i, δ_i) (19): the release state, the time since release
    τ (s) and a blade pose (p_i, R_i) at that time. ``par`` = (h, radius, g, bx, by). ``d`` (m) is the
    height of the burger's lowest point above the blade plane, along the blade normal (on the
    carrying side): (c(τ) − p_i)·n_i − e, with e = r √(1 − (n·n_i)²) + (h/2) |n·n_i| the
    disc's half extent along n_i (smoothed). d ≥ 0 means the blade's plane separates the blade
    from the burger — sufficient for no contact, whatever the blade's outline.
    """
    x = ca.SX.sym("x", 19)
    Rr, Ri, par = ca.SX.sym("Rr", 3, 3), ca.SX.sym("Ri", 3, 3), ca.SX.sym("par", 5)
    h, rad, g = par[0], par[1], par[2]
    c0, cd, n0 = _release(x[0:3], x[3:6], Rr, x[9:12], x[6:9], h, par[3], par[4])
    tau = x[12]
    c = c0 + cd * tau + ca.vertcat(0, 0, -g / 2 * tau**2)
    n = _rotate(n0, _axis_rate(x[9:12], n0, rad, h), tau)
    ni = ((ca.SX.eye(3) + _skew(x[16:19])) @ Ri)[:, 2]
    cos = ca.dot(n, ni)
    extent = rad * ca.sqrt(1 - cos**2 + _SMOOTH) + h / 2 * ca.sqrt(cos**2 + _SMOOTH)
    d = ca.dot(c - x[13:16], ni) - extent
    return ca.Function("clearance", [x, Rr, Ri, par], [d, ca.jacobian(d, x)])


LANDING = landing_function()  # built once, when the module loads (module docstring)
FLIGHT_CLEARANCE = clearance_function()


def gravity_magnitude(gravity) -> float:
    """|g| (m/s²) of a gravity vector along −z, or :class:`ConfigError`."""
    g = np.asarray(gravity, float)
    if g.shape != (3,) or abs(g[0]) > 1e-12 or abs(g[1]) > 1e-12 or not g[2] < 0:
        raise ConfigError(f"the flight model needs gravity along -z, got {g.tolist()}")
    return float(-g[2])


def landing_parameters(thickness: float, grill_height: float, gravity, target=(0.0, 0.0),
                       on_blade=(0.0, 0.0), *, diameter: float) -> list:
    """The ``par`` input of :data:`LANDING`: (h, g, z_land = h_g + h/2, target x,
    target y, bx, by, r = diameter/2) (SI; ``gravity`` the vector, along −z)."""
    return [float(thickness), gravity_magnitude(gravity), grill_height + thickness / 2,
            *np.asarray(target, float)[:2], *np.asarray(on_blade, float)[:2], diameter / 2]


def predict_landing(p, v, R, w, *, thickness: float, diameter: float, grill_height: float,
                    gravity, target=(0.0, 0.0), on_blade=(0.0, 0.0)) -> dict:
    """Landing of a burger (``thickness``, ``diameter``, m) released from the blade state
    (p, R, v, ω) (world, SI), its centre over the blade point ``on_blade`` (x, y) (blade
    frame, m).

    Returns:
        ``point`` (x, y, z of the centre at landing, m), ``offset`` (distance from ``target``,
        m), ``tilt_deg`` (angle of the top-face normal from +z, deg), ``time_of_flight`` (s).
    """
    par = landing_parameters(thickness, grill_height, gravity, target, on_blade,
                             diameter=diameter)
    z_land = par[2]
    x = np.concatenate([p, v, np.zeros(3), w])
    y = np.asarray(LANDING(x, np.asarray(R, float), par)[0])
    y = y.ravel()
    return {"point": [float(y[3]), float(y[4]), float(z_land)], "offset": float(y[0]),
            "tilt_deg": math.degrees(math.acos(float(np.clip(y[1], -1, 1)))),
            "time_of_flight": float(y[2])}


__all__ = ["FLIGHT_CLEARANCE", "LANDING", "TILT_MIN_DEG", "clearance_function",
           "gravity_magnitude", "landing_function", "landing_parameters", "predict_landing",
           "spin_ratio"]
