"""Independent check of a flip's release, flight and landing, from the plan's arrays alone.

Nothing here uses :mod:`flipkit.model.flight` or the NLP's blocks. The release state comes from
pinocchio (:class:`~flipkit.model.robot.Robot` rebuilt from the plan file) at the recorded release
node; the flight is integrated numerically (``scipy.integrate.solve_ivp`` on the centre's
ballistic ODE with a ground event, together with the attitude of a free solid disc, Ṙ = [ω]× R
with ω = R I⁻¹ Rᵀ L and the angular momentum L fixed by the blade's ω at release); the
blade–burger clearance after the release is a distance
query between the blade (a box of the spatula's length, width and thickness under its
carrying face) and the burger (a cylinder) with coal, the collision library shipped with
pinocchio.

Rows of group ``landing``: the target's distance outside the grill area (m), ``r_land``
outside :data:`~flipkit.config.task.R_LAND_RANGE` (m), the recomputed landing offset beyond
``r_land`` (m), the tilt
short of :data:`~flipkit.config.task.TILT_MIN_DEG` (deg), and the recorded prediction against
the recomputed one (point m, tilt deg, time of flight s; tolerances :data:`LANDING_TOL`).
Group ``landing_scenarios`` (robust flips): the same rows for every recorded scenario of the
burger's place on the blade, each against its own ``r_land`` (which lies in [r_land,
R_LAND_RANGE[1]]). Group
``flight_clearance``: penetration depth (m) of the blade into the flying burger at the nodes
after the release.
"""

from __future__ import annotations

import math

import coal
import numpy as np
from scipy.integrate import solve_ivp

# the task's bounds; the check itself is this module's own
from flipkit.config.task import R_LAND_RANGE, TILT_MIN_DEG
from flipkit.model.collision import pin_box_support

LANDING_TOL = {"m": R_LAND_RANGE[0], "deg": 1e-2, "s": 1e-4}  # the smallest r_land: 0.1 mm


def _disc_inertia(cell) -> np.ndarray:
    """Principal moments (per unit mass, m²) of the burger as a solid disc, axis last."""
    r, h = cell.burger.diameter / 2, cell.burger.thickness
    return np.array([(3 * r * r + h * h) / 12, (3 * r * r + h * h) / 12, r * r / 2])


def _attitude(R: np.ndarray) -> np.ndarray:
    """The rotation nearest to the integrated 3×3 R (its polar factor)."""
    u, _, vt = np.linalg.svd(R)
    return u @ vt


def recompute_landing(robot, seg, cell, on_blade=None) -> dict | None:
    """Release state and ballistic landing of ``seg``'s burger; ``None`` without a release.

    ``on_blade``: the burger's centre on the blade (x, y) (m); default the one recorded in
    ``seg.landing``.

    Returns:
        ``c0``, ``v0`` (centre and its velocity at release, m, m/s), ``w`` (rad/s), ``R0``
        (burger attitude at release), ``point`` (m), ``tilt_deg``, ``time_of_flight`` (s),
        ``attitude`` (a function of the time since release, s: the burger's rotation).
    """
    if not seg.release:
        return None
    r = seg.release["node"]
    st = robot.state(seg.q[r], seg.qd[r], seg.qdd[r])
    _, _, _, Jw = robot.pose_jacobians(seg.q[r])
    w = Jw @ seg.qd[r]
    h, g = cell.burger.thickness, np.asarray(cell.gravity, float)
    bx, by = ((seg.landing or {}).get("burger_on_blade", (0.0, 0.0)) if on_blade is None
              else on_blade)
    arm = st.R @ np.array([bx, by, h / 2])
    c0, v0 = st.p + arm, st.v + np.cross(w, arm)
    z_land = cell.grill.height + h / 2

    inertia = _disc_inertia(cell)  # the burger's axes are the blade's at release
    L = st.R @ (inertia * (st.R.T @ w))  # angular momentum per unit mass, fixed in flight

    def flight(_, y):
        R = y[6:].reshape(3, 3)
        omega = R @ ((R.T @ L) / inertia)
        return np.concatenate([y[3:6], g, np.cross(omega, R.T).T.ravel()])

    def ground(_, y):
        return y[2] - z_land

    ground.terminal, ground.direction = True, -1
    sol = solve_ivp(flight, (0.0, 10.0), np.concatenate([c0, v0, st.R.ravel()]), events=ground,
                    rtol=1e-10, atol=1e-12, dense_output=True, method="DOP853")
    if not sol.t_events[0].size:
        return None
    tf = float(sol.t_events[0][0])
    n = _attitude(sol.y_events[0][0][6:].reshape(3, 3))[:, 2]
    return {"c0": c0, "v0": v0, "w": w, "R0": st.R, "point": sol.y_events[0][0][:3],
            "tilt_deg": math.degrees(math.acos(float(np.clip(n[2], -1.0, 1.0)))),
            "time_of_flight": tf,
            "attitude": lambda tau: _attitude(sol.sol(min(tau, tf))[6:].reshape(3, 3))}


def blade_burger_distance(blade_pose, burger_pose, cell) -> float:
    """coal distance (m) between the blade box and the burger cylinder (negative: overlap
    depth as coal reports it). Poses are (p, R) in the world."""

    pin_box_support()  # coal's box support state, the same in every process
    sp, bg = cell.spatula, cell.burger
    blade = coal.Box(sp.length, sp.width, sp.thickness)
    burger = coal.Cylinder(bg.diameter / 2, bg.thickness)
    (pb, Rb), (pc, Rc) = blade_pose, burger_pose
    tb = coal.Transform3s(np.asarray(Rb), np.asarray(pb) - np.asarray(Rb)[:, 2] * sp.thickness / 2)
    tc = coal.Transform3s(np.asarray(Rc), np.asarray(pc))
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    return float(coal.distance(blade, tb, burger, tc, req, res))


def check_flight(report, k, seg, robot, cell, states) -> None:
    """Add the ``landing`` and ``flight_clearance`` rows of flip segment k to ``report``."""
    add, tol = report.add, LANDING_TOL
    rec = seg.landing
    pred = recompute_landing(robot, seg, cell)
    if rec is None or pred is None:  # no release recorded, or a burger that never comes down
        add("landing", k, [math.inf], tol["m"], seg.release["node"] if seg.release else None)
        return
    r = seg.release["node"]
    g, (lo, hi) = cell.grill, R_LAND_RANGE
    target = np.asarray(rec["target"], float)  # on the grill, the disc within the range
    add("landing", k, np.maximum(np.concatenate([np.array([g.x_range[0], g.y_range[0]]) - target,
                                                 target - np.array([g.x_range[1], g.y_range[1]])]),
                                 0.0), tol["m"], r)
    add("landing", k, [max(lo - rec["r_land"], rec["r_land"] - hi, 0.0)], tol["m"], r)
    offset = float(np.linalg.norm(pred["point"][:2] - target))
    add("landing", k, [max(offset - rec["r_land"], 0.0)], tol["m"], r)
    add("landing", k, [max(TILT_MIN_DEG - pred["tilt_deg"], 0.0)], tol["deg"], r)
    add("landing", k, np.abs(pred["point"] - np.asarray(rec["point"])), tol["m"], r)
    add("landing", k, [abs(pred["tilt_deg"] - rec["tilt_deg"])], tol["deg"], r)
    add("landing", k, [abs(pred["time_of_flight"] - rec["time_of_flight"])], tol["s"], r)
    add("landing", k, [abs(seg.release["time"] - seg.t[r])], tol["s"], r)
    for row in rec.get("scenarios", ()):  # a robust flip: every scenario lands too
        alt = recompute_landing(robot, seg, cell, row["burger_on_blade"])
        if alt is None:
            add("landing_scenarios", k, [math.inf], tol["m"], r)
            continue
        add("landing_scenarios", k, [max(rec["r_land"] - row["r_land"], row["r_land"] - hi, 0.0)],
            tol["m"], r)
        miss = float(np.linalg.norm(alt["point"][:2] - target))
        add("landing_scenarios", k, [max(miss - row["r_land"], 0.0)], tol["m"], r)
        add("landing_scenarios", k, [max(TILT_MIN_DEG - alt["tilt_deg"], 0.0)], tol["deg"], r)
        add("landing_scenarios", k, np.abs(alt["point"] - np.asarray(row["point"])), tol["m"], r)
        add("landing_scenarios", k, [abs(alt["time_of_flight"] - row["time_of_flight"])],
            tol["s"], r)
    for i in range(r + 1, seg.N + 1):
        tau = seg.t[i] - seg.t[r]
        c = pred["c0"] + pred["v0"] * tau + 0.5 * np.asarray(cell.gravity) * tau**2
        Rc = pred["attitude"](tau)
        d = blade_burger_distance((states[i].p, states[i].R), (c, Rc), cell)
        add("flight_clearance", k, [max(-d, 0.0)], tol["m"], i)
