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
        self._limits = [float(self.limits[k]) for k in QUANTITIES]
        self._qd_limit = [float(v) for v in self.qd_limit]
        self._peaks = [0.0] * len(QUANTITIES)
        self.stop: dict | None = None

    @property
    def peaks(self) -> dict:
        """The largest value of each of :data:`QUANTITIES` so far."""
        return {k: float(v) for k, v in zip(QUANTITIES, self._peaks)}

    def __call__(self, t: float, q: np.ndarray, qd: np.ndarray, force: float) -> None:
        """Watch the state at time ``t`` (s): joint positions (rad) and speeds (rad/s), and
        the steel's normal force on the blade (N)."""
        ratios = [abs(v) / lim for v, lim in zip(qd.tolist(), self._qd_limit)]
        speed, momentum = self.tool.speed_and_momentum(q, qd)
        # in the order of QUANTITIES; plain floats: this runs at every 1 ms step
        values = (max(ratios), speed, force, momentum, force * speed)
        self._peaks = [max(p, v) for p, v in zip(self._peaks, values)]
        if self.stop is None:
            over = [i for i, (v, lim) in enumerate(zip(values, self._limits)) if v > lim]
            if over:  # the first quantity over its limit
                name = QUANTITIES[over[0]]
                self.stop = {"time_s": float(t), "quantity": name,
                             "value": float(values[over[0]]), "limit": self.limits[name],
                             "joint": self.joints[ratios.index(values[0])]
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
