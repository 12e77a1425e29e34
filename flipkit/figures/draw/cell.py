"""The cell in 3D (arm, spatula, grill, table, burger locations) and the shading of
subbehaviour segments on time axes.

All lengths are in metres, times in seconds. The helpers draw into axes they are given and
leave the figure size, style (:func:`flipkit.figures.style`) and saving to the caller.
"""

from __future__ import annotations

import numpy as np
from matplotlib.patches import Patch
from mpl_toolkits.mplot3d import proj3d
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from flipkit.config import CellConfig
from flipkit.errors import ConfigError
from flipkit.model.robot import Robot

ROBOT_COLOR, JOINT_COLOR, BLADE_COLOR = "0.55", "0.15", "#0072B2"
GRILL_COLOR, TABLE_COLOR, LOCATION_COLOR = "0.30", "#E69F00", "#D55E00"


def _rectangle(center, x_axis, y_axis, half_x: float, half_y: float) -> np.ndarray:
    """4x3 corners of the rectangle center ± half_x·x_axis ± half_y·y_axis (m)."""
    c, ex, ey = (np.asarray(v, dtype=float) for v in (center, x_axis, y_axis))
    return np.array([c - half_x * ex - half_y * ey, c + half_x * ex - half_y * ey,
                     c + half_x * ex + half_y * ey, c - half_x * ex + half_y * ey])


def _area(x_range, y_range, height: float) -> np.ndarray:
    """4x3 corners of the horizontal rectangle x_range × y_range at ``height`` (m)."""
    (x0, x1), (y0, y1) = x_range, y_range
    return np.array([[x0, y0, height], [x1, y0, height], [x1, y1, height], [x0, y1, height]])


def _group_locations(locations, tol: float = 1e-3) -> list[tuple[np.ndarray, str]]:
    """Locations merged where they coincide in (x, y) within ``tol`` (m), labelled '1,4'."""
    groups: list[tuple[np.ndarray, list[int]]] = []
    for k, loc in enumerate(np.asarray(locations, dtype=float).reshape(-1, 3), start=1):
        for point, labels in groups:
            if np.linalg.norm(point[:2] - loc[:2]) <= tol:
                labels.append(k)
                break
        else:
            groups.append((loc, [k]))
    return [(point, ",".join(map(str, labels))) for point, labels in groups]


def _label_spots(ax3d, points, gap: float = 0.04) -> list[np.ndarray]:
    """Label positions (m) beside ``points``, each chosen greedily among five offsets (above,
    ±x, ±y) to lie farthest, on screen, from the markers and the labels already placed."""
    def screen(xyz):
        x, y, _ = proj3d.proj_transform(*np.asarray(xyz, dtype=float).T, ax3d.get_proj())
        return np.column_stack([x, y])

    offsets = np.array([[0, 0, gap], [gap, 0, gap / 3], [-gap, 0, gap / 3], [0, gap, gap / 3],
                        [0, -gap, gap / 3]])
    taken = list(screen(points))
    spots = []
    for point in np.asarray(points, dtype=float):
        candidates = point + offsets
        clearance = [min(np.linalg.norm(c - t) for t in taken) for c in screen(candidates)]
        best = int(np.argmax(np.round(clearance, 4)))  # ties keep the earlier (above) spot
        spots.append(candidates[best])
        taken.append(screen(candidates[best:best + 1])[0])
    return spots


def draw_cell(ax3d, robot: Robot, cell: CellConfig, q, locations, legend: bool = True,
              view: tuple = (22.0, -60.0), clip: bool = False, table: bool = True) -> dict:
    """Draw the cell in 3D: arm, spatula, grill, table and burger locations.

    The arm is a stick chain through the base, the joint origins (``data.oMi``) and the tool
    flange; the spatula is its handle plus the blade rectangle (l_l along spatula x, l_w
    along y); the grill and the table are their areas at their heights; ``locations`` are
    markers numbered from 1 (coinciding ones share a marker); a dotted line drops from the
    blade centre to the grill plane as a depth cue. Axes are equal-aspect, in m.

    Args:
        ax3d: A matplotlib 3D axes (``projection="3d"``).
        robot: The robot model (its spatula frame is drawn).
        cell: The cell configuration (spatula, grill, table).
        q: Joint configuration (rad), shape (nq,).
        locations: Burger locations p^b (m), shape (k, 3); e.g. ``config.TABLE1_LOCATIONS``.
        legend: Add a legend naming the parts.
        view: Camera (elevation, azimuth) (deg).
        clip: Hide what falls outside the axes limits (matplotlib's ``axlim_clip``), for
            callers that zoom in by setting narrower limits afterwards.
        table: Draw the table (and include it in the limits).

    Returns:
        The drawn geometry in the world frame (m): ``joints`` (n, 3) chain points,
        ``blade`` (4, 3) corners, ``spatula_position`` (3,) blade centre, and
        ``location_labels``, one label per drawn marker (e.g. ``"1,4"``).
    """
    q = np.asarray(q, dtype=float)
    if q.shape != (robot.nq,) or not np.all(np.isfinite(q)):
        raise ConfigError(f"q must be {robot.nq} finite joint angles (rad), got {q.tolist()}")
    model, data = robot.model, robot.data
    spatula = robot.placement(q)  # also runs framesForwardKinematics for oMi and oMf
    tool = data.oMf[model.getFrameId(cell.robot.tool_frame)].translation
    base = np.asarray(cell.robot.base_in_world, dtype=float)[:3, 3]
    joints = np.vstack([base] + [data.oMi[j].translation for j in range(1, model.njoints)]
                       + [tool])
    R, p, sp = spatula.rotation, spatula.translation, cell.spatula
    blade = _rectangle(p, R[:, 0], R[:, 1], sp.length / 2, sp.width / 2)
    handle = np.vstack([tool, p - R[:, 0] * sp.length / 2])
    grill = _area(cell.grill.x_range, cell.grill.y_range, cell.grill.height)
    table = _area(cell.table.x_range, cell.table.y_range, cell.table.height) if table else None
    points = _group_locations(locations)

    ax3d.computed_zorder = False  # surfaces below, arm above: drawn in this order
    ax3d.add_collection3d(Poly3DCollection([grill], facecolor=GRILL_COLOR, alpha=0.35,
                                           edgecolor="0.1", linewidth=0.6, zorder=1),
                          axlim_clip=clip)
    if table is not None:
        ax3d.add_collection3d(Poly3DCollection([table], facecolor=TABLE_COLOR, alpha=0.35,
                                               edgecolor="0.1", linewidth=0.6, zorder=1),
                              axlim_clip=clip)
    for point, _ in points:
        ax3d.scatter(*point, s=14, color=LOCATION_COLOR, depthshade=False, zorder=2,
                     axlim_clip=clip)
    ax3d.plot(*joints.T, color=ROBOT_COLOR, linewidth=5, solid_capstyle="round", zorder=3,
              axlim_clip=clip)
    ax3d.plot(*joints.T, "o", color=JOINT_COLOR, markersize=3.5, zorder=4, axlim_clip=clip)
    ax3d.plot(*base, "s", color=JOINT_COLOR, markersize=7, zorder=4, axlim_clip=clip)
    ax3d.plot(*handle.T, color=JOINT_COLOR, linewidth=1.5, zorder=4, axlim_clip=clip)
    ax3d.plot([p[0], p[0]], [p[1], p[1]], [cell.grill.height, p[2]], ":", color=BLADE_COLOR,
              linewidth=1, zorder=4, axlim_clip=clip)
    ax3d.add_collection3d(Poly3DCollection([blade], facecolor=BLADE_COLOR, alpha=0.9,
                                           edgecolor="k", linewidth=0.6, zorder=5),
                          axlim_clip=clip)

    every = np.vstack([joints, blade, grill] + ([] if table is None else [table])
                      + [np.reshape([pt for pt, _ in points], (-1, 3))])
    lo, hi = every.min(axis=0) - 0.05, every.max(axis=0) + 0.05
    lo[2] = min(lo[2], 0.0)
    ax3d.set_xlim(lo[0], hi[0])
    ax3d.set_ylim(lo[1], hi[1])
    ax3d.set_zlim(lo[2], hi[2])
    ax3d.view_init(elev=view[0], azim=view[1])
    ax3d.set_box_aspect(hi - lo)  # equal aspect: one metre is as long on every axis
    ax3d.set_xlabel("x (m)")
    ax3d.set_ylabel("y (m)")
    ax3d.set_zlabel("z (m)")
    spots = _label_spots(ax3d, [pt for pt, _ in points]) if points else []
    for (point, label), spot in zip(points, spots):
        ax3d.text(*spot, label, fontsize=6, ha="center", va="center", color=LOCATION_COLOR,
                  zorder=6, axlim_clip=clip)
    if legend:
        ax3d.legend(handles=[
            Patch(color=ROBOT_COLOR, label="arm (joint origins)"),
            Patch(color=BLADE_COLOR, label="spatula blade"),
            Patch(color=GRILL_COLOR, alpha=0.35, label=f"grill, z = {cell.grill.height} m"),
            *([] if table is None else [Patch(color=TABLE_COLOR, alpha=0.35, label="table")]),
            Patch(color=LOCATION_COLOR, label="Table I locations")], loc="upper left")
    return {"joints": joints, "blade": blade, "spatula_position": np.array(p),
            "location_labels": [label for _, label in points]}


def shade_segments(ax, boundaries, names, color: str = "0.92", label_y: float = 0.98) -> None:
    """Shade alternate time segments of a 2D time plot and name each at the top.

    Args:
        ax: A 2D matplotlib axes whose x axis is time (s).
        boundaries: Segment edges t_0 < t_1 < ... < t_K (s), K = len(names).
        names: Segment (subbehaviour) names, e.g. ``FLIP_NAMES``.
        color: Colour of the shaded (every other) band.
        label_y: Height of the names in axes coordinates (0 bottom, 1 top).

    Raises:
        ConfigError: Edge count is not len(names) + 1, or the edges do not increase.
    """
    edges = np.asarray(boundaries, dtype=float)
    if edges.ndim != 1 or edges.size != len(names) + 1:
        raise ConfigError(f"need {len(names) + 1} segment boundaries for {len(names)} names, "
                          f"got {edges.size}")
    if not np.all(np.isfinite(edges)) or np.any(np.diff(edges) <= 0):
        raise ConfigError(f"segment boundaries must increase, got {edges.tolist()}")
    transform = ax.get_xaxis_transform()  # x in data (s), y in axes fraction
    for k, name in enumerate(names):
        if k % 2 == 0:
            ax.axvspan(edges[k], edges[k + 1], color=color, zorder=0, linewidth=0)
        ax.text((edges[k] + edges[k + 1]) / 2, label_y, str(name).replace("_", " "),
                transform=transform, ha="center", va="top", fontsize=6, color="0.3")
    ax.set_xlim(edges[0], edges[-1])
