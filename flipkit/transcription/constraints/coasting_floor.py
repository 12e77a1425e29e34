"""Coasting floor: a segment that ends moving leaves the next one's blade floor reachable."""

from __future__ import annotations

import numpy as np

from flipkit.errors import ConfigError
from flipkit.model.robot import BLADE_CORNERS
from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.registry import Check


class CoastingFloor(Block):
    """floor ≤ height of each blade corner at q_i + τ q̇_i, at one node i (four rows).

    The blade's corners where the arm would be coasting for ``tau`` from node i's state stay
    above ``floor``, the next segment's blade floor (a segment that ends in motion, the flip,
    hands its state to the next, eq. 29). Without it a flip could end with the blade above
    the turn back's floor but falling fast, and the turn back, which must keep its corners
    above a flipped burger lying anywhere on the grill from its first node on, could not stop
    the fall in time (a flip at the grill area's corner can end with the blade a few
    centimetres above that floor, falling at over 2 m/s). The arm's own coasting clearance
    (:class:`~flipkit.transcription.constraints.clearance.CoastingClearance`) keeps the blade
    clear of the grill's box only, which is beside the blade at the grill's edges. Jacobian:
    ∂h/∂q_i = J_h(q_c), ∂h/∂q̇_i = τ J_h(q_c), q_c = q_i + τ q̇_i, with J_h a corner's height
    Jacobian ∂p_z/∂q + r_y J_ωx − r_x J_ωy (r = R r_corner).

    Args:
        layout: Variable layout. node: Node index. tau: Coasting time (s, > 0).
        floor: Lowest corner height (m). length, width: The blade's (m).
    """

    def __init__(self, layout, node: int, tau: float, floor: float, length: float,
                 width: float):
        super().__init__("coasting_floor", layout)
        if not (np.isfinite(tau) and tau > 0):
            raise ConfigError(f"coasting time must be positive (s), got {tau!r}")
        if not np.isfinite(floor):
            raise ConfigError(f"coasting floor must be a finite height (m), got {floor!r}")
        self.node, self.tau = int(node), float(tau)
        self._corners = np.array([[a * length / 2 for a, _ in BLADE_CORNERS],
                                  [b * width / 2 for _, b in BLADE_CORNERS],
                                  [0.0] * len(BLADE_CORNERS)])
        self.m = len(BLADE_CORNERS)
        self._add(0, self.m, np.concatenate([layout.iq(self.node), layout.iqd(self.node)]))
        self._finish(float(floor), np.inf, 1.0)

    check = Check(none="a margin the planner keeps for the next segment: what it protects, "
                       "that segment's grill_clearance from its continuous start, is checked "
                       "there")
    no_symbolic_form = "not stated as SX: the flip, which applies it, is solved by the SQP"

    def evaluate(self, ev):
        q, qd = ev.node(self.node)[:2]
        p, R, dp_dq, Jw = ev.robot.pose_jacobians(q + self.tau * qd)
        r = R @ self._corners  # (3, corners), world
        heights = p[2] + r[2]
        J = dp_dq[2][None, :] + r[1][:, None] * Jw[0][None, :] - r[0][:, None] * Jw[1][None, :]
        return heights, np.concatenate([J, self.tau * J], axis=1).ravel()
