"""Closed-form inverse kinematics of the UR10: all eight branches of a spatula pose.

The UR arms have three parallel joints (2, 3, 4) between a shoulder pan (1) and a wrist whose
last two axes (5, 6) are perpendicular, so every pose has up to eight joint solutions in
closed form (Hawkins, "Analytic inverse kinematics for the Universal Robots UR-5/UR-10 arms",
2013). In the Denavit–Hartenberg frames of Universal Robots' published table,
T_{i−1,i} = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i), and with φ = θ2 + θ3 + θ4:

* frame 1's axis is z1 = (sin θ1, −cos θ1, 0), and the origin of frame 5,
  o5 = o6 − d6 z6, lies at height d4 along it: o5 · z1 = d4 — two θ1 (shoulder left/right);
* R_16 = R_01ᵀ R_06 = Rz(φ) Ry(−θ5) Rz(θ6), so cos θ5 = R_16[2, 2] — two θ5 (wrist
  up/down) — and θ6 and φ follow from its last row and column;
* the origin of frame 4 in frame 1 is a planar two-link point a2 e^{iθ2} + a3 e^{i(θ2+θ3)}
  — two θ3 (elbow up/down), then θ2, and θ4 = φ − θ2 − θ3.

The URDF (example-robot-data's ``ur10_joint_limited_robot.urdf``, ROS-Industrial layout)
uses the same joint angles as the DH table; its ``base_link`` is the DH base turned by π
about z and its ``tool0`` a fixed transform from DH frame 6. :class:`URAnalyticIK` finds both
transforms from the pinocchio model at q = 0 and checks the DH chain against pinocchio's
forward kinematics at seeded configurations before it is used.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from flipkit.errors import ConfigError
from flipkit.model.robot import Robot

# UR10 DH table (Universal Robots, "Parameters for calculations of kinematics and dynamics";
# the same lengths as the URDF's joint origins: d4 = 0.220941 − 0.1719 + 0.1149).
D = (0.1273, 0.0, 0.0, 0.163941, 0.1157, 0.0922)  # m
A = (0.0, -0.612, -0.5723, 0.0, 0.0, 0.0)  # m
ALPHA = (np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0)  # rad
BRANCHES = 8  # shoulder (2) × wrist (2) × elbow (2)
SINGULAR = 1e-9  # |sin θ5| below this: wrist singularity (θ6 is set to 0 there)


def dh_transform(i: int, theta) -> np.ndarray:
    """T_{i−1,i} (…, 4, 4) of joint i (0-based) at angle(s) ``theta`` (rad, any shape)."""
    theta = np.asarray(theta, float)
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(ALPHA[i]), np.sin(ALPHA[i])
    T = np.zeros(theta.shape + (4, 4))
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 2], T[..., 0, 3] = ct, -st * ca, st * sa, A[i] * ct
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = st, ct * ca, -ct * sa, A[i] * st
    T[..., 2, 1], T[..., 2, 2], T[..., 2, 3], T[..., 3, 3] = sa, ca, D[i], 1.0
    return T


def dh_forward(q) -> np.ndarray:
    """T_06 (4×4) of the DH chain at ``q`` (rad)."""
    T = np.eye(4)
    for i in range(6):
        T = T @ dh_transform(i, q[i])
    return T


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def dh_inverse(T06: np.ndarray) -> np.ndarray:
    """The eight DH joint solutions of T_06, (8, 6) rad in [−π, π); rows of an unreachable
    branch are NaN. Row k: shoulder = k // 4, wrist = (k // 2) % 2, elbow = k % 2."""
    return dh_inverse_many(np.asarray(T06, float)[None])[0]


def dh_inverse_many(T06: np.ndarray) -> np.ndarray:
    """:func:`dh_inverse` of n poses at once: T06 (n, 4, 4) → (n, 8, 6) rad.

    The same steps on arrays, axes (pose, shoulder, wrist, elbow): two θ1 from the wrist
    centre, two θ5 per θ1, then θ6 and φ (θ6 = 0 at the wrist singularity), and two θ3 per
    (θ1, θ5) from the planar triangle.
    """
    T06 = np.asarray(T06, float)
    n = T06.shape[0]
    R, p = T06[:, :3, :3], T06[:, :3, 3]
    o5 = p - D[5] * R[:, :, 2]
    r = np.hypot(o5[:, 0], o5[:, 1])
    reach = r >= abs(D[3])  # else the wrist centre is inside the cylinder of radius d4
    psi = np.arctan2(o5[:, 1], o5[:, 0])
    delta = np.arcsin(np.where(reach, D[3] / np.where(reach, r, 1.0), 0.0))
    th1 = np.stack([psi + delta, psi + np.pi - delta], axis=1)  # (n, 2)
    T16 = np.linalg.solve(dh_transform(0, th1), T06[:, None])  # (n, 2, 4, 4)
    R16 = T16[..., :3, :3]
    c5 = np.clip(R16[..., 2, 2], -1.0, 1.0)
    th5 = np.stack([np.arccos(c5), -np.arccos(c5)], axis=2)  # (n, 2, 2)
    s5 = np.sin(th5)
    singular = np.abs(s5) < SINGULAR
    safe = np.where(singular, 1.0, s5)
    R16w = R16[:, :, None]  # broadcast over the wrist axis
    th6 = np.where(singular, 0.0, np.arctan2(-R16w[..., 2, 1] / safe, R16w[..., 2, 0] / safe))
    phi = np.where(singular, np.arctan2(R16w[..., 1, 0], R16w[..., 0, 0]),
                   np.arctan2(-R16w[..., 1, 2] / safe, -R16w[..., 0, 2] / safe))
    T14 = T16[:, :, None] @ np.linalg.inv(dh_transform(4, th5) @ dh_transform(5, th6))
    x, y = T14[..., 0, 3], T14[..., 1, 3]
    c3 = (x * x + y * y - A[1] ** 2 - A[2] ** 2) / (2 * A[1] * A[2])
    ok = (np.abs(c3) <= 1.0 + 1e-12) & reach[:, None, None]  # else out of reach
    a3 = np.arccos(np.clip(c3, -1.0, 1.0))
    th3 = np.stack([a3, -a3], axis=3)  # (n, 2, 2, 2)
    th2 = (np.arctan2(y, x)[..., None]
           - np.arctan2(A[2] * np.sin(th3), A[1] + A[2] * np.cos(th3)))
    th4 = phi[..., None] - th2 - th3
    full = lambda a: np.broadcast_to(a, th3.shape)  # noqa: E731
    out = _wrap(np.stack([full(th1[:, :, None, None]), th2, th3, th4,
                          full(th5[..., None]), full(th6[..., None])], axis=-1))
    out[~np.broadcast_to(ok[..., None], th3.shape)] = np.nan
    return out.reshape(n, BRANCHES, 6)


class URAnalyticIK:
    """All eight IK branches of the spatula frame of a flipkit :class:`Robot` (a UR10).

    Args:
        robot: The arm; its chain must be the UR10 of :data:`D`, :data:`A`, :data:`ALPHA`.

    Raises:
        ConfigError: The model's forward kinematics differ from the DH chain (not a UR10).
    """

    def __init__(self, robot: Robot, check_seed: int = 0):
        self.robot = robot
        m, d = robot.model, robot.model.createData()
        # world <- DH base: the robot's base placement, and base_link = DH base turned by π
        self.base = np.asarray(robot.cell.robot.base_in_world, float) @ np.diag([-1.0, -1.0,
                                                                                 1.0, 1.0])
        T = self._tool0(np.zeros(6), m, d)
        self.tool = np.linalg.solve(self.base @ dh_forward(np.zeros(6)), T)  # DH 6 -> tool0
        self.spatula = np.linalg.solve(T, robot.placement(np.zeros(6)).homogeneous)
        rng = np.random.default_rng(check_seed)
        for q in rng.uniform(-np.pi, np.pi, (5, 6)):
            err = np.abs(self._tool0(q, m, d) - self.base @ dh_forward(q) @ self.tool).max()
            if err > 1e-9:
                raise ConfigError(f"the arm is not the UR10 of the DH table (tool0 differs by "
                                  f"{err:.2g} m at a test configuration)")

    @staticmethod
    def _tool0(q, m, d):
        pin.framesForwardKinematics(m, d, np.asarray(q, float))
        return d.oMf[m.getFrameId("tool0")].homogeneous.copy()

    def solve(self, T_spatula: np.ndarray) -> np.ndarray:
        """The eight branches (8, 6) rad for a spatula pose (4×4, world frame), each
        wrapped into the joint limits where a 2π shift allows; NaN rows where a branch does
        not exist or leaves the limits."""
        return self.solve_many(np.asarray(T_spatula, float)[None])[0]

    def solve_many(self, T_spatula: np.ndarray) -> np.ndarray:
        """:meth:`solve` of n poses (n, 4, 4) at once: (n, 8, 6) rad. Each joint takes the
        first of the shifts 0, +2π, −2π that puts it inside its limits."""
        T06 = np.linalg.solve(self.base, T_spatula @ np.linalg.inv(self.spatula)) @ np.linalg.inv(
            self.tool)
        sols = dh_inverse_many(T06)
        lo, hi = self.robot.q_min, self.robot.q_max
        shifted = sols[..., None] + np.array([0.0, 2 * np.pi, -2 * np.pi])  # (n, 8, 6, 3)
        inside = (shifted >= lo[:, None]) & (shifted <= hi[:, None])
        first = np.argmax(inside, axis=-1)[..., None]
        sols = np.take_along_axis(shifted, first, axis=-1)[..., 0]
        sols[~inside.any(axis=-1).all(axis=-1)] = np.nan
        return sols

    def nearest(self, T_spatula: np.ndarray, q_ref) -> tuple[int, np.ndarray] | None:
        """(branch, q) of the solution nearest to ``q_ref`` (max joint distance, with 2π
        shifts inside the limits), or None if no branch exists."""
        return nearest_branch(self.solve(T_spatula), q_ref)


def nearest_branch(sols: np.ndarray, q_ref) -> tuple[int, np.ndarray] | None:
    """(branch, q) of the row of ``sols`` (8, 6) nearest to ``q_ref`` (max joint distance;
    NaN rows do not exist), or None if every row is NaN."""
    ok = ~np.isnan(sols[:, 0])
    if not ok.any():
        return None
    dist = np.where(ok, np.abs(np.nan_to_num(sols) - np.asarray(q_ref)).max(axis=1), np.inf)
    k = int(np.argmin(dist))
    return k, sols[k]
