"""The still part of a plan's view in MeshCat: the cell's boxes, the predicted landing, the
camera and the background.

The boxes are the ones the arm's clearance is checked against (:meth:`CellConfig.boxes`: the
grill and the table up to their surfaces, the back wall, drawn translucent so that it does
not hide the arm). The landing is drawn as the plan records it
(:class:`~flipkit.viz.motion.Landing`): a red disc of radius ``r_land`` about the target, a
translucent green disc of the burger's diameter centred on the predicted landing point (on
the grill, or the serve's spot on the table) and the flight's arc as an orange line.
Every node sits under :data:`ROOT` (drawn shifted so that the camera orbits about
:data:`CENTER`, :func:`draw_cell`); lengths are in metres.
"""

from __future__ import annotations

import meshcat
import meshcat.geometry as mg
import meshcat.transformations as mt
import numpy as np

from flipkit.config import CellConfig
from flipkit.viz.motion import Landing

ROOT = "flipkit"  # every node of the view is under /flipkit
COLORS = {"grill": 0x303030, "table": 0xB08A5A, "wall": 0xDDDDD0, "arm": 0x8FA3B8,
          "blade": 0xB8BCC4, "handle": 0x202020, "burger": 0x6B3A1E, "target": 0xD02020,
          "landing": 0x20A040, "arc": 0xF08020}
WALL_OPACITY = 0.25
BACKGROUND = ([0.97, 0.97, 0.97], [0.80, 0.82, 0.85])  # top, bottom (RGB in [0, 1])
CENTER = (0.5, -0.1, 0.2)  # m, the point the view orbits about (drawn at MeshCat's origin)
CAMERA_OFFSET = (0.3, 0.95, 0.65)  # m, camera from CENTER: on the blade's carrying side
MARK_HEIGHT = 0.0005  # m: the landing discs' thickness (and lift above the surface)
Y_TO_Z = mt.rotation_matrix(np.pi / 2, [1.0, 0.0, 0.0])  # three.js cylinders are along y


def material(name: str, opacity: float = 1.0) -> mg.MeshLambertMaterial:
    """A matte material of :data:`COLORS` ``name`` (opacity in [0, 1])."""
    return mg.MeshLambertMaterial(color=COLORS[name], opacity=opacity)


def cylinder(node: meshcat.Visualizer, length: float, radius: float, mat) -> None:
    """A cylinder along the node's z axis (m), centred on its origin."""
    node["shape"].set_object(mg.Cylinder(length, radius), mat)
    node["shape"].set_transform(Y_TO_Z)


def draw_cell(vis: meshcat.Visualizer, cell: CellConfig) -> None:
    """The cell's boxes under ``/flipkit/cell``, the background and the camera.

    MeshCat's camera orbits about its origin, so ``/flipkit`` is drawn shifted by −:data:`CENTER`
    (the cell's world frame is ``/flipkit``'s: draw more under it) and MeshCat's own grid and
    axes at its origin are hidden.
    """
    vis[ROOT].set_transform(mt.translation_matrix(-np.asarray(CENTER)))
    vis["/Grid"].set_property("visible", False)
    vis["/Axes"].set_property("visible", False)
    for box in cell.boxes():
        name = box.name if box.name in COLORS else "wall"
        opacity = WALL_OPACITY if name == "wall" else 1.0
        node = vis[f"{ROOT}/cell/{box.name}"]
        node.set_object(mg.Box(box.size), material(name, opacity))
        node.set_transform(mt.translation_matrix(box.center))
    vis["/Background"].set_property("top_color", BACKGROUND[0])
    vis["/Background"].set_property("bottom_color", BACKGROUND[1])
    dx, dy, dz = CAMERA_OFFSET  # the camera's parent turns y up: (x, y, z) -> (x, z, -y)
    vis["/Cameras/default/rotated/<object>"].set_property("position", [dx, dz, -dy])


def draw_landing(vis: meshcat.Visualizer, landing: Landing | None, diameter: float) -> None:
    """The target, the predicted landing spot (``diameter``: the burger's, m) and the flight's
    arc under ``/flipkit/landing``; nothing for a plan without a landing."""
    if landing is None:
        return
    node = vis[f"{ROOT}/landing"]
    if landing.radius > 0:
        cylinder(node["target"], MARK_HEIGHT, landing.radius, material("target", 0.8))
        node["target"].set_transform(mt.translation_matrix(landing.target + [0, 0, MARK_HEIGHT]))
    spot = landing.point.copy()
    spot[2] = landing.target[2] + 2 * MARK_HEIGHT
    cylinder(node["spot"], MARK_HEIGHT, diameter / 2, material("landing", 0.45))
    node["spot"].set_transform(mt.translation_matrix(spot))
    if len(landing.arc) > 1:
        node["arc"].set_object(mg.Line(mg.PointsGeometry(np.asarray(landing.arc, float).T),
                                       mg.LineBasicMaterial(color=COLORS["arc"])))
