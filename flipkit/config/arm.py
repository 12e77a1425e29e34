"""The arm as its maker publishes it: joint limits and the safety system's limits.

An :class:`ArmProfile` holds what Universal Robots publishes for one arm: each joint's position
range and top speed, its torque, and the safety system's limits on the tool (TCP speed, TCP
force, momentum, power) in the named presets a cell configures. Plans, ``flipkit verify``, the
exported command streams and the simulated safety system all check against a profile, never
against a URDF's own (often rounder) numbers.

Sources:

* Joint ranges, speeds and torques: Universal Robots' ROS 2 description,
  ``Universal_Robots_ROS2_Description/config/ur10/joint_limits.yaml`` and
  ``config/ur10e/joint_limits.yaml``, which cite the UR10/CB3 User Manual 3.13 and the UR10e
  User Manual 5.8: ±360° on every joint, 120°/s base and shoulder, 180°/s elbow and wrists,
  330/330/150/56/56/56 N·m. The UR10 datasheet: "Base and Shoulder: 120°/s. Elbow, Wrist 1,
  Wrist 2, Wrist 3: 180°/s. Tool: Typical 1 m/s".
* Joint acceleration: UR publishes none ("acceleration limits are not publicly available",
  ``has_acceleration_limits: false`` in the files above; the arm limits torques only).
* Safety limits: the CB3 User Manual (3.1 §15.9, 3.4.5 §10.10, "General Limits") defines
  Force (the TCP's force on the environment), Power (mechanical work on the environment, the
  payload counted as the robot's), Speed (the TCP's linear speed) and Momentum (the arm's), in
  the slider presets Very Restricted, Restricted, Default and Least Restricted; "Least
  Restricted: intended to be used where there is little risk of the robot arm or its payload
  hitting a human, such as inside CNC machines, behind fences or in hard-to-reach places".
  Exceeding a limit is a Stop Category 0. The manual's text does not print the presets'
  numbers (its slider figure does): the values below are the slider's Default and Least
  Restricted sets, and a real cell checks them on its controller's Safety screen before it
  relies on them (docs/arm-profile.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from flipkit.errors import ConfigError, InvalidChoiceError

DEG = math.pi / 180.0


@dataclass(frozen=True)
class SafetyPreset:
    """One named set of the safety system's general limits.

    Attributes:
        name: The preset's name as flipkit spells it. tcp_speed: TCP linear speed (m/s).
        tcp_force: Force of the TCP on the environment (N). momentum: The arm's linear
            momentum, payload included (kg·m/s). power: Mechanical power on the environment
            (W). source: Where the numbers come from.
    """

    name: str
    tcp_speed: float
    tcp_force: float
    momentum: float
    power: float
    source: str

    def __post_init__(self):
        for key in ("tcp_speed", "tcp_force", "momentum", "power"):
            value = getattr(self, key)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ConfigError(f"safety preset {self.name}: {key} must be a positive number, "
                                  f"got {value!r}")

    def limits(self) -> dict:
        """``{quantity: limit}`` in SI units, the quantities of :data:`SAFETY_QUANTITIES`."""
        return {key: float(getattr(self, key)) for key in SAFETY_QUANTITIES}


SAFETY_QUANTITIES = ("tcp_speed", "tcp_force", "momentum", "power")
"""The safety system's general limits that flipkit checks, in :class:`SafetyPreset`'s units."""

_CB3_SLIDER = ("UR CB3 User Manual 3.1 §15.9 / 3.4.5 §10.10 'General Limits', Basic Settings "
               "slider (numbers from the slider figure; check on the controller)")
DEFAULT = SafetyPreset("default", tcp_speed=1.5, tcp_force=150.0, momentum=25.0, power=300.0,
                       source=_CB3_SLIDER)
LEAST_RESTRICTED = SafetyPreset("least_restricted", tcp_speed=5.0, tcp_force=250.0,
                                momentum=100.0, power=1000.0, source=_CB3_SLIDER)


@dataclass(frozen=True)
class ArmProfile:
    """What the maker publishes for one arm.

    Attributes:
        name: flipkit's name for it. model: The maker's name. joints: The joint names, base
            to wrist 3 (the URDF's and ROS 2's). q_range: Each joint's position limit (rad,
            symmetric: ±q_range). qd_max: Each joint's top speed (rad/s). u_max: Each joint's
            torque (N·m). qdd_max: Each joint's acceleration limit (rad/s²), ``None`` where
            the maker publishes none. presets: The safety presets by name. sources: What
            each group of numbers comes from.
    """

    name: str
    model: str
    joints: tuple
    q_range: tuple
    qd_max: tuple
    u_max: tuple
    qdd_max: tuple | None
    presets: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)

    def __post_init__(self):
        n = len(self.joints)
        for key in ("q_range", "qd_max", "u_max") + (("qdd_max",) if self.qdd_max else ()):
            values = getattr(self, key)
            if len(values) != n or not all(math.isfinite(v) and v > 0 for v in values):
                raise ConfigError(f"arm profile {self.name}: {key} needs {n} positive numbers, "
                                  f"got {values!r}")

    def preset(self, name: str) -> SafetyPreset:
        """The safety preset ``name``.

        Raises:
            InvalidChoiceError: Not one of the profile's presets (the message lists them).
        """
        if name not in self.presets:
            raise InvalidChoiceError(f"{self.name} safety preset", name, tuple(self.presets))
        return self.presets[name]


_UR_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
              "wrist_2_joint", "wrist_3_joint")
_UR10_SPEEDS = (120 * DEG, 120 * DEG, 180 * DEG, 180 * DEG, 180 * DEG, 180 * DEG)
_UR10_TORQUES = (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)
_PRESETS = {p.name: p for p in (DEFAULT, LEAST_RESTRICTED)}


def _ur_profile(name: str, model: str, manual: str) -> ArmProfile:
    files = f"Universal_Robots_ROS2_Description config/{name}/joint_limits.yaml ({manual})"
    return ArmProfile(name, model, _UR_JOINTS, (2 * math.pi,) * 6, _UR10_SPEEDS, _UR10_TORQUES,
                      None, dict(_PRESETS),
                      {"joints": files, "acceleration": "none published: " + files,
                       "safety": _CB3_SLIDER})


PROFILES = {
    "ur10": _ur_profile("ur10", "UR10 (CB3)", "UR10/CB3 User Manual 3.13"),
    "ur10e": _ur_profile("ur10e", "UR10e (e-Series)", "UR10e User Manual 5.8"),
}
"""The arms flipkit knows, by name."""

DEFAULT_PROFILE = "ur10"
"""The paper's arm, a UR10 model."""

DEFAULT_PRESET = "least_restricted"
"""A kitchen cell's arm works behind a fence, where the manual puts Least Restricted."""

SPEED_MARGIN = 0.90
"""Plans keep every joint within this fraction of its published speed: room for a stream
resampled from the plan (a controller's own spline) and for the servo's corrections of what
the arm meets (the blade's contact with the grill can push a wrist past its command,
docs/arm-profile.md), so that the arm stays under the published speed."""


def arm_profile(name: str) -> ArmProfile:
    """The profile ``name`` (one of :data:`PROFILES`).

    Raises:
        InvalidChoiceError: An unknown name (the message lists the profiles).
    """
    if name not in PROFILES:
        raise InvalidChoiceError("arm profile", name, tuple(PROFILES))
    return PROFILES[name]


__all__ = ["DEFAULT_PRESET", "DEFAULT_PROFILE", "PROFILES", "SAFETY_QUANTITIES", "SPEED_MARGIN",
           "ArmProfile", "SafetyPreset", "arm_profile"]
