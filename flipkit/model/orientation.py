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
    """o = (o_x, o_y, o_z) (rad) with R = R_z(o_z) R_y(o_y) R_x(o_x) (DESIGN.md)."""
    return np.array(pin.rpy.matrixToRpy(np.asarray(R, dtype=float)))


def rpy_matrix(o) -> np.ndarray:
    """R = R_z(o_z) R_y(o_y) R_x(o_x)."""
    return np.array(pin.rpy.rpyToMatrix(*np.asarray(o, dtype=float)))


def rpy_jacobian(R: np.ndarray, Jw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """o(R) and ∂o/∂q = E(o)⁻¹ Jw, E mapping rpy rates to world angular velocity."""
    o = rpy(R)
    Einv = np.array(pin.rpy.computeRpyJacobianInverse(o, pin.ReferenceFrame.WORLD))
    return o, Einv @ Jw


def axis_jacobian(R: np.ndarray, Jw: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Axis a = R e_k of the spatula (k = 0: x toward the tip, 2: blade normal F_n) and ∂a/∂q."""
    a = R[:, k].copy()
    return a, -skew(a) @ Jw
