"""Time-series and contact panels: tracking, forces on the blade, Hermite–Simpson defects and
the friction cone's regions. Each function draws into axes it is given and returns what it
drew (numbers for captions); figure size, style and saving stay with the caller."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from flipkit.errors import ConfigError
from flipkit.figures.data import CONE_CLASSES
from flipkit.figures.draw.cell import shade_segments
from flipkit.figures.style import ACTUAL_COLOR, CONE_CLASS_COLORS, DESIRED_COLOR

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
        cs: A :class:`~flipkit.figures.data.ContactSeries`.

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
        hs: A :class:`~flipkit.figures.data.HermiteSimpsonCurves`.
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
        ax: 2D axes. hs: :class:`~flipkit.figures.data.HermiteSimpsonCurves`.
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
        The area fraction of each class of :data:`~flipkit.figures.data.CONE_CLASSES`.
    """
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
    square and the paper's circle (:func:`~flipkit.figures.data.tangential_boundaries`)."""
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
