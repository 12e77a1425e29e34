"""Independent check of the whole arm's space limits and the spatula's orientation limits.

From the plan's arrays alone: the arm's shapes (:class:`~flipkit.model.collision.ArmShapes`:
the URDF's link collision meshes as convex hulls, the handle's capsule, the blade's box) and
the cell's boxes go into a pinocchio ``GeometryModel``; pinocchio places them at each node
(``updateGeometryPlacements``) and coal measures each (shape, box) pair's distance. Nothing
here uses the NLP's :class:`~flipkit.transcription.constraints.clearance.ArmClearance` (its
minimum over shapes, its cap, its gradients). The pairs a segment exempts come from
the spec's ``exempt`` (:mod:`flipkit.behaviors.clearance`).

Group ``arm_clearance``: shortfall (m) of each applied pair's distance below the cell's
margin (``cell.space.margin``) at nodes 1..N (node 0 is the previous segment's last).
Group ``orientation``: the pitch o_y outside ``cell.limits.pitch_range`` (rad), nodes 1..N.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from flipkit.behaviors.library import SUBBEHAVIORS
from flipkit.model.collision import ArmShapes, distance_request, sphere_box_bound
from flipkit.model.orientation import rpy
import coal


class CellGeometry:
    """The arm's shapes and the cell's boxes as a pinocchio GeometryModel of ``robot``
    (the link meshes from ``meshes``, an :class:`~flipkit.model.collision.ArmMeshes`, if
    given, else loaded for this geometry)."""

    def __init__(self, robot, cell, meshes=None):
        self.robot, self.cell = robot, cell
        arm = ArmShapes(robot, cell, meshes)
        self.shape_names, self.box_names = arm.names, arm.box_names
        # bounding spheres (shape frame) and the boxes' corners, for the lower bounds of
        # :meth:`distances`
        self._centers = np.array([s.center for s in arm.shapes])
        self._radii = np.array([s.radius for s in arm.shapes])
        self._lo = np.array([b.lower for b in arm.boxes], float)
        self._hi = np.array([b.upper for b in arm.boxes], float)
        self.gmodel = pin.GeometryModel()
        for s in arm.shapes:
            self.gmodel.addGeometryObject(pin.GeometryObject(s.name, s.joint, s.placement,
                                                             s.geometry))
        for b in arm.boxes:
            self.gmodel.addGeometryObject(pin.GeometryObject(
                f"box:{b.name}", 0, pin.SE3(np.eye(3), np.array(b.center)), coal.Box(*b.size)))
        self.gdata = self.gmodel.createData()

    def distances(self, q, floor: float | None = None) -> np.ndarray:
        """Distance (m, negative: penetration depth) of every shape to every box at q, as an
        array (n shapes, n boxes).

        Args:
            q: Configuration (rad).
            floor: Pairs whose bounding sphere lies at least ``floor`` (m) from the box are
                not queried: they get that lower bound (≥ ``floor``) instead of their
                distance. A check of d ≥ floor reads the same either way; the default
                measures every pair.
        """
        pin.updateGeometryPlacements(self.robot.model, self.robot.data, self.gmodel, self.gdata,
                                     np.asarray(q, float))
        ns = len(self.shape_names)
        objs, places = self.gmodel.geometryObjects, self.gdata.oMg
        c = np.array([places[s].act(self._centers[s]) for s in range(ns)])
        out = sphere_box_bound(c, self._radii, self._lo, self._hi)
        req = distance_request()
        for b in range(len(self.box_names)):
            gb, Mb = objs[ns + b].geometry, places[ns + b]
            tb = coal.Transform3s(Mb.rotation, Mb.translation)
            for s in range(ns):
                if floor is not None and out[s, b] >= floor:
                    continue
                Ms = places[s]
                out[s, b] = coal.distance(objs[s].geometry,
                                          coal.Transform3s(Ms.rotation, Ms.translation),
                                          gb, tb, req, coal.DistanceResult())
        return out

    def applied(self, name: str, node: int, N: int) -> np.ndarray:
        """Mask (n shapes, n boxes) of the pairs segment ``name`` holds to the margin at node."""
        skip = SUBBEHAVIORS[name].exempt(node, N)
        return np.array([[(s, b) not in skip for b in self.box_names] for s in self.shape_names])


def segment_clearances(geometry: CellGeometry, seg, floor: float | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Distances (N+1, n shapes, n boxes) of segment ``seg`` (pairs surely beyond ``floor``:
    a lower bound, :meth:`CellGeometry.distances`) and the mask of applied pairs (node 0 never
    applied)."""
    d = np.array([geometry.distances(q, floor) for q in seg.q])
    mask = np.array([geometry.applied(seg.name, i, seg.N) if i else
                     np.zeros(d.shape[1:], bool) for i in range(seg.N + 1)])
    return d, mask


def check_space(report, k, seg, robot, cell, geometry: CellGeometry, tol: float) -> None:
    """Add the ``arm_clearance`` and ``orientation`` rows of segment k to ``report``."""
    margin = cell.space.margin
    # a pair whose bounding sphere is a margin away needs no measurement: its shortfall is 0
    d, mask = segment_clearances(geometry, seg, floor=margin)
    lo, hi = cell.limits.pitch_range
    for i in range(1, seg.N + 1):
        report.add("arm_clearance", k, np.maximum(margin - d[i][mask[i]], 0.0), tol, i)
        pitch = rpy(robot.rotation(seg.q[i]))[1]
        report.add("orientation", k, [max(lo - pitch, pitch - hi, 0.0)], tol, i)


def min_clearances(plan) -> dict:
    """Least distance (m) of each applied (shape, box) pair over the plan, with where:
    ``{"shape/box": {"distance": d, "segment": name, "node": i}}``."""
    cell = plan.cell()
    out, geometry = {}, None
    for seg in plan.segments:
        robot = plan.robot_for(seg, cell)
        geometry = geometry or CellGeometry(robot, cell)
        geometry.robot = robot
        d, mask = segment_clearances(geometry, seg)
        for s, shape in enumerate(geometry.shape_names):
            for b, box in enumerate(geometry.box_names):
                if not mask[:, s, b].any():
                    continue
                vals = np.where(mask[:, s, b], d[:, s, b], np.inf)
                i = int(np.argmin(vals))
                key = f"{shape}/{box}"
                if key not in out or vals[i] < out[key]["distance"]:
                    out[key] = {"distance": float(vals[i]), "segment": seg.name, "node": i}
    return out
