"""The arm's inverse dynamics and spatula kinematics as CasADi SX expressions.

The pinocchio wheel pinned by flipkit (3.8.0) has no ``pinocchio.casadi``, so exact-derivative
solvers (FATROP, exact-Hessian IPOPT) get the serial chain written out here from the numbers
of the pinocchio :class:`~flipkit.model.robot.Robot` model: each joint's placement in its
parent, its axis, each body's inertia (the spatula and burger payload included, as pinocchio
holds them) and the model's gravity. Everything is expressed in the world frame:

* forward pass, for each joint i with placement (R_p, t_p) in its parent and axis a_i:
  R_i = R_{i−1} R_p Rot(a_i, q_i), p_i = p_{i−1} + R_{i−1} t_p, z_i = R_i a_i,
  ω_i = ω_{i−1} + z_i q̇_i, ω̇_i = ω̇_{i−1} + ω_{i−1} × z_i q̇_i + z_i q̈_i,
  a_i = a_{i−1} + ω̇_{i−1} × r + ω_{i−1} × (ω_{i−1} × r), r = p_i − p_{i−1}
  (a_i the classical acceleration of the joint origin, base at rest);
* backward pass (Newton–Euler about each joint origin), body i with mass m, centre of mass
  c (world lever r_c = R_i c) and rotational inertia I_c about it (I_w = R_i I_c R_iᵀ):
  F_i = m (a_i + ω̇_i × r_c + ω_i × (ω_i × r_c) − g),
  n_i = I_w ω̇_i + ω_i × I_w ω_i + r_c × F_i + Σ_children (n_j + (p_j − p_i) × f_j),
  f_i = F_i + Σ_children f_j, τ_i = z_i · n_i (+ armature_i q̈_i).

Tests compare τ with ``pinocchio.rnea`` and the blade frame's pose, velocity and classical
acceleration with pinocchio at seeded random states.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from flipkit.errors import ConfigError
from flipkit.model.robot import Robot

_AXES = {"JointModelRX": (1.0, 0.0, 0.0), "JointModelRY": (0.0, 1.0, 0.0),
         "JointModelRZ": (0.0, 0.0, 1.0)}


def _axis_rotation(axis: np.ndarray, angle) -> ca.SX:
    """Rotation by ``angle`` (rad, symbolic) about the unit ``axis`` (Rodrigues)."""
    k = ca.DM(axis)
    K = ca.skew(k)
    return ca.DM.eye(3) + ca.sin(angle) * K + (1 - ca.cos(angle)) * (K @ K)


@dataclass
class Link:
    """One revolute joint and the body it carries, in numbers read from pinocchio.

    Attributes:
        R_parent, t_parent: Placement of the joint frame in its parent joint's frame.
        axis: Unit joint axis in the joint frame. mass: Body mass (kg).
        com: Centre of mass in the joint frame (m). inertia: 3x3 rotational inertia about
            the centre of mass, joint frame (kg·m²). armature: Rotor inertia (kg·m²).
    """

    R_parent: np.ndarray
    t_parent: np.ndarray
    axis: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    armature: float


@dataclass
class Kinematics:
    """Symbolic world-frame kinematics of one frame fixed to the last link.

    Attributes:
        p: Position (m). R: Rotation frame→world. v: Linear velocity (m/s).
        a: Classical linear acceleration (m/s²). w: Angular velocity (rad/s).
        dw: Angular acceleration (rad/s²).
    """

    p: ca.SX
    R: ca.SX
    v: ca.SX
    a: ca.SX
    w: ca.SX
    dw: ca.SX


class CasadiArm:
    """The serial chain of a :class:`Robot` as CasADi SX functions.

    Args:
        robot: The pinocchio model (its payload bodies are already in its last inertia).

    Raises:
        ConfigError: The model is not a serial chain of one-DOF revolute joints.
    """

    def __init__(self, robot: Robot):
        m = robot.model
        self.nq = m.nq
        if m.nv != m.nq or m.njoints != m.nq + 1:
            raise ConfigError("CasadiArm needs one one-DOF joint per configuration variable")
        self.links: list[Link] = []
        for j in range(1, m.njoints):
            joint = m.joints[j]
            if m.parents[j] != j - 1:
                raise ConfigError(f"joint {j} is not a child of joint {j - 1}: not a serial chain")
            name = joint.shortname()
            if name in _AXES:
                axis = np.array(_AXES[name])
            elif name == "JointModelRevoluteUnaligned":
                axis = np.asarray(joint.extract().axis, float)
            else:
                raise ConfigError(f"joint {j} has type {name}; CasadiArm handles revolute joints")
            M, inertia = m.jointPlacements[j], m.inertias[j]
            self.links.append(Link(R_parent=np.array(M.rotation), t_parent=np.array(M.translation),
                                   axis=axis, mass=float(inertia.mass),
                                   com=np.array(inertia.lever), inertia=np.array(inertia.inertia),
                                   armature=float(m.armature[j - 1])))
        self.gravity = np.array(m.gravity.linear)
        self.tool = robot.spatula_in_joint  # the spatula frame in the last joint's frame
        q, qd, qdd = (ca.SX.sym(s, self.nq) for s in ("q", "qd", "qdd"))
        self.rnea_function = ca.Function("rnea", [q, qd, qdd], [self.rnea(q, qd, qdd)])

    # ----------------------------------------------------------------- passes
    def _forward(self, q, qd, qdd):
        """Per joint: (R, p, z, ω, ω̇, v, a) in the world frame, symbolic."""
        R, p = ca.SX.eye(3), ca.SX.zeros(3)
        w, dw, v, a = ca.SX.zeros(3), ca.SX.zeros(3), ca.SX.zeros(3), ca.SX.zeros(3)
        out = []
        for i, L in enumerate(self.links):
            r = R @ ca.DM(L.t_parent)
            p_i = p + r
            v_i = v + ca.cross(w, r)
            a_i = a + ca.cross(dw, r) + ca.cross(w, ca.cross(w, r))
            R_i = R @ ca.DM(L.R_parent) @ _axis_rotation(L.axis, q[i])
            z = R_i @ ca.DM(L.axis)
            dw_i = dw + ca.cross(w, z) * qd[i] + z * qdd[i]
            w_i = w + z * qd[i]
            out.append((R_i, p_i, z, w_i, dw_i, v_i, a_i))
            R, p, w, dw, v, a = R_i, p_i, w_i, dw_i, v_i, a_i
        return out

    def rnea(self, q, qd, qdd) -> ca.SX:
        """Joint torques τ = D(q)q̈ + C(q, q̇)q̇ + G(q) (N·m), as pinocchio's RNEA."""
        frames = self._forward(q, qd, qdd)
        g = ca.DM(self.gravity)
        tau = [None] * self.nq
        f_next, n_next, p_next = ca.SX.zeros(3), ca.SX.zeros(3), None
        for i in reversed(range(self.nq)):
            L = self.links[i]
            R, p, z, w, dw, _, a = frames[i]
            rc = R @ ca.DM(L.com)
            Iw = R @ ca.DM(L.inertia) @ R.T
            F = L.mass * (a + ca.cross(dw, rc) + ca.cross(w, ca.cross(w, rc)) - g)
            n = Iw @ dw + ca.cross(w, Iw @ w) + ca.cross(rc, F)
            if p_next is not None:
                n = n + n_next + ca.cross(p_next - p, f_next)
                F = F + f_next
            tau[i] = ca.dot(z, n) + L.armature * qdd[i]
            f_next, n_next, p_next = F, n, p
        return ca.vertcat(*tau)

    def frame(self, q, qd, qdd, point=None) -> Kinematics:
        """Kinematics of the spatula frame (blade centre), or of a blade ``point`` given in the
        spatula frame (m), at the symbolic state (q, q̇, q̈); the rotation is the spatula's."""
        R, p, _, w, dw, v, a = self._forward(q, qd, qdd)[-1]
        local = np.array(self.tool.translation, float)
        if point is not None:
            local = local + np.array(self.tool.rotation) @ np.asarray(point, float)
        r = R @ ca.DM(local)
        return Kinematics(p=p + r, R=R @ ca.DM(np.array(self.tool.rotation)), v=v + ca.cross(w, r),
                          a=a + ca.cross(dw, r) + ca.cross(w, ca.cross(w, r)), w=w, dw=dw)
