"""The arm's solid shapes and their distances to the cell's boxes, with analytic gradients.

Shapes (all moving with a joint of the arm, named as in :data:`ArmShapes.names`):

* every link's collision mesh of the URDF (UR10: shoulder, upper arm, forearm, three wrists)
  as its convex hull (coal's qhull): a hull contains its mesh, so a hull clear of a box
  means the link is; it fills the link's concave parts (a few mm to cm, on the safe side)
  and gives GJK a convex shape. The URDF's ``ee_link`` collision box is kept too. The base
  link does not move and is left out.
* the spatula handle: a capsule on the tool axis from the flange to the blade's heel, of
  radius ``cell.space.handle_radius`` (our choice, :mod:`flipkit.config.space`);
* the blade: a box of the spatula's length, width and thickness under its carrying face.

Distances come from coal (the collision library shipped with pinocchio): signed, negative
for penetration (coal's EPA depth). The gradient of the distance d between a shape and a
fixed box is ∂d/∂q = −nᵀ (J_v − [r]× J_ω), with n coal's unit normal from the shape's
witness point to the box's, r the witness point relative to the joint origin and
(J_v, J_ω) the joint's world-aligned Jacobian (pinocchio). It is exact wherever the witness
pair is unique, i.e. almost everywhere, for separated and penetrating pairs alike
(tests/test_clearance.py checks it against finite differences on the UR10).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from flipkit.config import CellConfig
from flipkit.config.urdf import robots_dir
from flipkit.errors import ConfigError
from flipkit.model.robot import LWA, Robot, skew

BLADE, HANDLE = "blade", "handle"
# GJK's stopping tolerance (m). coal's default, 1e-6, leaves distances off by more than the
# finite differences of the gradient tests and the SQP's line search can tell from a change
# of the configuration; 1e-9 makes a query somewhat dearer (docs/history.md).
GJK_TOLERANCE = 1e-9


_GENERIC_ROTATION = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])


def _box_probe() -> float:
    """A box–box distance that reads 0.3 with coal's exact box support and
    0.3 − 1.7e-11 with the inflated one."""
    req = coal.DistanceRequest()
    req.gjk_tolerance = GJK_TOLERANCE
    return float(coal.distance(
        coal.Box(0.2, 0.1, 0.3), coal.Transform3s(_GENERIC_ROTATION, np.array([0.31, -0.27, 0.52])),
        coal.Box(1.0, 1.0, 0.1), coal.Transform3s(np.eye(3), np.zeros(3)), req,
        coal.DistanceResult()))


def pin_box_support() -> bool:
    """Make coal's first Box support query of the process one with no zero direction
    component, and say whether coal's boxes are exact in this process.

    coal (3.0.x) keeps in its Box support function a function-local
    ``static const CoalScalar inflate = (dir.array() == 0).any() ? 1 + 1e-10 : 1.;``
    (``coal/narrowphase/support_functions.h``): the first Box support query of the process
    decides, for every later one, whether a box's negative half-sides are inflated by 1e-10
    relative. Left to chance, the process's history would decide — a box–box pair (the blade
    or the ee box against a cell box, the blade against the burger in verify) puts GJK's
    default guess (1, 0, 0) in the box's frame and inflates; a link's hull against the grill
    does not — and distances would differ in their last digits, enough for the SQP to end at
    another point of the solution set. This state is coal's, one per process, and cannot be
    passed to anyone: loading this module calls this function (:data:`BOX_SUPPORT_EXACT`)
    before flipkit makes any other coal query, so every flipkit process computes the same
    distances. Calling it again changes nothing (coal's choice is made) and reports it.

    Returns:
        True if coal's boxes are exact, False if a Box query made before flipkit's (outside
        flipkit) left them inflated: distances then differ from other processes' by ~1e-11 m.
    """
    # An ellipsoid first (GJK's first direction (−1, 0, 0) is its own), the box second,
    # turned so that the direction in its frame, the rotation's first row, has no zero.
    coal.distance(coal.Ellipsoid(0.1, 0.12, 0.14), coal.Transform3s(np.eye(3), np.zeros(3)),
                  coal.Box(1.0, 1.0, 1.0),
                  coal.Transform3s(_GENERIC_ROTATION, np.array([2.0, 0.3, 0.2])),
                  coal.DistanceRequest(), coal.DistanceResult())
    return abs(_box_probe() - 0.3) <= 1e-13


# Whether coal's boxes are exact in this process: pinned when this module loads, before any
# other flipkit query (pin_box_support), and fixed from then on by coal itself.
BOX_SUPPORT_EXACT = pin_box_support()
if not BOX_SUPPORT_EXACT:
    warnings.warn("coal's Box support was first used before flipkit in this process and "
                  "inflates boxes by 1e-10: collision distances (and so plans) may differ "
                  "from other processes' in their last digits", RuntimeWarning, stacklevel=2)


def distance_request():
    """A coal DistanceRequest with :data:`GJK_TOLERANCE` (coal's box support was pinned
    when this module loaded, :func:`pin_box_support`)."""
    req = coal.DistanceRequest()
    req.gjk_tolerance = GJK_TOLERANCE
    return req


def sphere_box_bound(centers, radii, lo, hi) -> np.ndarray:
    """Lower bounds (m) of the distances of spheres to axis-aligned boxes: centre-to-box
    distance minus radius, for ``centers`` (..., shapes, 3) and ``radii`` (shapes,) against
    boxes ``lo``, ``hi`` (boxes, 3); shape (..., shapes, boxes). Bounding spheres of the arm's
    shapes give the broad phase of the NLP's clearance rows and of verify's space check."""
    c = np.asarray(centers, float)[..., None, :]
    out = np.maximum(np.maximum(lo - c, c - hi), 0.0)
    return np.sqrt((out**2).sum(-1)) - np.asarray(radii)[:, None]


@dataclass
class Shape:
    """One rigid shape of the arm: a coal geometry at ``placement`` in joint ``joint``'s frame,
    with a bounding sphere (``center`` in the shape's own frame, ``radius``, m) for broad
    phase."""

    name: str
    joint: int
    placement: pin.SE3
    geometry: object
    center: np.ndarray
    radius: float


def _bounding_sphere(geometry) -> tuple[np.ndarray, float]:
    geometry.computeLocalAABB()
    return np.array(geometry.aabb_center), float(geometry.aabb_radius)


class ArmMeshes:
    """The URDF's collision meshes of the arm, loaded once per (URDF, joints) by whoever
    holds this and shared by every :class:`ArmShapes` built with it.

    Loading the meshes and building their hulls is not cheap, and a planner builds shapes
    for its models and again for every plan's verification: a planner's owner keeps one
    (:class:`~flipkit.planning.planners.caches.PlannerCaches`). The coal geometries are never
    modified after loading, so the shapes that share them stay independent.
    """

    def __init__(self):
        self._loaded: dict[tuple, list[Shape]] = {}

    def shapes(self, robot: Robot) -> list[Shape]:
        """The URDF's collision geometries on moving joints, meshes as their convex hulls
        (:func:`load_mesh_shapes`): new :class:`Shape` records around the shared geometries.

        Raises:
            ConfigError: The meshes cannot be loaded.
        """
        key = (str(robot.urdf), tuple(robot.model.names))
        if key not in self._loaded:
            self._loaded[key] = load_mesh_shapes(robot)
        return [Shape(s.name, s.joint, s.placement.copy(), s.geometry, s.center.copy(), s.radius)
                for s in self._loaded[key]]


def load_mesh_shapes(robot: Robot) -> list[Shape]:
    """The URDF's collision geometries on moving joints, meshes as their convex hulls (the
    base, fixed to the world, left out).

    Raises:
        ConfigError: The meshes cannot be loaded.
    """
    dirs = [str(robots_dir().parent.parent)] if robots_dir() is not None else []
    try:
        gmodel = pin.buildGeomFromUrdf(robot.model, robot.urdf, pin.COLLISION, package_dirs=dirs)
    except (ValueError, RuntimeError) as exc:
        raise ConfigError(f"collision meshes of {robot.urdf} cannot be loaded: {exc}") from None
    shapes = []
    for go in gmodel.geometryObjects:
        if go.parentJoint == 0:  # fixed to the world (the base): its distances never change
            continue
        geom = go.geometry
        if isinstance(geom, coal.BVHModelBase):
            geom.buildConvexHull(True, "Qt")
            geom = geom.convex
        name = robot.model.frames[go.parentFrame].name.removesuffix("_link")
        center, radius = _bounding_sphere(geom)
        shapes.append(Shape(name, go.parentJoint, go.placement.copy(), geom, center, radius))
    return shapes


class ArmShapes:
    """The arm's shapes (the URDF's link meshes, handle, blade) and the cell's boxes.

    Args:
        robot: The arm with its spatula frame.
        cell: Cell (boxes, margin, spatula); default ``robot.cell``.
        meshes: The loaded link meshes to take the links' shapes from (default: the
            URDF's, loaded for these shapes alone, :func:`load_mesh_shapes`).
    """

    def __init__(self, robot: Robot, cell: CellConfig | None = None,
                 meshes: ArmMeshes | None = None):
        self.robot, self.cell = robot, cell or robot.cell
        sp = self.cell.spatula
        shapes = load_mesh_shapes(robot) if meshes is None else meshes.shapes(robot)
        tool = robot.spatula_in_joint * pin.SE3(self._tool_in_spatula())
        handle_len = sp.handle - sp.length / 2
        if handle_len > 0:  # capsule along the tool z axis, flange to heel
            cap = coal.Capsule(self.cell.space.handle_radius, handle_len)
            pl = tool * pin.SE3(np.eye(3), np.array([0.0, 0.0, handle_len / 2]))
            shapes.append(Shape(HANDLE, robot.joint_id, pl, cap, np.zeros(3),
                                handle_len / 2 + self.cell.space.handle_radius))
        blade = coal.Box(sp.length, sp.width, sp.thickness)
        pl = robot.spatula_in_joint * pin.SE3(np.eye(3), np.array([0.0, 0.0, -sp.thickness / 2]))
        shapes.append(Shape(BLADE, robot.joint_id, pl, blade, np.zeros(3),
                            float(np.linalg.norm([sp.length, sp.width, sp.thickness]) / 2)))
        self.shapes = shapes
        self._joints = sorted({s.joint for s in shapes})
        self._radii = np.array([s.radius for s in shapes])
        self.names = tuple(s.name for s in shapes)
        if len(set(self.names)) != len(self.names):
            raise ConfigError(f"arm shape names are not unique: {self.names}")
        self.boxes = self.cell.boxes()
        self.box_names = tuple(b.name for b in self.boxes)
        self._lo = np.array([b.lower for b in self.boxes], float)
        self._hi = np.array([b.upper for b in self.boxes], float)
        self._box_geoms = [(coal.Box(*b.size), coal.Transform3s(np.eye(3), np.array(b.center)),
                            np.array(b.lower), np.array(b.upper)) for b in self.boxes]
        # each shape in its joint's frame, for :meth:`nearest_nodes`' array arithmetic
        self._joint_of = np.array([self._joints.index(s.joint) for s in shapes])
        self._R_in_joint = np.array([s.placement.rotation for s in shapes])
        self._p_in_joint = np.array([s.placement.translation for s in shapes])
        self._c_in_joint = np.array([s.placement.act(s.center) for s in shapes])

    def _tool_in_spatula(self) -> np.ndarray:
        """Placement of the tool flange in the spatula frame (inverse of the spatula's mount)."""
        return np.linalg.inv(self.robot.spatula_in_parent)

    def shape_index(self, name: str) -> int:
        """Index of the shape ``name`` (ConfigError if there is none)."""
        if name not in self.names:
            raise ConfigError(f"no arm shape {name!r}; shapes: {', '.join(self.names)}")
        return self.names.index(name)

    def box_index(self, name: str) -> int:
        """Index of the cell box ``name`` (ConfigError if there is none)."""
        if name not in self.box_names:
            raise ConfigError(f"no cell box {name!r}; boxes: {', '.join(self.box_names)}")
        return self.box_names.index(name)

    def _place(self, q) -> list[pin.SE3]:
        """Forward kinematics and joint Jacobians at q; the world placement of every shape."""
        m, d = self.robot.model, self.robot.data
        pin.computeJointJacobians(m, d, np.asarray(q, float))
        joints = {j: d.oMi[j] for j in self._joints}
        return [joints[s.joint] * s.placement for s in self.shapes]

    def _query(self, k: int, R: np.ndarray, p: np.ndarray, b: int, req, res):
        """coal distance of shape k at world placement (R, p) to box b: (d, witness on the
        shape, unit normal from the shape to the box)."""
        geom, tf, _, _ = self._box_geoms[b]
        res.clear()
        d = coal.distance(self.shapes[k].geometry, coal.Transform3s(R, p), geom, tf, req, res)
        return float(d), np.array(res.getNearestPoint1()), np.array(res.normal)

    def nearest(self, q, pairs, cap: float = np.inf) -> tuple[float, np.ndarray, int, int]:
        """The least distance (m) over the (shape index, box index) ``pairs`` at q, capped at
        ``cap``: (min(cap, d), its gradient ∂/∂q, the nearest pair's shape and box indices;
        −1, −1 and a zero gradient when every pair lies farther than ``cap``). A broad phase
        by bounding spheres skips the pairs that cannot be nearer; the minimum is exact
        (:meth:`nearest_nodes` at one configuration)."""
        allowed = np.zeros((1, len(self.shapes), len(self.boxes)), bool)
        allowed[0, pairs[:, 0], pairs[:, 1]] = True
        dist, grad, shape, box = self.nearest_nodes(np.asarray(q, float)[None], allowed, cap)
        return float(dist[0]), grad[0], int(shape[0]), int(box[0])

    def nearest_nodes(self, qs, allowed, cap: float = np.inf):
        """:meth:`nearest` at n configurations at once, the broad phase of all of them in one
        array operation (per node, :meth:`nearest` spends more time in NumPy calls on a few
        dozen pairs than in coal's queries).

        Args:
            qs: (n, nq) configurations (rad).
            allowed: (n, shapes, boxes) booleans: the pairs applied at each configuration.
            cap: Distances beyond it read as ``cap`` (m), with a zero gradient.

        Returns:
            (d (n,), ∂d/∂q (n, nq), nearest shape (n,), nearest box (n,)), as :meth:`nearest`
            at each configuration (indices −1 where every pair lies beyond ``cap``).
        """
        m, data = self.robot.model, self.robot.data
        qs = np.asarray(qs, float)
        n, nb = len(qs), len(self.boxes)
        H = np.empty((n, len(self._joints), 4, 4))
        for i, q in enumerate(qs):
            pin.forwardKinematics(m, data, q)
            for jj, j in enumerate(self._joints):
                H[i, jj] = data.oMi[j].homogeneous
        Hs = H[:, self._joint_of]  # (n, shapes, 4, 4): each shape's joint placement
        Rj, pj = Hs[..., :3, :3], Hs[..., :3, 3]
        Rw = np.einsum("nsij,sjk->nsik", Rj, self._R_in_joint)  # the shapes' world placements
        pw = np.einsum("nsij,sj->nsi", Rj, self._p_in_joint) + pj
        c = np.einsum("nsij,sj->nsi", Rj, self._c_in_joint) + pj
        bound = sphere_box_bound(c, self._radii, self._lo, self._hi)
        bound = np.where(allowed, bound, np.inf).reshape(n, -1)
        dist, grad = np.full(n, float(cap)), np.zeros((n, self.robot.nq))
        shape, box = np.full(n, -1), np.full(n, -1)
        req, res = distance_request(), coal.DistanceResult()
        for i in range(n):
            best = (float(cap), None, None)
            for j in np.argsort(bound[i], kind="stable"):
                if bound[i, j] >= best[0]:
                    break
                k, b = divmod(int(j), nb)
                d, p1, normal = self._query(k, Rw[i, k], pw[i, k], b, req, res)
                if d < best[0]:
                    best, shape[i], box[i] = (d, p1, normal), k, b
            dist[i] = best[0]
            if shape[i] >= 0:
                pin.computeJointJacobians(m, data, qs[i])
                grad[i] = self._gradient(shape[i], best[1], best[2])
        return dist, grad, shape, box

    def _gradient(self, k: int, p1: np.ndarray, n: np.ndarray) -> np.ndarray:
        """∂d/∂q = −nᵀ (J_v − [r]× J_ω) of shape k's witness point p1 (after pinocchio's
        ``computeJointJacobians`` at the configuration, as :meth:`_place` runs it)."""
        joint = self.shapes[k].joint
        J = pin.getJointJacobian(self.robot.model, self.robot.data, joint, LWA)
        r = p1 - self.robot.data.oMi[joint].translation
        return -(n @ (J[:3] - skew(r) @ J[3:]))

    def distance(self, q, shape: int, box: int) -> tuple[float, np.ndarray]:
        """Distance (m) of one shape to one box at q and its gradient ∂d/∂q."""
        placed = self._place(q)
        M = placed[shape]
        dist, p1, n = self._query(shape, M.rotation, M.translation, box, distance_request(),
                                  coal.DistanceResult())
        return dist, self._gradient(shape, p1, n)
