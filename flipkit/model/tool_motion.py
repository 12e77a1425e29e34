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

import math

import numpy as np
import pinocchio as pin

from flipkit.errors import ConfigError
from flipkit.model.robot import Robot


class ToolMotion:
    """The tool's speed and the arm's momentum at any (q, q̇) of ``robot``.

    The blade and the flange are fixed to the same (last) joint, so every point's velocity is
    ``v + ω × r`` with (v, ω) that joint's spatial velocity and r the point, all in the joint's
    own frame: a speed is a norm, the same in any frame, so one kinematics pass and no frame
    placement give every point's speed (the simulated safety system calls this every step).

    Args:
        robot: The arm with its payload (the model's inertias carry it).

    Attributes:
        points: The blade's centre and corners in its own frame (m), 5×3.

    Raises:
        ConfigError: The blade and the flange hang from different joints.
    """

    def __init__(self, robot: Robot):
        self.model, self.data = robot.model, robot.model.createData()
        blade = robot.model.frames[robot.frame_id]
        flange = robot.model.frames[robot.model.getFrameId(robot.cell.robot.tool_frame)]
        if blade.parentJoint != flange.parentJoint:
            raise ConfigError("the blade and the tool flange must hang from the same joint")
        self.joint = blade.parentJoint
        half = np.array([robot.cell.spatula.length / 2, robot.cell.spatula.width / 2])
        self.points = np.array([[0.0, 0.0, 0.0]] + [[a * half[0], b * half[1], 0.0]
                                                    for a in (1, -1) for b in (1, -1)])
        # the points in the joint's frame: the blade's five, then the flange's origin, as
        # float tuples: on six points plain arithmetic costs a fifth of numpy's per-call
        # overhead, and the simulated safety system calls this at every 1 ms step
        points = np.vstack([self.points @ blade.placement.rotation.T + blade.placement.translation,
                            flange.placement.translation])
        self._points = [tuple(float(c) for c in p) for p in points]

    def _speed(self) -> float:
        """The fastest point's speed (m/s) after a kinematics pass with velocities."""
        vx, vy, vz, wx, wy, wz = self.data.v[self.joint].vector.tolist()
        fastest = 0.0
        for rx, ry, rz in self._points:  # v + ω × r
            a, b, c = vx + wy * rz - wz * ry, vy + wz * rx - wx * rz, vz + wx * ry - wy * rx
            fastest = max(fastest, a * a + b * b + c * c)
        return math.sqrt(fastest)

    def _momentum(self) -> float:
        """The linear momentum's norm (kg·m/s) after a kinematics pass with velocities."""
        x, y, z = pin.computeCentroidalMomentum(self.model, self.data).linear.tolist()
        return math.sqrt(x * x + y * y + z * z)

    def tcp_speed(self, q: np.ndarray, qd: np.ndarray) -> float:
        """The fastest speed (m/s) of the blade's centre, its corners and the flange."""
        pin.forwardKinematics(self.model, self.data, q, qd)
        return self._speed()

    def momentum(self, q: np.ndarray, qd: np.ndarray) -> float:
        """The arm's linear momentum (kg·m/s), payload included."""
        pin.forwardKinematics(self.model, self.data, q, qd)
        return self._momentum()

    def speed_and_momentum(self, q: np.ndarray, qd: np.ndarray) -> tuple[float, float]:
        """:meth:`tcp_speed` and :meth:`momentum` from one kinematics pass."""
        pin.forwardKinematics(self.model, self.data, q, qd)
        return self._speed(), self._momentum()


__all__ = ["ToolMotion"]
