"""Spatula orientation: roll-pitch-yaw o = (o_x, o_y, o_z) with R = R_z R_y R_x, and axes.

Derivatives use the angular Jacobian Jw of :class:`~flipkit.model.robot.Robot` (dR = [Jw dq]× R):
the rpy rates follow from pinocchio's ``rpy.computeRpyJacobianInverse`` and an axis
a = R e_k moves as da = −[a]× Jw dq.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from flipkit.model.robot import skew


def rpy(R: np.ndarray) -> np.ndarray:
    """o = (o_x, o_y, o_z) (rad) with R = R_z(o_z) R_y(o_y) R_x(o_x) (docs/conventions.md)."""
    return np.array(pin.rpy.matrixToRpy(np.asarray(R, dtype=float)))


def rpy_matrix(o) -> np.ndarray:
    """R = R_z(o_z) R_y(o_y) R_x(o_x)."""
    return np.array(pin.rpy.rpyToMatrix(*np.asarray(o, dtype=float)))


def rpy_matrix_derivatives(o) -> np.ndarray:
    """∂R/∂o_j of R = R_z(o_z) R_y(o_y) R_x(o_x), shape (3, 3, 3) with index [j] = ∂R/∂o_j
    (1/rad)."""
    x, y, z = np.asarray(o, dtype=float)
    cx, sx, cy, sy, cz, sz = np.cos(x), np.sin(x), np.cos(y), np.sin(y), np.cos(z), np.sin(z)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    dRx = np.array([[0, 0, 0], [0, -sx, -cx], [0, cx, -sx]])
    dRy = np.array([[-sy, 0, cy], [0, 0, 0], [-cy, 0, -sy]])
    dRz = np.array([[-sz, -cz, 0], [cz, -sz, 0], [0, 0, 0]])
    return np.stack([Rz @ Ry @ dRx, Rz @ dRy @ Rx, dRz @ Ry @ Rx])


def rpy_rate_matrix(o) -> np.ndarray:
    """E(o) (3×3) with ω = E(o) ȯ: world angular velocity (rad/s) from the rpy rates (rad/s)."""
    return np.array(pin.rpy.computeRpyJacobian(np.asarray(o, dtype=float),
                                               pin.ReferenceFrame.WORLD))


def rpy_jacobian(R: np.ndarray, Jw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """o(R) and ∂o/∂q = E(o)⁻¹ Jw, E mapping rpy rates to world angular velocity; for R
    (n, 3, 3) and Jw (n, 3, nq), o (n, 3) and ∂o/∂q (n, 3, nq)."""
    if np.ndim(R) == 3:
        outs = [rpy_jacobian(Ri, Ji) for Ri, Ji in zip(R, Jw)]
        return np.array([o for o, _ in outs]), np.array([J for _, J in outs])
    o = rpy(R)
    Einv = np.array(pin.rpy.computeRpyJacobianInverse(o, pin.ReferenceFrame.WORLD))
    return o, Einv @ Jw


def axis_jacobian(R: np.ndarray, Jw: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Axis a = R e_k of the spatula (k = 0: x toward the tip, 2: blade normal F_n) and ∂a/∂q
    (over leading node axes of R and Jw)."""
    a = R[..., :, k].copy()
    return a, -skew(a) @ Jw
