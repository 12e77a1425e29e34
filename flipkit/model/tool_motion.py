"""How fast the tool moves and how much momentum the arm carries: what a UR safety system
limits (:mod:`flipkit.config.arm`), computed with pinocchio from (q, q̇).

UR's safety system limits the TCP's speed at the tool flange and at the tool's positions; for
a spatula that is the flange and the blade, whose fastest point is a corner or its centre
(the blade is a rigid plate: its points' speeds are v + ω × r). Momentum is the arm's linear
momentum, payload included (pinocchio's centroidal momentum of the model with the payload).
``flipkit verify`` (:mod:`flipkit.planning.plans.verify_safety`) checks a plan with these, and
the simulated safety system (:mod:`flipkit.simulation.safety`) watches a run with them.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from flipkit.model.robot import LWA, Robot


class ToolMotion:
    """The tool's speed and the arm's momentum at any (q, q̇) of ``robot``.

    Args:
        robot: The arm with its payload (the model's inertias carry it).
    """

    def __init__(self, robot: Robot):
        self.model, self.data = robot.model, robot.model.createData()
        self.frame = robot.frame_id
        self.flange = robot.model.getFrameId(robot.cell.robot.tool_frame)
        half = np.array([robot.cell.spatula.length / 2, robot.cell.spatula.width / 2])
        self.points = np.array([[0.0, 0.0, 0.0]] + [[a * half[0], b * half[1], 0.0]
                                                    for a in (1, -1) for b in (1, -1)])

    def tcp_speed(self, q: np.ndarray, qd: np.ndarray) -> float:
        """The fastest speed (m/s) of the blade's centre, its corners and the flange."""
        m, d = self.model, self.data
        pin.forwardKinematics(m, d, q, qd)
        pin.updateFramePlacements(m, d)
        v = pin.getFrameVelocity(m, d, self.frame, LWA)
        # v + ω × r of each point, as rows: r Rᵀ S(ω)ᵀ (np.cross costs more than the
        # kinematics on five points, and the simulated safety system calls this every step)
        p = v.linear + self.points @ (pin.skew(v.angular) @ d.oMf[self.frame].rotation).T
        blade = float(np.einsum("ij,ij->i", p, p).max())
        fv = pin.getFrameVelocity(m, d, self.flange, LWA).linear
        return float(np.sqrt(max(blade, float(fv @ fv))))

    def momentum(self, q: np.ndarray, qd: np.ndarray) -> float:
        """The arm's linear momentum (kg·m/s), payload included."""
        return float(np.linalg.norm(pin.computeCentroidalMomentum(
            self.model, self.data, q, qd).linear))


__all__ = ["ToolMotion"]
