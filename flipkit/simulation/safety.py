"""The arm's safety system in the simulated cell: a protective stop when a limit is exceeded.

A UR's safety system watches the arm as it moves, whatever it was commanded, and stops it
(Stop Category 0) when a joint's speed or one of the general limits of the cell's preset is
exceeded (:mod:`flipkit.config.arm`). :class:`SafetyMonitor` does the same with the simulated
state at every control step:

* ``joint_speed``: each joint's |q̇| over the profile's published speed (a ratio);
* ``tcp_speed``: the fastest of the blade's centre, its four corners and the flange (m/s,
  :class:`~flipkit.model.tool_motion.ToolMotion`);
* ``tcp_force``: the normal force of the cell's steel (grill, table) on the blade (N), the
  force the TCP exerts on the environment;
* ``momentum``: the arm's linear momentum, spatula included (kg·m/s);
* ``power``: the power the blade delivers to the environment, the force times the blade's
  fastest point's speed (W; an upper bound: UR counts the work done on the environment,
  the payload being the robot's).

The first excess ends the run at that step (:meth:`tripped`); its record names the quantity,
the time, the value and the limit. The peaks of every quantity are kept for the report.
"""

from __future__ import annotations

import numpy as np

from flipkit.config.arm import SAFETY_QUANTITIES
from flipkit.model.robot import Robot
from flipkit.model.tool_motion import ToolMotion

QUANTITIES = ("joint_speed",) + SAFETY_QUANTITIES
"""What the monitor watches: ``joint_speed`` (a ratio to the published speed) and the
preset's general limits (:data:`flipkit.config.arm.SAFETY_QUANTITIES`)."""


class SafetyMonitor:
    """UR's safety system over a simulated run (module docstring).

    Args:
        robot: The arm with its spatula (the plant's model: momentum, the blade's points).
        enabled: Stop the run on an excess (``False``: only record the peaks).
    """

    def __init__(self, robot: Robot, enabled: bool = True):
        rc = robot.cell.robot
        self.preset = robot.profile.preset(rc.safety_preset)
        self.limits = {"joint_speed": 1.0, **self.preset.limits()}
        self.tool = ToolMotion(robot)
        self.joints = robot.profile.joints
        self.qd_limit = robot.qd_limit
        self.enabled = enabled
        self._limits = np.array([self.limits[k] for k in QUANTITIES])
        self._peaks = np.zeros(len(QUANTITIES))
        self.stop: dict | None = None

    @property
    def peaks(self) -> dict:
        """The largest value of each of :data:`QUANTITIES` so far."""
        return {k: float(v) for k, v in zip(QUANTITIES, self._peaks)}

    def __call__(self, t: float, q: np.ndarray, qd: np.ndarray, force: float) -> None:
        """Watch the state at time ``t`` (s): joint positions (rad) and speeds (rad/s), and
        the steel's normal force on the blade (N)."""
        ratio = np.abs(qd) / self.qd_limit
        speed = self.tool.tcp_speed(q, qd)
        values = np.array([ratio.max(), speed, force, self.tool.momentum(q, qd),
                           force * speed])  # in the order of QUANTITIES
        np.maximum(self._peaks, values, out=self._peaks)
        if self.stop is None and (values > self._limits).any():
            i = int(np.argmax(values > self._limits))  # the first quantity over its limit
            name = QUANTITIES[i]
            self.stop = {"time_s": float(t), "quantity": name, "value": float(values[i]),
                         "limit": self.limits[name],
                         "joint": self.joints[int(np.argmax(ratio))]
                         if name == "joint_speed" else None}

    @property
    def tripped(self) -> bool:
        """Whether the run must end: a limit was exceeded and the monitor stops runs."""
        return self.enabled and self.stop is not None

    def record(self) -> dict:
        """``{"preset", "limits", "peaks", "stop"}`` (SI units; ``stop`` ``None`` or the
        first excess: ``time_s``, ``quantity``, ``value``, ``limit``, ``joint``)."""
        return {"preset": self.preset.name, "limits": dict(self.limits),
                "peaks": self.peaks, "stop": self.stop}


__all__ = ["QUANTITIES", "SafetyMonitor"]
