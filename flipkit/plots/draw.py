"""Axes-level drawing for the figure notebooks: each function draws into axes it is given
and returns what it drew (numbers for captions); figure size, style and saving stay with the
caller (:func:`flipkit.figures.style`, :func:`flipkit.figures.save`).

Colours follow the paper where it names them (Figs. 6–7: desired red, actual blue) and the
Okabe–Ito palette of :data:`flipkit.figures.COLORS` elsewhere.
"""

from __future__ import annotations

import numpy as np

from ..errors import ConfigError
from ..plotting import draw_cell, shade_segments
from .data import CONE_CLASSES

DESIRED_COLOR, ACTUAL_COLOR = "#D55E00", "#0072B2"  # paper Figs. 6-7: desired red, actual blue
SOLVER_COLORS = {"sqp": "#0072B2", "ipopt": "#E69F00"}
SOLVER_LABELS = {"sqp": "SQP (cvxpy/OSQP)", "ipopt": "IPOPT (L-BFGS, MUMPS)"}
BURGER_COLOR = "#8B4513"
# both admit, physical only, paper only, neither
CONE_CLASS_COLORS = ("#CFE8D8", "#0072B2", "#D55E00", "white")


def plot_tracking(axes, t, p_des, p, boundaries=None, names=None, points=None,
                  xlabel: bool = True) -> dict:
    """Desired vs tracked spatula position, one axes per coordinate (x, y, z).

    Args:
        axes: Three 2D axes (x, y, z), sharing the time axis.
        t: Sample times (s), (n,).
        p_des, p: Desired and tracked blade-centre positions (m), (n, 3).
        boundaries, names: Segment edges (s) and names to shade (optional, both or neither).
        points: Optional (times (k,), positions (k, 3)) of key points, marked on the desired.
        xlabel: Label the time axis of the last axes (off when another panel below has it).

    Returns:
        ``max_error_m`` and ``rms_error_m`` of |p − p_des| (3D), and per axis
        ``max_abs_error_m`` (3,).
    """
    t, p_des, p = (np.asarray(v, dtype=float) for v in (t, p_des, p))
    if len(axes) != 3 or p.shape != p_des.shape or p.shape != (t.size, 3):
        raise ConfigError("need three axes and (n, 3) positions matching n times")
    for k, (ax, label) in enumerate(zip(axes, "xyz")):
        if boundaries is not None:
            shade_segments(ax, boundaries, names)
        # desired wide and pale underneath, tracked thin on top: both stay visible when
        # they coincide to within a line width
        ax.plot(t, p_des[:, k], color=DESIRED_COLOR, lw=3.0, alpha=0.45, solid_capstyle="butt",
                label="desired (plan)")
        ax.plot(t, p[:, k], color=ACTUAL_COLOR, lw=0.9, label="tracked (simulated PD)")
        if points is not None:
            ax.plot(points[0], np.asarray(points[1])[:, k], "o", color=DESIRED_COLOR, ms=3,
                    mfc="white", label="key point", zorder=5)
        ax.set_ylabel(f"$p_{label}$ (m)")
        lo, hi = min(p_des[:, k].min(), p[:, k].min()), max(p_des[:, k].max(), p[:, k].max())
        pad = max(0.15 * (hi - lo), 0.01)
        ax.set_ylim(lo - pad, hi + 2.2 * pad)  # room for the segment names at the top
    if xlabel:
        axes[-1].set_xlabel("time (s)")
    err = np.linalg.norm(p - p_des, axis=1)
    return {"max_error_m": float(err.max()), "rms_error_m": float(np.sqrt(np.mean(err**2))),
            "max_abs_error_m": np.abs(p - p_des).max(axis=0)}


def plot_tracking_error(ax, t, p_des, p, boundaries=None, names=None) -> None:
    """|p − p_des| (mm) against time, with the segments shaded."""
    err = np.linalg.norm(np.asarray(p, float) - np.asarray(p_des, float), axis=1)
    if boundaries is not None:
        shade_segments(ax, boundaries, names)
    ax.plot(t, 1e3 * err, color=ACTUAL_COLOR, lw=1.0)
    ax.set_ylabel("|error| (mm)")
    ax.set_ylim(0, 1e3 * err.max() * 1.35 + 1e-3)
    ax.set_xlabel("time (s)")


def shade_nodes(ax, t, mask, segment=None, color: str = "#56B4E9", alpha: float = 0.22,
                label=None) -> None:
    """Shade the time spans of runs of consecutive nodes where ``mask`` holds: each run from
    half a node spacing before its first node to half a spacing after its last, clipped to
    its segment (runs do not cross segments when ``segment`` labels are given)."""
    t, mask = np.asarray(t, float), np.asarray(mask, bool)
    seg = np.zeros(t.size, int) if segment is None else np.asarray(segment)
    first = True
    for k in np.unique(seg):
        idx = np.flatnonzero(seg == k)
        ts, ms = t[idx], mask[idx]
        half = 0.5 * np.min(np.diff(ts)) if ts.size > 1 else 0.0
        run_start = None
        for i in range(ts.size + 1):
            on = i < ts.size and ms[i]
            if on and run_start is None:
                run_start = i
            elif not on and run_start is not None:
                lo = max(ts[run_start] - half, ts[0])
                hi = min(ts[i - 1] + half, ts[-1])
                ax.axvspan(lo, hi, color=color, alpha=alpha, lw=0, zorder=0,
                           label=label if first else None)
                first, run_start = False, None


def plot_forces(axes, cs) -> dict:
    """The specific contact force and the cone margins along a plan (paper Fig. 3).

    Axes, top to bottom: f_z (normal), |f_x|, |f_y| (tangential) and μ f_z, in m/s² (force
    per burger mass); the physical cone margin min(f_z, μf_z − |f_x|, μf_z − |f_y|) (m/s²);
    optionally (a third axes) the margin of the paper's form (20), ⟨F_n, ŵ⟩ − cos μ.
    Nodes where the planner enforced the cone are shaded; lines break between segments.

    Args:
        axes: Two or three 2D axes sharing the time axis.
        cs: A :class:`~flipkit.plots.data.ContactSeries`.

    Returns:
        ``min_margin_enforced`` (m/s²), ``min_fz`` (m/s²), ``max_tangential_ratio`` (max of
        max(|f_x|, |f_y|)/f_z over enforced nodes), ``n_enforced``, ``n_nodes``,
        ``violated_unenforced`` (nodes outside the physical cone among those not enforced)
        and ``min_paper_margin_enforced`` (1).
    """
    f, margin = cs.f, cs.margin["physical"]
    ks = np.unique(cs.segment)
    lo_k, hi_k = int(ks.min()), int(ks.max())
    edges = cs.boundaries[lo_k:hi_k + 2]
    names = cs.names[lo_k:hi_k + 1]
    for n, ax in enumerate(axes):
        shade_segments(ax, edges, names, color="none", label_y=0.99)
        for edge in edges[1:-1]:
            ax.axvline(edge, color="0.4", lw=0.7, ls="--", zorder=1)
        shade_nodes(ax, cs.t, cs.enforced, cs.segment,
                    label="cone enforced (planner)" if n == 0 else None)
    ax_force, ax_margin = axes[0], axes[1]
    ax_paper = axes[2] if len(axes) > 2 else None
    for n, k in enumerate(ks):
        s = cs.segment == k
        lab = (lambda text: text if n == 0 else None)  # noqa: E731
        ax_force.plot(cs.t[s], f[s, 2], "-o", color="#000000", ms=2.2, label=lab("$f_z$ (normal)"))
        ax_force.plot(cs.t[s], cs.mu * f[s, 2], ":", color="0.35", label=lab(r"$\mu f_z$"))
        ax_force.plot(cs.t[s], np.abs(f[s, 0]), "-s", color="#D55E00", ms=2,
                      label=lab("$|f_x|$ (tangential)"))
        ax_force.plot(cs.t[s], np.abs(f[s, 1]), "-^", color="#009E73", ms=2,
                      label=lab("$|f_y|$ (tangential)"))
        ax_margin.plot(cs.t[s], margin[s], "-o", color=ACTUAL_COLOR, ms=2.2,
                       label=lab("physical cone (5)"))
        if ax_paper is not None:
            ax_paper.plot(cs.t[s], cs.margin["paper"][s], "-o", color=DESIRED_COLOR, ms=2.2,
                          label=lab("paper's cone (20)"))
    for ax in axes[1:]:
        ax.axhline(0.0, color="k", lw=0.8)
    ax_force.set_ylabel("force / mass (m/s²)")
    ax_margin.set_ylabel("margin (m/s²)")
    if ax_paper is not None:
        ax_paper.set_ylabel(r"$\langle F_n, \hat w\rangle - \cos\mu$")
    axes[-1].set_xlabel("time (s)")
    for ax in axes:
        ax.set_xlim(edges[0], edges[-1])
        bottom, top = ax.get_ylim()
        ax.set_ylim(bottom, top + 0.15 * (top - bottom))  # room for the segment names
    en = cs.enforced
    ratio = np.max(np.abs(f[:, :2]), axis=1) / np.where(f[:, 2] > 0, f[:, 2], np.nan)
    return {"min_margin_enforced": float(margin[en].min()) if en.any() else float("nan"),
            "min_fz": float(f[:, 2].min()),
            "max_tangential_ratio": float(np.nanmax(ratio[en])) if en.any() else float("nan"),
            "n_enforced": int(en.sum()), "n_nodes": int(en.size),
            "violated_unenforced": int(np.sum((margin < 0) & ~en)),
            "min_paper_margin_enforced": float(cs.margin["paper"][en].min()) if en.any()
            else float("nan")}


def plot_hermite_simpson(ax, hs, color: str = "#0072B2", label_prefix: str = "",
                         defect_color: str = "#D55E00") -> None:
    """Knots (filled), midpoints (open), cubic interpolants and the defects δ_i as bars from
    the interpolant's midpoint value to the node value (paper Fig. 5).

    Args:
        ax: 2D axes (time in s).
        hs: A :class:`~flipkit.plots.data.HermiteSimpsonCurves`.
    """
    for k in range(hs.t_dense.shape[0]):
        ax.plot(hs.t_dense[k], hs.x_dense[k], color=color, lw=1.0,
                label=f"{label_prefix}cubic interpolant" if k == 0 else None)
    ax.plot(hs.t_knots, hs.x_knots, "o", color=color, ms=3.5,
            label=f"{label_prefix}knots $x_{{i\\pm1}}$")
    ax.plot(hs.t_mid, hs.x_mid, "o", mfc="white", mec=color, ms=3.5,
            label=f"{label_prefix}midpoints $x_i$")
    ax.vlines(hs.t_mid, hs.x_mid_interp, hs.x_mid, color=defect_color, lw=1.6,
              label=r"defect $\delta_i = x_i - \bar x_i$")


def plot_defect_zoom(ax, hs, k: int, scale: float = 1e3, unit: str = "mrad",
                     color: str = "#0072B2", defect_color: str = "#D55E00") -> dict:
    """One interval pair near its midpoint, detrended about the interpolant's midpoint
    tangent (everything minus x̄_k + ẋ̄_k (t − t_k)), so that the defects of eqs. (8)–(9)
    become visible: the interpolant touches zero at t_k with zero slope, the midpoint node
    sits at δ_k and its own slope ẋ_k (a short line through it) leans by ξ_k.

    The view spans ±1/6 of the pair and a few |δ_k| vertically; the defect values are
    written in the axes.

    Args:
        ax: 2D axes. hs: :class:`~flipkit.plots.data.HermiteSimpsonCurves`.
        k: Interval pair (0-based).
        scale, unit: Display scale of x (default rad -> mrad).

    Returns:
        ``delta`` and ``xi`` of the pair (units of x and x per s).
    """
    tm, xbar, xdbar = hs.t_mid[k], hs.x_mid_interp[k], hs.xd_mid_interp[k]
    h = hs.t_knots[k + 1] - hs.t_knots[k]
    t = np.linspace(tm - h / 6, tm + h / 6, 201)
    x = hs.interpolant(k, t)
    trend = xbar + xdbar * (t - tm)
    d, xi = float(hs.delta[k]), float(hs.xi[k])
    ax.plot(t - tm, scale * (x - trend), color=color, lw=1.2, label="cubic interpolant")
    ax.plot([0], [scale * d], "o", mfc="white", mec=color, ms=5, zorder=5,
            label="midpoint node $x_i$")
    ax.vlines(0, 0, scale * d, color=defect_color, lw=1.8, label=r"$\delta_i$", zorder=4)
    half = h / 6
    tt = np.array([-half / 2, half / 2])
    ax.plot(tt, scale * (d + xi * tt), "-", color="#009E73", lw=1.2,
            label=r"node slope $\dot x_i$ (lean $\xi_i$)")
    ax.axhline(0, color="0.5", lw=0.6, ls=":")
    ax.set_xlim(-half, half)
    span = max(abs(d), 1e-12) * scale
    ax.set_ylim(-2.5 * span, 2.5 * span)
    ax.text(0.03, 0.04, f"$\\delta_i$ = {d:.2g} rad\n$\\xi_i$ = {xi:.2g} rad/s",
            transform=ax.transAxes, fontsize=6, va="bottom")
    ax.set_xlabel(r"$t - t_i$ (s)")
    ax.set_ylabel(f"detrended $x$ ({unit})")
    return {"delta": float(d), "xi": float(xi)}


def plot_cone_regions(ax, tilts, accels, grid) -> dict:
    """Map of which cone form admits each (tilt, horizontal acceleration) (:func:`~flipkit.
    plots.data.cone_region_grid`), with the boundary of eq. (20) as printed dashed.

    Returns:
        The area fraction of each class of :data:`~flipkit.plots.data.CONE_CLASSES`.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    deg = np.degrees(np.asarray(tilts, float))
    cat = grid["category"]
    acc = np.asarray(accels, float)
    half_a, half_d = (acc[-1] - acc[0]) / (2 * (acc.size - 1)), (deg[-1] - deg[0]) / (
        2 * (deg.size - 1))
    ax.imshow(cat, origin="lower", aspect="auto", interpolation="nearest",
              cmap=ListedColormap(CONE_CLASS_COLORS), vmin=-0.5, vmax=3.5,
              extent=(acc[0] - half_a, acc[-1] + half_a, deg[0] - half_d, deg[-1] + half_d))
    ax.contour(accels, deg, grid["physical"], levels=[0.0], colors=[CONE_CLASS_COLORS[1]],
               linewidths=1.0)
    ax.contour(accels, deg, grid["paper"], levels=[0.0], colors=[CONE_CLASS_COLORS[2]],
               linewidths=1.0)
    printed = np.nan_to_num(grid["printed"], nan=-1.0)
    admits = bool(np.any(printed >= 0))
    if admits:
        ax.contour(accels, deg, printed, levels=[0.0], colors=["k"], linewidths=0.9,
                   linestyles="--")
    handles = [Patch(facecolor=c, edgecolor="0.5", lw=0.4, label=lab)
               for c, lab in zip(CONE_CLASS_COLORS, ("both admit", "only physical (5)",
                                                    "only paper (20)", "neither"))]
    from matplotlib.lines import Line2D

    handles.append(Line2D([], [], color="k", ls="--" if admits else "none", lw=0.9,
                          label="(20) as printed ($a$ without $g$)" + (
                              "" if admits else ":\nadmits no point here")))
    ax.legend(handles=handles, loc="lower right", fontsize=6, frameon=True, framealpha=0.9)
    ax.set_xlabel("horizontal acceleration $a_x$ (m/s²)")
    ax.set_ylabel("spatula pitch $o_y$ (deg)")
    ax.grid(False)
    return {name: float(np.mean(cat == k)) for k, name in enumerate(CONE_CLASSES)}


def plot_tangential_sections(ax, bounds) -> None:
    """The cones' cross-sections in the (f_x/f_z, f_y/f_z) plane: the physical pyramid's
    square and the paper's circle (:func:`~flipkit.plots.data.tangential_boundaries`)."""
    sq, ci = bounds["square"], bounds["circle"]
    ax.fill(*sq.T, color=CONE_CLASS_COLORS[1], alpha=0.15, lw=0)
    ax.plot(*sq.T, color=CONE_CLASS_COLORS[1], lw=1.2,
            label=r"physical (5): $|f_{x,y}| \leq \mu f_z$")
    ax.fill(*ci.T, color=CONE_CLASS_COLORS[2], alpha=0.12, lw=0)
    ax.plot(*ci.T, color=CONE_CLASS_COLORS[2], lw=1.2,
            label=r"paper (20): angle to normal $\leq \mu$ rad")
    lim = 1.25 * max(np.abs(sq).max(), np.abs(ci).max())
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim * 1.6)
    ax.set_aspect("equal")
    ax.set_xlabel("$f_x / f_z$")
    ax.set_ylabel("$f_y / f_z$")
    ax.legend(loc="upper center", fontsize=6)


def draw_burger(ax3d, center, R, diameter: float, thickness: float, color=BURGER_COLOR,
                n: int = 32):
    """A burger disc (its two faces) centred at ``center`` with axis R[:, 2], in 3D (m)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    R = np.asarray(R, float)
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = (diameter / 2) * (np.outer(np.cos(ang), R[:, 0]) + np.outer(np.sin(ang), R[:, 1]))
    faces = [np.asarray(center) + ring + s * thickness / 2 * R[:, 2] for s in (-1, 1)]
    side = [np.vstack([faces[0][k], faces[0][(k + 1) % n], faces[1][(k + 1) % n], faces[1][k]])
            for k in range(n)]
    coll = Poly3DCollection(faces + side, facecolor=color, edgecolor="none", alpha=0.95, zorder=6)
    ax3d.add_collection3d(coll)
    return coll


def draw_snapshot(ax3d, robot, cell, q, location=None, burger: str | None = None,
                  path=None, limits=None, view=(20.0, -60.0), title=None) -> dict:
    """One subbehaviour snapshot: the cell drawn by :func:`flipkit.plotting.draw_cell` at q
    (no legend), zoomed to ``limits``, with the blade-centre path of the segment and the
    burger.

    Args:
        ax3d: 3D axes. robot, cell: Model and cell. q: Configuration (rad).
        location: Burger location p^b (m) (where the ``grill`` and ``flipped`` burgers lie).
        burger: ``"blade"`` (resting centred on the blade), ``"grill"`` (flat at
            ``location``, upright), ``"flipped"`` (flat at ``location``, other side up) or
            None (not drawn).
        path: Blade-centre positions along the segment (k, 3) (m), drawn as a line.
        limits: ((x0, x1), (y0, y1), (z0, z1)) (m); default the grill area and the space
            above it, with the arm. Whatever lies outside is hidden (cut at the view's edge).
        view: Camera (elevation, azimuth) (deg).
    """
    drawn = draw_cell(ax3d, robot, cell, q, np.zeros((0, 3)), legend=False, view=view,
                      clip=True, table=False)
    M = robot.placement(q)
    bg = cell.burger
    if burger == "blade":
        center = M.translation + M.rotation[:, 2] * (bg.thickness / 2)
        draw_burger(ax3d, center, M.rotation, bg.diameter, bg.thickness)
    elif burger in ("grill", "flipped"):
        center = np.array([location[0], location[1], cell.grill.height + bg.thickness / 2])
        R = np.eye(3) if burger == "grill" else np.diag([1.0, -1.0, -1.0])
        draw_burger(ax3d, center, R, bg.diameter, bg.thickness,
                    color=BURGER_COLOR if burger == "grill" else "#C68642")
    elif burger is not None:
        raise ConfigError(f"burger must be 'blade', 'grill', 'flipped' or None, got {burger!r}")
    if path is not None:
        path = np.asarray(path, float)
        ax3d.plot(*path.T, color="#CC79A7", lw=1.2, zorder=7, axlim_clip=True)
        ax3d.plot(*path[0], "o", color="#CC79A7", ms=2.5, zorder=7, axlim_clip=True)
    if limits is None:
        g = cell.grill
        limits = ((-0.1, g.x_range[1] + 0.04), (g.y_range[0] - 0.04, g.y_range[1] + 0.1),
                  (0.0, 0.9))
    lim = np.asarray(limits, float)
    ax3d.set_xlim(*lim[0])
    ax3d.set_ylim(*lim[1])
    ax3d.set_zlim(*lim[2])
    ax3d.set_box_aspect(lim[:, 1] - lim[:, 0])
    from matplotlib.ticker import MaxNLocator

    for axis in (ax3d.xaxis, ax3d.yaxis, ax3d.zaxis):
        axis.label.set_size(6)
        axis.set_major_locator(MaxNLocator(3))
    ax3d.tick_params(labelsize=5, pad=0)
    if title:
        ax3d.set_title(title, fontsize=8, pad=0)
    return drawn


def wilson_interval(successes, trials, z: float = 1.96) -> tuple[np.ndarray, np.ndarray]:
    """Wilson score interval (lower, upper) of a binomial success ratio (95 % by default)."""
    k, n = np.asarray(successes, float), np.asarray(trials, float)
    n_safe = np.where(n > 0, n, 1.0)
    p = k / n_safe
    den = 1 + z**2 / n_safe
    mid = (p + z**2 / (2 * n_safe)) / den
    half = z * np.sqrt(p * (1 - p) / n_safe + z**2 / (4 * n_safe**2)) / den
    lo, hi = np.clip(mid - half, 0, 1), np.clip(mid + half, 0, 1)
    return np.where(n > 0, lo, np.nan), np.where(n > 0, hi, np.nan)


def plot_success(ax, labels, ours_k, ours_n, paper_k, paper_n, title: str = "",
                 pooled: bool = True) -> None:
    """Success ratios per location: ours (filled circles, 95 % Wilson interval) beside the
    paper's (open squares); with ``pooled`` a last column "all" pools every location."""
    labels = [str(v) for v in labels]
    ours_k, ours_n = np.asarray(ours_k, float), np.asarray(ours_n, float)
    paper_k, paper_n = np.asarray(paper_k, float), np.asarray(paper_n, float)
    if pooled:
        labels = labels + ["all"]
        ours_k, ours_n = np.append(ours_k, ours_k.sum()), np.append(ours_n, ours_n.sum())
        paper_k, paper_n = np.append(paper_k, paper_k.sum()), np.append(paper_n, paper_n.sum())
    x = np.arange(len(labels), dtype=float)
    if pooled:
        x[-1] += 0.5
        ax.axvline(x[-1] - 0.75, color="0.6", lw=0.6, ls=":")
    lo, hi = wilson_interval(ours_k, ours_n)
    ratio = np.where(ours_n > 0, ours_k / np.where(ours_n > 0, ours_n, 1), np.nan)
    ax.errorbar(x + 0.12, ratio, yerr=[ratio - lo, hi - ratio], fmt="o", color=ACTUAL_COLOR,
                ms=4, capsize=1.5, lw=0.8, label="ours (simulated), 95 % CI")
    ax.plot(x - 0.12, paper_k / paper_n, "s", mfc="white", mec=DESIRED_COLOR, ms=4.5, mew=1.0,
            label="paper (real robot)")
    ax.set_xticks(x, labels)
    ax.set_ylim(-0.05, 1.08)
    ax.set_ylabel("success ratio")
    if title:
        ax.set_title(title)


def plot_success_series(ax, labels, series, paper_k, paper_n, title: str = "",
                        pooled: bool = True) -> None:
    """Success ratios per location of several simulated pipelines side by side (each with a
    95 % Wilson interval) beside the paper's (open squares); with ``pooled`` a last column
    "all" pools every location.

    Args:
        ax: 2D axes. labels: Location labels.
        series: ``[{"label", "k" (successes per location), "n" (trials per location),
            optional "color", "marker", "open" (hollow marker)}]``, drawn left to right.
        paper_k, paper_n: The paper's successes and trials per location.
    """
    labels = [str(v) for v in labels]
    paper_k, paper_n = np.asarray(paper_k, float), np.asarray(paper_n, float)
    if pooled:
        labels = labels + ["all"]
        paper_k, paper_n = np.append(paper_k, paper_k.sum()), np.append(paper_n, paper_n.sum())
    x = np.arange(len(labels), dtype=float)
    if pooled:
        x[-1] += 0.5
        ax.axvline(x[-1] - 0.75, color="0.6", lw=0.6, ls=":")
    width = 0.7 / (len(series) + 1)
    ax.plot(x - 0.35 + width / 2, paper_k / paper_n, "s", mfc="white", mec=DESIRED_COLOR,
            ms=4, mew=1.0, label="paper (real robot)")
    for j, sr in enumerate(series, 1):
        k, n = np.asarray(sr["k"], float), np.asarray(sr["n"], float)
        if pooled:
            k, n = np.append(k, k.sum()), np.append(n, n.sum())
        lo, hi = wilson_interval(k, n)
        ratio = np.where(n > 0, k / np.where(n > 0, n, 1), np.nan)
        color = sr.get("color", f"C{j - 1}")
        ax.errorbar(x - 0.35 + width * (j + 0.5), ratio, yerr=[ratio - lo, hi - ratio],
                    fmt=sr.get("marker", "o"), color=color, mfc="white" if sr.get("open")
                    else color, ms=3.5, capsize=1.2, lw=0.7, label=sr["label"])
    ax.set_xticks(x, labels)
    ax.set_ylim(-0.05, 1.08)
    ax.set_ylabel("success ratio")
    if title:
        ax.set_title(title)


def plot_solve_times(ax, names, times, budget: float | None = None, log: bool = True,
                     failed=None) -> dict:
    """Solve time per group (subbehaviour) and solver: points per location, box over them.

    Args:
        ax: 2D axes.
        names: Group names along x (e.g. the subbehaviours and ``"total"``).
        times: ``{solver: {name: [seconds per location]}}``; missing or None entries skipped.
        budget: A horizontal budget line (s), e.g. the paper's 20 s per trajectory.
        failed: Same form as ``times``: solves that did not converge, drawn as crosses.

    Returns:
        ``{solver: {name: median seconds}}``.
    """
    solvers = list(times)
    width = 0.8 / max(len(solvers), 1)
    rng = np.random.default_rng(0)
    medians = {}
    for k, solver in enumerate(solvers):
        medians[solver] = {}
        color = SOLVER_COLORS.get(solver, f"C{k}")
        for j, name in enumerate(names):
            vals = np.array([v for v in times[solver].get(name, []) if v is not None], float)
            if vals.size == 0:
                continue
            pos = j - 0.4 + width * (k + 0.5)
            ax.boxplot([vals], positions=[pos], widths=width * 0.8, showfliers=False,
                       patch_artist=True, boxprops={"facecolor": color, "alpha": 0.25,
                                                    "edgecolor": color},
                       medianprops={"color": color, "lw": 1.5},
                       whiskerprops={"color": color}, capprops={"color": color})
            jitter = rng.uniform(-0.25, 0.25, vals.size) * width
            ax.plot(pos + jitter, vals, "o", color=color, ms=2.5, alpha=0.9,
                    label=SOLVER_LABELS.get(solver, solver) if j == 0 else None)
            medians[solver][name] = float(np.median(vals))
        for j, name in enumerate(names):
            bad = np.array([v for v in (failed or {}).get(solver, {}).get(name, [])
                            if v is not None], float)
            if bad.size:
                pos = j - 0.4 + width * (k + 0.5)
                ax.plot(np.full(bad.size, pos), bad, "x", color=color, ms=4, mew=1.0,
                        label=f"{SOLVER_LABELS.get(solver, solver)}: not converged"
                        if not any(h.get_label().endswith(f"{SOLVER_LABELS.get(solver, solver)}"
                                                          ": not converged")
                                   for h in ax.lines) else None)
    if budget is not None:
        ax.axhline(budget, color="k", ls="--", lw=1.0,
                   label=f"paper budget, {budget:g} s per trajectory")
    if log:
        ax.set_yscale("log")
    ax.set_xticks(range(len(names)), [str(n).replace("_", " ") for n in names])
    ax.set_xlim(-0.6, len(names) - 0.4)
    ax.set_ylabel("solve time (s)")
    return medians


def plot_grill_map(ax, cell, points, categories, styles, title: str = "",
                   table_locations=None, notes=None) -> None:
    """Top view of the grill with burger locations, one marker style per outcome category.

    Drawn as seen from above with the robot behind the bottom edge: world x (away from the
    robot) up the page, world y to the left (the horizontal axis is y, increasing to the
    left); equal aspect, m.

    Args:
        ax: 2D axes.
        cell: The cell (grill area).
        points: Locations (k, 2 or 3) (m).
        categories: Outcome label of each location (k,); ``_`` shows as a space.
        styles: ``{label: dict(marker=..., color=..., s=...)}``; also fixes the legend order.
        table_locations: Optional Table I locations, drawn as small crosses for reference.
        notes: Optional short text per location (k,), written beside its marker (None: none).
    """
    from matplotlib.patches import Rectangle

    g = cell.grill
    ax.add_patch(Rectangle((g.y_range[0], g.x_range[0]), g.y_range[1] - g.y_range[0],
                           g.x_range[1] - g.x_range[0], facecolor="0.93", edgecolor="0.3",
                           lw=0.8, zorder=0))
    pts = np.asarray(points, float).reshape(len(categories), -1)
    cats = np.asarray(categories, dtype=object)
    for label, st in styles.items():
        sel = cats == label
        if not sel.any():
            continue
        ax.scatter(pts[sel, 1], pts[sel, 0], s=st.get("s", 30), marker=st.get("marker", "o"),
                   color=st.get("color", "k"), edgecolors=st.get("edgecolor", "k"),
                   linewidths=0.4, label=f"{str(label).replace('_', ' ')} ({int(sel.sum())})",
                   zorder=3)
    if notes is not None:
        for (x, y), note in zip(pts[:, :2], notes):
            if note:
                ax.annotate(str(note), (y, x), xytext=(3, 3), textcoords="offset points",
                            fontsize=5, color="0.2", zorder=5)
    if table_locations is not None:
        tl = np.asarray(table_locations, float)
        ax.plot(tl[:, 1], tl[:, 0], "+", color="0.1", ms=4, mew=0.6, zorder=4,
                label="Table I location")
    _grill_view(ax, g, "$p^b_y$ (m)", "$p^b_x$ (m)", title)


def _grill_view(ax, g, xlabel: str, ylabel: str, title: str = "") -> None:
    """Top view of the grill area ``g``: y to the left, x up, 3 cm of margin, equal axes."""
    ax.set_xlim(g.y_range[1] + 0.03, g.y_range[0] - 0.03)  # y grows to the left
    ax.set_ylim(g.x_range[0] - 0.03, g.x_range[1] + 0.03)
    ax.set_aspect("equal")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)


def plot_landings(ax, cell, points: dict, targets_xy, radius: float = 0.05, title: str = "",
                  legend: bool = True) -> None:
    """Top view of the grill (axes as :func:`plot_grill_map`): each target with a circle of
    ``radius`` (m) about it, the predicted landing points (crosses), the simulated ones
    (filled: flipped by the paper's judge; open: not), a thin line from each prediction to
    its simulated landing.

    Args:
        ax: 2D axes. cell: The cell (grill area).
        points: :func:`flipkit.plots.data.landing_points`.
        targets_xy: The landing targets (k×2) (m).
        radius: Circle radius (m), the paper's 5 cm.
    """
    from matplotlib.patches import Circle, Rectangle

    g = cell.grill
    ax.add_patch(Rectangle((g.y_range[0], g.x_range[0]), g.y_range[1] - g.y_range[0],
                           g.x_range[1] - g.x_range[0], facecolor="0.95", edgecolor="0.3",
                           lw=0.8, zorder=0))
    tg = np.asarray(targets_xy, float).reshape(-1, 2)
    for k, (x, y) in enumerate(tg):
        ax.add_patch(Circle((y, x), radius, fill=False, ec="0.35", lw=0.6, ls="--", zorder=1))
        ax.annotate(str(k + 1), (y, x), xytext=(0, 0), textcoords="offset points",
                    fontsize=5, color="0.3", ha="center", va="center", zorder=1)
    ax.plot([], [], ls="--", color="0.35", lw=0.6, label=f"{100 * radius:g} cm about target")
    xy, pred, ok = points["xy"], points["predicted"], points["flipped"]
    for a, b in zip(pred, xy):
        if np.all(np.isfinite(a)):
            ax.plot([a[1], b[1]], [a[0], b[0]], color="0.6", lw=0.4, zorder=2)
    ax.plot(pred[:, 1], pred[:, 0], "x", color=DESIRED_COLOR, ms=3.5, mew=0.8, zorder=3,
            label="predicted (plan)")
    ax.plot(xy[ok, 1], xy[ok, 0], "o", color=ACTUAL_COLOR, ms=3, zorder=4,
            label=f"simulated, flipped ({int(ok.sum())})")
    ax.plot(xy[~ok, 1], xy[~ok, 0], "o", mfc="white", mec=ACTUAL_COLOR, ms=3, mew=0.7,
            zorder=4, label=f"simulated, not flipped ({int((~ok).sum())})")
    _grill_view(ax, g, "y (m)", "x (m)", title)
    if legend:
        ax.legend(loc="lower left", fontsize=6)


def plot_sensitivity(axes, result: dict, stages=("scoop", "pickup", "flip"),
                     labels=None) -> list:
    """One panel per stage: per parameter (rows), the success ratio at the low end
    (down-triangle) and the high end (up-triangle) of its range, the nominal cell's ratio as
    a vertical line. ``result`` is :func:`flipkit.sensitivity.run_sensitivity`'s.

    Returns:
        The parameter names, top to bottom.
    """
    names = list(result["parameters"])
    y = np.arange(len(names))[::-1]
    nominal = result.get("nominal")
    for ax, stage in zip(axes, stages):
        for end, marker, color in (("low", "v", DESIRED_COLOR), ("high", "^", ACTUAL_COLOR)):
            r = [result["parameters"][n][end] for n in names]
            ratio = np.array([c["success"][stage] / c["trials"] for c in r])
            off = -0.12 if end == "low" else 0.12
            ax.plot(ratio, y + off, marker, color=color, ms=3.5, ls="none",
                    label=f"{end} end of range")
        if nominal is not None:
            ax.axvline(nominal["success"][stage] / nominal["trials"], color="0.3", lw=0.9,
                       ls=":", label="nominal")
        ax.set_xlim(-0.05, 1.05)
        ax.set_ylim(-0.6, len(names) - 0.4)
        ax.set_title(stage)
        ax.set_xlabel("success ratio")
        ax.set_yticks(y, labels or names)
    return names


__all__ = ["DESIRED_COLOR", "ACTUAL_COLOR", "SOLVER_COLORS", "SOLVER_LABELS", "plot_tracking",
           "plot_tracking_error", "shade_nodes", "plot_forces", "plot_hermite_simpson",
           "plot_cone_regions", "plot_tangential_sections", "draw_burger", "draw_snapshot",
           "wilson_interval", "plot_success", "plot_success_series", "plot_solve_times", "plot_grill_map",
           "plot_landings", "plot_sensitivity"]
