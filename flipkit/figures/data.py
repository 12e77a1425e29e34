"""What the figures show, computed from plans, NLPs and the contact model (no drawing).

Everything here reads the package's own objects — a :class:`~flipkit.planning.plans.plan_file.Plan`, an
:class:`~flipkit.transcription.nlp.NLP` and its constraint blocks, the cone forms of
:mod:`flipkit.model.contact` — so a figure shows exactly what the planner imposed and the
verifier checked. Units: s, m, rad, m/s² (specific forces, i.e. force per burger mass).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from importlib import resources

import numpy as np

from flipkit.model.contact import CONE_FORMS, make_cone, specific_force
from flipkit.errors import ConfigError
from flipkit.model.robot import SpatulaState


# ------------------------------------------------------------------ plan time series
@dataclass
class PlanSeries:
    """A plan's segments laid end to end on one time axis.

    The first node of every segment after the first is dropped (it repeats the previous
    segment's last (q, q̇) by the chaining constraint (29)), so ``t`` strictly increases.

    Attributes:
        t: Node times (s), from 0. q, qd, qdd, u: Per node (n, nq): rad, rad/s, rad/s², N·m.
        segment: Index of the segment each node belongs to (n,).
        boundaries: Segment edges t_0 = 0 < t_1 < ... < t_K (s).
        names: Segment names (K,).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    u: np.ndarray
    segment: np.ndarray
    boundaries: np.ndarray
    names: list

    @property
    def durations(self) -> dict:
        """Executed duration of each segment (s), by name."""
        return {n: float(b - a) for n, a, b in
                zip(self.names, self.boundaries[:-1], self.boundaries[1:])}


def plan_series(plan) -> PlanSeries:
    """The plan's node samples on one time axis (see :class:`PlanSeries`)."""
    if not plan.segments:
        raise ConfigError("the plan has no segments")
    parts = {k: [] for k in ("t", "q", "qd", "qdd", "u", "segment")}
    t0, edges = 0.0, [0.0]
    for k, seg in enumerate(plan.segments):
        first = 0 if k == 0 else 1
        parts["t"].append(t0 + seg.t[first:])
        for key in ("q", "qd", "qdd", "u"):
            parts[key].append(getattr(seg, key)[first:])
        parts["segment"].append(np.full(seg.t.size - first, k))
        t0 += seg.T
        edges.append(t0)
    out = {k: np.concatenate(v) for k, v in parts.items()}
    return PlanSeries(out["t"], out["q"], out["qd"], out["qdd"], out["u"], out["segment"],
                      np.array(edges), [s.name for s in plan.segments])


def spatula_positions(robot, q) -> np.ndarray:
    """Blade-centre positions p(q) (m), (n, 3), for configurations q (n, nq)."""
    return np.array([robot.position(x) for x in np.asarray(q, dtype=float)])


# ------------------------------------------------------------------ contact along a plan
@dataclass
class ContactSeries:
    """Specific contact force and cone margins at the nodes of the burger-carrying segments.

    Attributes:
        t: Node times on the plan's time axis (s), (n,); a segment's first node repeats
            the previous one's last at the same time (q̈ may jump there).
        segment: Segment index of each node (n,). names: All segment names of the plan.
        boundaries: Segment edges (s), as :class:`PlanSeries`.
        f: Specific contact force f = Rᵀ(a − g) in the spatula frame (m/s²), (n, 3).
        mu: Friction coefficient used.
        margin: Cone margin min(h) per form (m/s² for ``physical``, 1 for ``paper``), by
            form name, (n,) each; positive inside the cone.
        enforced: Whether the planner imposed the cone at the node (its ``cone_nodes``).
    """

    t: np.ndarray
    segment: np.ndarray
    names: list
    boundaries: np.ndarray
    f: np.ndarray
    mu: float
    margin: dict
    enforced: np.ndarray


def contact_series(plan, segments=None, mu: float | None = None) -> ContactSeries:
    """f, cone margins and the enforced-cone mask at every node of ``segments``.

    Args:
        plan: A :class:`~flipkit.planning.plans.plan_file.Plan`.
        segments: Segment names to evaluate (default: those that carry the burger, i.e.
            with cone nodes).
        mu: Friction coefficient (default: the plan's burger μ).
    """
    mu = float(plan.burger["mu"] if mu is None else mu)
    if segments is None:
        segments = [s.name for s in plan.segments if "burger" in s.payload]
    missing = set(segments) - {s.name for s in plan.segments}
    if missing:
        raise ConfigError(f"plan has no segment {sorted(missing)}")
    cones = {form: make_cone(form, mu, plan.gravity) for form in CONE_FORMS}
    cell = plan.cell()
    t0, rows = 0.0, {k: [] for k in ("t", "segment", "f", "enforced")}
    margins = {form: [] for form in CONE_FORMS}
    for k, seg in enumerate(plan.segments):
        if seg.name in segments:
            robot = plan.robot_for(seg, cell)
            for i in range(seg.t.size):
                st = robot.state(seg.q[i], seg.qd[i], seg.qdd[i])
                rows["t"].append(t0 + seg.t[i])
                rows["segment"].append(k)
                rows["f"].append(specific_force(st.R, st.a, plan.gravity))
                rows["enforced"].append(i in seg.cone_nodes)
                for form, cone in cones.items():
                    margins[form].append(cone.margin(st))
        t0 += seg.T
    edges = np.concatenate([[0.0], np.cumsum([s.T for s in plan.segments])])
    return ContactSeries(np.array(rows["t"]), np.array(rows["segment"], int),
                         [s.name for s in plan.segments], edges, np.array(rows["f"]).reshape(-1, 3),
                         mu, {k: np.array(v) for k, v in margins.items()},
                         np.array(rows["enforced"], bool))


# ------------------------------------------------------------------ Hermite–Simpson
@dataclass
class HermiteSimpsonCurves:
    """One variable x (with derivative ẋ) of a segment under Hermite–Simpson collocation.

    On each interval pair [t_{i−1}, t_{i+1}] (i odd) the cubic Hermite interpolant through
    (x, ẋ) at both ends; at its midpoint t_i it has value x̄_i and slope ẋ̄_i. The defects
    are δ_i = x_i − x̄_i (eq. 8) and ξ_i = ẋ_i − ẋ̄_i (eq. 9).

    Attributes:
        t_knots, x_knots, xd_knots: Even nodes (knots): time (s), value, slope.
        t_mid, x_mid, xd_mid: Odd nodes (midpoints): time, value, slope.
        t_dense, x_dense: Interpolant samples, (N/2, samples) each.
        x_mid_interp, xd_mid_interp: x̄_i, ẋ̄_i at the midpoints.
        delta, xi: Defects δ_i and ξ_i at the midpoints.
    """

    t_knots: np.ndarray
    x_knots: np.ndarray
    xd_knots: np.ndarray
    t_mid: np.ndarray
    x_mid: np.ndarray
    xd_mid: np.ndarray
    t_dense: np.ndarray
    x_dense: np.ndarray
    x_mid_interp: np.ndarray
    xd_mid_interp: np.ndarray
    delta: np.ndarray
    xi: np.ndarray

    def interpolant(self, k: int, t) -> np.ndarray:
        """The cubic of interval pair k (0-based) at times t (s)."""
        ta, tb = self.t_knots[k], self.t_knots[k + 1]
        h = tb - ta
        s = (np.asarray(t, dtype=float) - ta) / h
        return ((2 * s**3 - 3 * s**2 + 1) * self.x_knots[k]
                + (s**3 - 2 * s**2 + s) * h * self.xd_knots[k]
                + (-2 * s**3 + 3 * s**2) * self.x_knots[k + 1]
                + (s**3 - s**2) * h * self.xd_knots[k + 1])


def hermite_simpson_curves(t, x, xd, samples: int = 25) -> HermiteSimpsonCurves:
    """Knots, midpoints, cubic interpolants and defects of one variable (see
    :class:`HermiteSimpsonCurves`).

    Args:
        t: Node times (N+1,) (s), N even, evenly spaced.
        x, xd: The variable and its time derivative at the nodes (N+1,).
        samples: Interpolant samples per interval pair.
    """
    t, x, xd = (np.asarray(v, dtype=float) for v in (t, x, xd))
    n = t.size
    if n < 3 or n % 2 == 0 or x.shape != (n,) or xd.shape != (n,):
        raise ConfigError(f"need N+1 node times with N even and x, xd of the same length, "
                          f"got {n}, {x.shape}, {xd.shape}")
    a, m, b = np.arange(0, n - 2, 2), np.arange(1, n - 1, 2), np.arange(2, n, 2)
    h = t[b] - t[a]
    s = np.linspace(0.0, 1.0, samples)
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
    x_dense = (np.outer(x[a], h00) + np.outer(h * xd[a], h10) + np.outer(x[b], h01)
               + np.outer(h * xd[b], h11))
    t_dense = t[a][:, None] + np.outer(h, s)
    x_bar = (x[a] + x[b]) / 2 + h * (xd[a] - xd[b]) / 8
    xd_bar = 3 * (x[b] - x[a]) / (2 * h) - (xd[a] + xd[b]) / 4
    return HermiteSimpsonCurves(t[::2], x[::2], xd[::2], t[m], x[m], xd[m], t_dense, x_dense,
                                x_bar, xd_bar, x[m] - x_bar, xd[m] - xd_bar)


def defect_magnitudes(nlp, x) -> dict:
    """Largest Hermite–Simpson defect of each interval pair, read from the NLP's own
    ``hermite_simpson`` constraint block at the point ``x``.

    The block holds, per midpoint i and for x ∈ {q, q̇}, the interpolation defect δ_i (eq. 8)
    and the Simpson defect σ_i = −(2Δt_i/3) ξ_i (see
    :class:`~flipkit.transcription.constraints.HermiteSimpson`); the slope defect ξ_i of eq. (9) is
    recovered from σ_i.

    Returns:
        ``t_mid`` (N/2,) midpoint times (s) and, each (N/2,), the largest |·| over joints of
        ``delta_q`` (rad), ``xi_q`` (rad/s), ``delta_qd`` (rad/s), ``xi_qd`` (rad/s²), and
        ``all``, the largest of the four in the solver's units of each.
    """
    L = nlp.layout
    x = np.asarray(x, dtype=float)
    c = nlp.constraints(x)[nlp.block_slices["hermite_simpson"]]
    # Row order of HermiteSimpson: per odd node, for x in (q, q̇): δ (nq rows), σ (nq rows).
    v = np.abs(c.reshape(L.N // 2, 2, 2, L.nq)).max(axis=3)
    T = float(x[L.T_index])
    dt = 2 * T / L.N
    out = {"t_mid": L.s[1::2] * T, "delta_q": v[:, 0, 0], "xi_q": 1.5 * v[:, 0, 1] / dt,
           "delta_qd": v[:, 1, 0], "xi_qd": 1.5 * v[:, 1, 1] / dt}
    out["all"] = np.max([out[k] for k in ("delta_q", "xi_q", "delta_qd", "xi_qd")], axis=0)
    return out


# ------------------------------------------------------------------ cone forms
CONE_CLASSES = ("both", "physical only", "paper only", "neither")


def _state(R, a) -> SpatulaState:
    """A :class:`SpatulaState` with rotation R and acceleration a, zero Jacobians (for
    evaluating cone values only)."""
    z3, z36 = np.zeros(3), np.zeros((3, 6))
    return SpatulaState(p=z3, R=np.asarray(R, float), v=z3, a=np.asarray(a, float), dp_dq=z36,
                        Jw=z36, dv_dq=z36, dv_dqd=z36, da_dq=z36, da_dqd=z36, da_dqdd=z36)


def pitch_matrix(theta: float) -> np.ndarray:
    """Rotation R_y(θ) (spatula pitched by θ rad about world y; o = (0, θ, 0))."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def printed_paper_cone(R, a, mu: float) -> float:
    """Eq. (20) exactly as printed: ⟨F_n, a/|a|⟩ − cos μ, with a the spatula's own
    acceleration (gravity left out); NaN at rest (|a| = 0), where it is undefined."""
    a = np.asarray(a, dtype=float)
    na = np.linalg.norm(a)
    if na == 0:
        return float("nan")
    return float(np.asarray(R)[:, 2] @ a / na - np.cos(mu))


def cone_region_grid(tilts, accels, mu: float, gravity=(0.0, 0.0, -9.81),
                     lateral: float = 0.0) -> dict:
    """Which cone forms admit a spatula pitched by θ and accelerating horizontally.

    For every tilt θ (rad, about world y, tip down for θ > 0) and horizontal acceleration
    a_x (m/s², along world x) — plus ``lateral`` a_y (m/s²) — the margins of the physical
    cone (5) and the paper's cone (20) as implemented in :mod:`flipkit.model.contact` (with the
    contact force w = a − g), and of (20) as printed (with a alone).

    Returns:
        ``physical``, ``paper``, ``printed``: margins, (len(tilts), len(accels)) each
        (m/s², 1, 1); ``category``: index into :data:`CONE_CLASSES` comparing ``physical``
        and ``paper`` (0 both admit, 1 only physical, 2 only paper, 3 neither).
    """
    cones = {form: make_cone(form, mu, gravity) for form in CONE_FORMS}
    tilts, accels = np.asarray(tilts, float), np.asarray(accels, float)
    out = {k: np.empty((tilts.size, accels.size)) for k in ("physical", "paper", "printed")}
    for i, th in enumerate(tilts):
        R = pitch_matrix(th)
        for j, ax in enumerate(accels):
            a = np.array([ax, lateral, 0.0])
            st = _state(R, a)
            out["physical"][i, j] = cones["physical"].margin(st)
            out["paper"][i, j] = cones["paper"].margin(st)
            out["printed"][i, j] = printed_paper_cone(R, a, mu)
    phys, pap = out["physical"] >= 0, out["paper"] >= 0
    out["category"] = np.select([phys & pap, phys & ~pap, ~phys & pap], [0, 1, 2], 3)
    return out


def tangential_boundaries(mu: float, n: int = 361) -> dict:
    """The two cones' cross-sections in the plane of tangential-to-normal force ratios
    (f_x/f_z, f_y/f_z): the physical pyramid's square |·| ≤ μ and the paper's circle of radius
    tan μ (half-angle μ rad about the normal).

    Returns:
        ``square`` (5, 2) closed corner list, ``circle`` (n, 2), and the half-angles (rad)
        along an axis (``physical_axis`` = atan μ, ``paper`` = μ) and along a diagonal
        (``physical_diagonal`` = atan(μ√2)).
    """
    ang = np.linspace(0, 2 * np.pi, n)
    r = np.tan(mu)
    return {"square": mu * np.array([[1, 1], [-1, 1], [-1, -1], [1, -1], [1, 1]], float),
            "circle": np.column_stack([r * np.cos(ang), r * np.sin(ang)]),
            "physical_axis": float(np.arctan(mu)), "physical_diagonal":
                float(np.arctan(mu * np.sqrt(2))), "paper": float(mu)}


# ------------------------------------------------------------------ the paper's Table I
PAPER_TABLE1 = "paper_table1.csv"  # in flipkit/data (package data)


def paper_table1() -> list[dict]:
    """The paper's Table I (real robot): per location ``location`` (m, as printed, row 2's
    z read as 0.073), ``scoop``, ``pickup``, ``flip`` successes and ``trials`` (10 each).

    Read from the package copy of ``data/paper_table1.csv`` (a clean transcription).
    """
    text = resources.files("flipkit").joinpath("data", PAPER_TABLE1).read_text()
    rows = csv.DictReader(line for line in text.splitlines() if not line.startswith("#"))
    return [{"location": (float(r["px"]), float(r["py"]), float(r["pz"])),
             **{k: int(r[k]) for k in ("scoop", "pickup", "flip", "trials")}} for r in rows]


# ------------------------------------------------------------------ landing points
SUCCESS_TOL = 0.05  # m: the paper's flip test, the burger lands within 5 cm in x and in y


def landing_points(report: dict, targets_xy) -> dict:
    """The flips of a :func:`flipkit.experiments.trials.validate` report that reached the flight
    (scoop and pickup succeeded), with their target.

    Args:
        report: A validate report (``locations[k]["landings"]`` and ``failures``).
        targets_xy: Landing target (x, y) (m) of each location, in the report's order.

    Returns:
        Arrays over those trials: ``location`` (index), ``target``, ``xy`` (final burger
        position), ``predicted`` (the executed plan's predicted landing point; NaN without
        one) (m, k×2), ``flipped`` (the paper's judge); and ``reached``/``trials`` counts.
    """
    rows = []
    for k, (entry, target) in enumerate(zip(report["locations"], targets_xy)):
        early = {f["trial"] for f in entry["failures"] if f["stage"] in ("scoop", "pickup")}
        for land in entry["landings"]:
            if land["trial"] in early or land["xy"] is None:
                continue
            pred = land["predicted_xy"] if land["predicted_xy"] is not None else [np.nan] * 2
            rows.append((k, target, land["xy"], pred, bool(land["flipped"])))
    n = len(rows)
    return {"location": np.array([r[0] for r in rows], int),
            "target": np.array([r[1] for r in rows], float).reshape(n, 2),
            "xy": np.array([r[2] for r in rows], float).reshape(n, 2),
            "predicted": np.array([r[3] for r in rows], float).reshape(n, 2),
            "flipped": np.array([r[4] for r in rows], bool), "reached": n,
            "trials": sum(e["trials"] for e in report["locations"])}


def scenario_landings(plans) -> np.ndarray:
    """Planned landing points (x, y) (m) of every robust scenario of the flips of ``plans``
    (``landing["scenarios"]`` of each flip segment), k×2; empty without scenarios."""
    rows = [row["point"][:2] for plan in plans for seg in plan.segments
            if seg.name == "flip" and seg.landing for row in seg.landing.get("scenarios", ())]
    return np.array(rows, float).reshape(-1, 2)


def landing_summary(points: dict, tol: float = SUCCESS_TOL) -> dict:
    """Counts and medians of :func:`landing_points`: ``within_tol_xy`` (|Δx|, |Δy| ≤ tol,
    the paper's test), ``within_tol_radius`` (distance ≤ tol), ``flipped``, ``reached``,
    ``median_target_distance_m`` (simulated landing to target) and
    ``median_prediction_error_m`` (|simulated − predicted|) (m; None without trials)."""
    d = points["xy"] - points["target"]
    dist = np.hypot(d[:, 0], d[:, 1])
    err = np.hypot(*(points["xy"] - points["predicted"]).T)
    err = err[np.isfinite(err)]
    return {"reached": int(points["reached"]), "trials": int(points["trials"]),
            "flipped": int(points["flipped"].sum()),
            "within_tol_xy": int(np.sum(np.all(np.abs(d) <= tol, axis=1))),
            "within_tol_radius": int(np.sum(dist <= tol)),
            "median_target_distance_m": float(np.median(dist)) if dist.size else None,
            "median_prediction_error_m": float(np.median(err)) if err.size else None}


__all__ = ["PlanSeries", "plan_series", "spatula_positions", "ContactSeries", "contact_series",
           "HermiteSimpsonCurves", "hermite_simpson_curves", "defect_magnitudes",
           "CONE_CLASSES", "pitch_matrix", "printed_paper_cone", "cone_region_grid",
           "tangential_boundaries", "PAPER_TABLE1", "paper_table1", "SUCCESS_TOL",
           "landing_points", "landing_summary"]
