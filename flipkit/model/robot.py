"""The arm with its spatula: pinocchio model, spatula kinematics and inverse dynamics.

Every derivative comes from pinocchio's analytic algorithms (forward-kinematics, frame
velocity, point classical acceleration and RNEA derivatives); tests compare them with
central finite differences.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from flipkit.config import CellConfig
from flipkit.config.arm import arm_profile
from flipkit.config.urdf import default_urdf
from flipkit.errors import ConfigError

SPATULA_FRAME = "spatula"
# the blade's corners (±l/2, ±w/2) as signs (a, b): tip left, tip right, heel left, heel right
BLADE_CORNERS = ((1, 1), (1, -1), (-1, 1), (-1, -1))
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def skew(w: np.ndarray) -> np.ndarray:
    """3x3 matrix [w]× with [w]× v = w × v; over leading axes for w of shape (..., 3)."""
    w = np.asarray(w)
    if w.ndim == 1:
        return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    S = np.zeros(w.shape + (3,))
    S[..., 0, 1], S[..., 0, 2], S[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    S[..., 1, 0], S[..., 2, 0], S[..., 2, 1] = w[..., 2], -w[..., 1], w[..., 0]
    return S


def _matvec(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    """M x over a leading node axis: (n, i, j), (n, j) -> (n, i)."""
    return (M @ x[..., None])[..., 0]


@dataclass
class SpatulaState:
    """Spatula kinematics at one (q, q̇, q̈), world frame, with Jacobians; or at several, every
    field then with a leading node axis (see :meth:`Robot.states`).

    Attributes:
        p: Blade-centre position (m). R: Rotation spatula→world.
        v: Velocity (m/s). a: Classical acceleration (m/s²).
        dp_dq: ∂p/∂q (3x6). Jw: Angular Jacobian, dR = [Jw dq]× R (3x6).
        dv_dq, dv_dqd: ∂v/∂q, ∂v/∂q̇. da_dq, da_dqd, da_dqdd: ∂a/∂(q, q̇, q̈).
    """

    p: np.ndarray
    R: np.ndarray
    v: np.ndarray
    a: np.ndarray
    dp_dq: np.ndarray
    Jw: np.ndarray
    dv_dq: np.ndarray
    dv_dqd: np.ndarray
    da_dq: np.ndarray
    da_dqd: np.ndarray
    da_dqdd: np.ndarray

    def __len__(self) -> int:
        """Number of nodes of a batch."""
        return len(self.p)

    def take(self, index) -> SpatulaState:
        """The states at ``index`` of the node axis (an int: one node's state; a slice or an
        index array: a batch)."""
        return SpatulaState(self.p[index], self.R[index], self.v[index], self.a[index],
                            self.dp_dq[index], self.Jw[index], self.dv_dq[index],
                            self.dv_dqd[index], self.da_dq[index], self.da_dqd[index],
                            self.da_dqdd[index])


class Robot:
    """Pinocchio model of the arm plus a spatula frame and payload bodies.

    Args:
        cell: Cell configuration (robot, spatula, burger, gravity).
        with_burger: Add the burger to the payload (it rides on the blade).

    Joint limits are the arm profile's (``cell.robot.profile``, :mod:`flipkit.config.arm`):
    ``qd_limit`` the published speeds (rad/s), ``qd_max`` the speeds plans keep to
    (``speed_margin`` of them), ``q_min``/``q_max`` (rad) and ``u_max`` (N·m) within both the
    URDF's and the profile's.
    """

    def __init__(self, cell: CellConfig | None = None, with_burger: bool = False):
        self.cell = cell or CellConfig()
        rc = self.cell.robot
        self.urdf = rc.urdf_path
        model = pin.buildModelFromUrdf(self.urdf)
        if not model.existFrame(rc.tool_frame):
            names = ", ".join(f.name for f in model.frames)
            raise ConfigError(f"tool frame {rc.tool_frame!r} not in URDF; frames: {names}")
        base = pin.SE3(np.asarray(rc.base_in_world, dtype=float))
        for j in range(1, model.njoints):  # joints hanging from the universe move with the base
            if model.parents[j] == 0:
                model.jointPlacements[j] = base * model.jointPlacements[j]
        model.gravity = pin.Motion(np.array(self.cell.gravity), np.zeros(3))
        tool = model.frames[model.getFrameId(rc.tool_frame)]
        self.spatula_in_parent = np.asarray(self.cell.spatula.placement_in_tool())
        in_joint = tool.placement * pin.SE3(self.spatula_in_parent)
        self.joint_id = tool.parentJoint
        model.addFrame(pin.Frame(SPATULA_FRAME, tool.parentJoint, model.getFrameId(rc.tool_frame),
                                 in_joint, pin.FrameType.OP_FRAME))
        self.payload = self._payload(with_burger)
        for body in self.payload:
            model.inertias[self.joint_id] += in_joint.act(body["inertia_obj"])
        self.model, self.data = model, model.createData()
        self.frame_id = model.getFrameId(SPATULA_FRAME)
        self.spatula_in_joint = in_joint
        self._placements = {}
        self.nq = model.nq
        self._minus_identity = -np.eye(self.nq)  # ∂r/∂u, shared read-only
        self._minus_identity.setflags(write=False)
        if self.nq != len(rc.q_home):
            raise ConfigError(f"q_home has {len(rc.q_home)} entries, robot has {self.nq} joints")
        self.q_home = np.array(rc.q_home)
        self.profile = arm_profile(rc.profile)
        self._apply_profile(model, default=self.urdf == default_urdf())
        self.qd_limit = np.array(self.profile.qd_max)
        self.qd_max = np.minimum(model.velocityLimit, rc.speed_margin * self.qd_limit)
        self.q_min, self.q_max = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
        self.u_max = model.effortLimit.copy()
        self.qdd_max = np.full(self.nq, rc.accel_limit)
        self.qdd_free = np.full(self.nq, float(rc.free_accel_limit))

    def _apply_profile(self, model, default: bool) -> None:
        """Hold the model's joint limits to the arm profile's (:mod:`flipkit.config.arm`).

        The package's default URDF (example-robot-data's UR10) rounds UR's joint speeds up
        (2.16 rad/s for 2.094, 3.2 for 3.142): its limits are cut to the profile's. A URDF of
        the user's that states looser limits than the profile is refused: it claims an arm
        the maker does not sell.

        Raises:
            ConfigError: The URDF's joints are not the profile's, or (a user's URDF) a joint's
                position range, speed or torque exceeds the profile's.
        """
        prof = self.profile
        names = tuple(model.names[1:])
        if names != prof.joints:
            raise ConfigError(f"URDF joints {', '.join(names)} are not the {prof.model}'s "
                              f"({', '.join(prof.joints)}); choose another arm profile")
        published = {"speed": (model.velocityLimit, np.array(prof.qd_max), "rad/s"),
                     "torque": (model.effortLimit, np.array(prof.u_max), "N·m"),
                     "upper position": (model.upperPositionLimit, np.array(prof.q_range), "rad"),
                     "lower position": (-model.lowerPositionLimit, np.array(prof.q_range), "rad")}
        for what, (urdf, limit, unit) in published.items():
            over = np.flatnonzero(urdf > limit * (1 + 1e-9))
            if over.size and not default:
                j = int(over[0])
                raise ConfigError(f"URDF {self.urdf}: {names[j]}'s {what} limit {urdf[j]:.4g} "
                                  f"{unit} exceeds the {prof.model}'s published {limit[j]:.4g} "
                                  f"{unit}; give a URDF within the arm's limits")
        model.velocityLimit = np.minimum(model.velocityLimit, prof.qd_max)
        model.effortLimit = np.minimum(model.effortLimit, prof.u_max)
        model.upperPositionLimit = np.minimum(model.upperPositionLimit, prof.q_range)
        model.lowerPositionLimit = np.maximum(model.lowerPositionLimit, -np.array(prof.q_range))

    def qdd_bound(self, free_motion: bool) -> np.ndarray:
        """Joint acceleration bound (rad/s²) of a segment: :attr:`qdd_free` for a free
        motion (it neither carries nor touches the burger), else :attr:`qdd_max`."""
        return self.qdd_free if free_motion else self.qdd_max

    def _payload(self, with_burger: bool) -> list[dict]:
        """Payload bodies in the spatula frame: the blade (thin plate) and the burger (disc)."""
        sp, bg = self.cell.spatula, self.cell.burger
        bodies = [("spatula", sp.mass, np.zeros(3),
                   pin.Inertia.FromBox(sp.mass, sp.length, sp.width, sp.thickness))]
        if with_burger:
            com = np.array([0.0, 0.0, (sp.thickness + bg.thickness) / 2])
            bodies.append(("burger", bg.mass, com, pin.Inertia.FromCylinder(
                bg.mass, bg.diameter / 2, bg.thickness)))
        out = []
        for name, mass, com, inertia in bodies:
            body = pin.Inertia(mass, com, inertia.inertia)
            out.append({"name": name, "parent_frame": SPATULA_FRAME, "mass": mass,
                        "com": com, "inertia": body.inertia.copy(), "inertia_obj": body})
        return out

    # ----------------------------------------------------------------- kinematics
    def placement(self, q) -> pin.SE3:
        """World placement of the spatula frame at q."""
        pin.framesForwardKinematics(self.model, self.data, np.asarray(q, dtype=float))
        return self.data.oMf[self.frame_id].copy()

    def position(self, q) -> np.ndarray:
        """Blade-centre position p(q) (m)."""
        return self.placement(q).translation

    def rotation(self, q) -> np.ndarray:
        """Rotation R(q) of the spatula frame in the world."""
        return self.placement(q).rotation

    def pose_jacobians(self, q) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """p, R, ∂p/∂q and the angular Jacobian Jw (dR = [Jw dq]× R) at q."""
        q = np.asarray(q, dtype=float)
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        J = pin.getFrameJacobian(self.model, self.data, self.frame_id, LWA)
        M = self.data.oMf[self.frame_id]
        return M.translation.copy(), M.rotation.copy(), J[:3].copy(), J[3:].copy()

    def state(self, q, qd, qdd, point=None) -> SpatulaState:
        """Spatula position, orientation, velocity, classical acceleration and Jacobians.

        Args:
            q, qd, qdd: Joint state (rad, rad/s, rad/s²).
            point: A point of the blade in the spatula frame (m) whose position, velocity
                and acceleration to give instead of the blade centre's (e.g. where the burger
                lies); the rotation is the spatula's either way.
        """
        q, qd, qdd = (np.asarray(x, dtype=float)[None] for x in (q, qd, qdd))
        if point is None:
            return self.states(q, qd, qdd)[0].take(0)
        return self.states(q, qd, qdd, [point])[1][0].take(0)

    def states(self, q, qd, qdd, points=()) -> tuple[SpatulaState, list[SpatulaState]]:
        """:meth:`state` at n joint states at once: the blade centre's and each blade point's.

        One forward-kinematics pass per joint state serves the centre and every point: a
        point r (spatula frame) moves with the blade, p_r = p + R r, v_r = v + ω × R r,
        a_r = a + α × R r + ω × (ω × R r), its velocity and acceleration derivatives from
        pinocchio's point classical-acceleration derivatives.

        Args:
            q, qd, qdd: Joint states (n, nq) (rad, rad/s, rad/s²).
            points: Blade points (spatula frame, m).

        Returns:
            The centre's states and one batch per point, each field with a leading axis of n.
        """
        m, d, fid, jid = self.model, self.data, self.frame_id, self.joint_id
        q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
        n, nq = q.shape
        points = [np.asarray(r, dtype=float) for r in points]
        placements = [self._point_placement(None)] + [self._point_placement(r) for r in points]
        p, acc, alpha = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
        R, J = np.empty((n, 3, 3)), np.empty((n, 6, nq))
        # per placement: ∂v/∂q, ∂a/∂q, ∂a/∂q̇, ∂a/∂q̈
        D = np.empty((len(placements), 4, n, 3, nq))
        for k in range(n):
            # also fills the joint Jacobians data.J that getFrameJacobian reads
            pin.computeForwardKinematicsDerivatives(m, d, q[k], qd[k], qdd[k])
            pin.updateFramePlacements(m, d)
            M = d.oMf[fid]
            p[k], R[k] = M.translation, M.rotation
            J[k] = pin.getFrameJacobian(m, d, fid, LWA)
            acc[k] = pin.getFrameClassicalAcceleration(m, d, fid, LWA).linear
            if points:
                alpha[k] = pin.getFrameAcceleration(m, d, fid, LWA).angular
            for j, placement in enumerate(placements):
                D[j, :, k] = pin.getPointClassicAccelerationDerivatives(m, d, jid, placement, LWA)
        Jv, Jw = J[:, :3], J[:, 3:]
        v = _matvec(Jv, qd)
        centre = SpatulaState(p=p, R=R, v=v, a=acc, dp_dq=Jv, Jw=Jw, dv_dq=D[0, 0], dv_dqd=Jv,
                              da_dq=D[0, 1], da_dqd=D[0, 2], da_dqdd=D[0, 3])
        out = []
        if points:
            W, A = skew(_matvec(Jw, qd)), skew(alpha)  # [ω]×, [α]×
        for j, r_local in enumerate(points, 1):
            r = R @ r_local
            wr = _matvec(W, r)
            Jv_r = Jv - skew(r) @ Jw
            out.append(SpatulaState(p=p + r, R=R, v=v + wr,
                                    a=acc + _matvec(A, r) + _matvec(W, wr),
                                    dp_dq=Jv_r, Jw=Jw, dv_dq=D[j, 0], dv_dqd=Jv_r,
                                    da_dq=D[j, 1], da_dqd=D[j, 2], da_dqdd=D[j, 3]))
        return centre, out

    def _point_placement(self, point) -> pin.SE3:
        """The joint-frame placement of a blade point (spatula frame, m; None: the centre),
        kept per point: the SQP asks for the same few points at every node."""
        key = None if point is None else tuple(float(c) for c in point)
        placement = self._placements.get(key)
        if placement is None:
            placement = self.spatula_in_joint if key is None else (
                self.spatula_in_joint * pin.SE3(np.eye(3), np.array(key)))
            self._placements[key] = placement
        return placement

    def angular_velocity_jacobian(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """Spatula angular velocity ω = J_ω q̇ (world, rad/s) and ∂ω/∂q (3×nq); ∂ω/∂q̇ = J_ω.

        From pinocchio's frame velocity derivatives; only their angular rows are used (the
        linear rows of the LOCAL_WORLD_ALIGNED derivative are not ∂v/∂q of the frame origin —
        :meth:`state` gives that one)."""
        m, d = self.model, self.data
        q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
        pin.computeForwardKinematicsDerivatives(m, d, q, qd, np.zeros(self.nq))
        pin.updateFramePlacements(m, d)
        dv_dq, _ = pin.getFrameVelocityDerivatives(m, d, self.frame_id, LWA)
        w = pin.getFrameVelocity(m, d, self.frame_id, LWA).angular
        return np.array(w), np.array(dv_dq[3:])

    # ----------------------------------------------------------------- dynamics
    def inverse_dynamics(self, q, qd, qdd) -> np.ndarray:
        """D(q)q̈ + C(q,q̇)q̇ + G(q) by RNEA (N·m), payload included."""
        return pin.rnea(self.model, self.data, *(np.asarray(x, float) for x in (q, qd, qdd))).copy()

    def dynamics_residual(self, q, qd, qdd, u) -> np.ndarray:
        """Residual r = D q̈ + C q̇ + G − B u of eq. (1)/(7), with B = I (N·m)."""
        return self.inverse_dynamics(q, qd, qdd) - np.asarray(u, dtype=float)

    def dynamics_residual_jacobians(self, q, qd, qdd):
        """r and ∂r/∂q, ∂r/∂q̇, ∂r/∂q̈ (= D), ∂r/∂u (= −I) from RNEA derivatives."""
        q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
        dq, dqd, dqdd = pin.computeRNEADerivatives(self.model, self.data, q, qd, qdd)
        tau = self.data.tau.copy()
        return tau, np.array(dq), np.array(dqd), np.array(dqdd), self._minus_identity

    def payload_json(self) -> list[dict]:
        """The payload list of the plan file."""
        return [{"name": b["name"], "parent_frame": b["parent_frame"], "mass": float(b["mass"]),
                 "com": [float(x) for x in b["com"]],
                 "inertia": [[float(x) for x in row] for row in b["inertia"]]}
                for b in self.payload]
