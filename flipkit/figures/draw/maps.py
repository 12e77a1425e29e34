"""Spatial views: the arm at an instant (3D snapshot with the burger) and top views of the
grill (locations by outcome, where the burgers landed)."""

from __future__ import annotations

import numpy as np
from matplotlib.patches import Circle, Rectangle
from matplotlib.ticker import MaxNLocator
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from flipkit.errors import ConfigError
from flipkit.figures.draw.cell import draw_cell
from flipkit.figures.style import ACTUAL_COLOR, BURGER_COLOR, DESIRED_COLOR


def draw_burger(ax3d, center, R, diameter: float, thickness: float, color=BURGER_COLOR,
                n: int = 32):
    """A burger disc (its two faces) centred at ``center`` with axis R[:, 2], in 3D (m)."""
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
    """One subbehaviour snapshot: the cell drawn by :func:`flipkit.figures.draw.draw_cell` at q
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
    for axis in (ax3d.xaxis, ax3d.yaxis, ax3d.zaxis):
        axis.label.set_size(6)
        axis.set_major_locator(MaxNLocator(3))
    ax3d.tick_params(labelsize=5, pad=0)
    if title:
        ax3d.set_title(title, fontsize=8, pad=0)
    return drawn


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
                  legend: bool = True, scenarios=None) -> None:
    """Top view of the grill (axes as :func:`plot_grill_map`): each target with a circle of
    ``radius`` (m) about it, the predicted landing points (crosses), the simulated ones
    (filled: flipped by the paper's judge; open: not), a thin line from each prediction to
    its simulated landing.

    Args:
        ax: 2D axes. cell: The cell (grill area).
        points: :func:`flipkit.figures.data.landing_points`.
        targets_xy: The landing targets (k×2) (m).
        radius: Circle radius (m), the paper's 5 cm.
        scenarios: Planned landing points (k×2) (m) of the plans' robust scenarios
            (:func:`flipkit.figures.data.scenario_landings`), drawn as plus signs.
    """
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
    sc = np.asarray([] if scenarios is None else scenarios, float).reshape(-1, 2)
    if len(sc):
        ax.plot(sc[:, 1], sc[:, 0], "+", color=DESIRED_COLOR, ms=3, mew=0.5, alpha=0.7,
                zorder=3, label="planned scenarios")
    ax.plot(xy[ok, 1], xy[ok, 0], "o", color=ACTUAL_COLOR, ms=3, zorder=4,
            label=f"simulated, flipped ({int(ok.sum())})")
    ax.plot(xy[~ok, 1], xy[~ok, 0], "o", mfc="white", mec=ACTUAL_COLOR, ms=3, mew=0.7,
            zorder=4, label=f"simulated, not flipped ({int((~ok).sum())})")
    _grill_view(ax, g, "y (m)", "x (m)", title)
    if legend:
        ax.legend(loc="lower left", fontsize=6)
