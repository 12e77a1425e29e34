"""The cell: robot, spatula, burger, grill, table and task limits.

Frozen dataclasses in SI units (m, kg, s, rad, N·m). Every default names its source: the
paper (Kolathaya et al., RA-L 2018) where it gives a value, the URDF, or a stated choice of
ours where the paper is silent. Constructors validate their arguments and raise
:class:`~flipkit.errors.ConfigError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from flipkit.config.checks import box, finite, positive
from flipkit.config.physics import PhysicsConfig
from flipkit.config.space import CellBox, SpaceConfig, cell_boxes
from flipkit.config.arm import DEFAULT_PRESET, DEFAULT_PROFILE, SPEED_MARGIN, arm_profile
from flipkit.config.urdf import default_urdf, resolve_urdf
from flipkit.errors import ConfigError

GRAVITY = (0.0, 0.0, -9.81)  # m/s², world z up (docs/conventions.md)


def _identity() -> tuple:
    return tuple(tuple(float(i == j) for j in range(4)) for i in range(4))


@dataclass(frozen=True)
class RobotConfig:
    """The arm: URDF, tool frame, base placement and home configuration.

    Attributes:
        urdf: URDF path or portable name (``example-robot-data:<path>``, see
            :mod:`flipkit.config.urdf`); ``None`` means the UR10 joint-limited robot of example-robot-data
            (the paper's arm is an unnamed 6-DOF industrial arm; the UR10 matches its reach).
        tool_frame: Frame the spatula is mounted on (``tool0``, the ROS-Industrial flange).
        base_in_world: 4x4 homogeneous transform of the robot base in the world (identity:
            docs/conventions.md: world = robot base frame).
        q_home: Home configuration (rad): spatula flat and level, radially in front of the
            above the grill at (0.62, -0.20, 0.30) m, o = 0, elbow up (our choice; found by
            IK, checked in tests/test_config.py).
        accel_limit: Joint acceleration bound (rad/s²), same for every joint, of the
            subbehaviours that carry or touch the burger. The planner's choice: the URDF has
            none, and Universal Robots state that the arms have no inherent acceleration limit,
            only torque limits (Universal_Robots_ROS2_Driver, ``ur_moveit_config/config/
            joint_limits.yaml``). It keeps the flips' tosses short (docs/robust-flips.md §5).
        free_accel_limit: The same bound for the free motions (subbehaviours with
            ``free_motion``: go to burger, turn back), which neither carry nor touch the
            burger: ``inf`` by default, the URDF's torque limits alone bound them, as the arm's
            maker states.
        profile: The arm as its maker publishes it (:data:`flipkit.config.arm.PROFILES`):
            its joint limits replace the URDF's, and a URDF of the user's whose limits are
            looser than the profile's is refused (:class:`flipkit.model.robot.Robot`).
        speed_margin: Plans keep every joint within this fraction of the profile's speed,
            in (0, 1] (:data:`flipkit.config.arm.SPEED_MARGIN`, 0.9).
        safety_preset: The safety system's preset the cell is configured with (one of the
            profile's presets; default :data:`flipkit.config.arm.DEFAULT_PRESET`).
    """

    urdf: str | None = None
    tool_frame: str = "tool0"
    base_in_world: tuple = field(default_factory=_identity)
    q_home: tuple = (-0.988933, -1.792774, 2.362261, -0.569486, 0.581863, 1.570796)
    accel_limit: float = 20.0
    free_accel_limit: float = math.inf
    profile: str = DEFAULT_PROFILE
    speed_margin: float = SPEED_MARGIN
    safety_preset: str = DEFAULT_PRESET

    def __post_init__(self):
        arm_profile(self.profile).preset(self.safety_preset)  # both names valid
        if not (isinstance(self.speed_margin, (int, float)) and not isinstance(
                self.speed_margin, bool) and 0 < self.speed_margin <= 1):
            raise ConfigError(f"speed_margin must be a number in (0, 1], got "
                              f"{self.speed_margin!r}")
        if self.urdf is not None:
            resolve_urdf(self.urdf)  # a path, or a portable name (flipkit.config.urdf)
        base = finite("base_in_world", self.base_in_world, (4, 4))
        if not np.allclose(base[3], [0, 0, 0, 1]) or not np.allclose(
                base[:3, :3] @ base[:3, :3].T, np.eye(3), atol=1e-6):
            raise ConfigError("base_in_world must be a rigid 4x4 transform")
        finite("q_home", self.q_home)
        positive("accel_limit", self.accel_limit)
        if not (isinstance(self.free_accel_limit, (int, float)) and self.free_accel_limit > 0):
            raise ConfigError(f"free_accel_limit must be a positive number or inf, got "
                              f"{self.free_accel_limit!r}")

    @property
    def urdf_path(self) -> str:
        """Absolute URDF path (a portable name or the default resolved)."""
        return resolve_urdf(self.urdf) if self.urdf else default_urdf()


@dataclass(frozen=True)
class SpatulaConfig:
    """The spatula: a flat blade at the end of a straight handle along the tool axis.

    The paper gives no dimensions; these are a standard grill spatula's.

    Attributes:
        length: Blade length l_l along its x axis (m).
        width: Blade width l_w (m).
        thickness: Thickness (m) of the blade's box below its top face in the planner's
            collision model and inertia (and the prescribed-blade simulator's): 3 mm, an
            envelope of the simulated blade (``physics.blade_thickness``, 0.45-2 mm).
        handle: Distance from the tool flange to the blade centre along the tool z axis (m).
        mass: Total mass (kg), lumped at the blade centre for dynamics.
    """

    length: float = 0.16
    width: float = 0.12
    thickness: float = 0.003
    handle: float = 0.20
    mass: float = 0.30

    def __post_init__(self):
        for name in ("length", "width", "thickness", "handle", "mass"):
            positive(f"spatula {name}", getattr(self, name))

    @property
    def half_extent(self) -> np.ndarray:
        """(l_l/2, l_w/2) (m): how far a place on the blade (x, y, blade frame) may lie from
        its centre."""
        return np.array([self.length, self.width]) / 2

    def placement_in_tool(self) -> np.ndarray:
        """4x4 placement of the spatula frame in the tool frame.

        Spatula x (toward the tip) is the tool z axis; spatula z (blade normal) is the tool
        x axis; y = z × x. The origin is the blade centre, ``handle`` along tool z.
        """
        T = np.eye(4)
        T[:3, :3] = np.column_stack(([0, 0, 1], [0, -1, 0], [1, 0, 0]))
        T[:3, 3] = [0, 0, self.handle]
        return T


@dataclass(frozen=True)
class BurgerConfig:
    """The burger patty: a uniform disc (paper Sec. II.C). Sources beside each value; the
    plausible ranges the sensitivity study sweeps are in :data:`PHYSICAL_RANGES`.

    Attributes:
        diameter: d (m). 0.10 m = 3.9 in: "a standard hamburger patty is formed into a 4-5
            inch wide patty that is about 3/4 inch thick" (The Donut Whole, "How many ounces
            is a 1/4 burger?", https://www.thedonutwhole.com/how-many-ounces-is-a-1-4-burger/);
            homemade 3.5-4 in (Kitchen Wisdom, "How many ounces are in a quarter-pound
            burger?", https://kitchenwisdom.info/how-many-ounces-are-in-a-quarter-pound-burger).
        thickness: Patty thickness (m). The same sources give 3/4 in (19 mm) for the raw,
            hand-formed patty; 15 mm is a pressed patty (no source gives it: range
            10-19 mm, stated as ours).
        mass: m (kg). A quarter pound = 4 oz = 113.4 g raw (ChefRadar, "How many ounces does
            a hamburger weighing a quarter pound have?", https://chefradar.com/how-many-ounces-
            does-a-hamburger-weighing-a-quarter-pound-have/); cooking loses 15-25 % (The Donut
            Whole, above), 24.7-32.1 % for 5-30 % fat patties (J. Food Sci., "Chemical,
            physical and sensory characterization of ground beef containing 5 to 30 percent
            fat").
        mu: Spatula-burger (meat on stainless steel) friction coefficient mu. No measurement
            of meat on stainless steel was found; friction coefficients of foods on a texture
            test cell's surface range 0.04-0.52 ("Effect of friction on the performance of
            texture test cells", J. Texture Studies; https://paperexplained.cn/articles/paper/
            detail/0401cf38c535a35e153632f5b9bb1a2a752387d2). 0.5 (the planner's value, top of
            that range) is kept; range 0.2-0.8 stated as ours.
    """

    diameter: float = 0.10
    thickness: float = 0.015
    mass: float = 0.113
    mu: float = 0.5

    def __post_init__(self):
        for name in ("diameter", "thickness", "mass", "mu"):
            positive(f"burger {name}", getattr(self, name))

    @property
    def area(self) -> float:
        """Face area π d²/4 (m²)."""
        return math.pi * self.diameter**2 / 4

    @property
    def density(self) -> float:
        """Mass over the disc's volume (kg/m³)."""
        return self.mass / (self.area * self.thickness)


@dataclass(frozen=True)
class GrillConfig:
    """The grill: a horizontal plate at height h_g; burgers may lie anywhere in the area.

    Attributes:
        height: Surface height h_g (m), Table I z column.
        x_range: Grill area along world x (m); contains all ten Table I locations.
        y_range: Grill area along world y (m); contains all ten Table I locations.
    """

    height: float = 0.072
    x_range: tuple = (0.60, 0.88)
    y_range: tuple = (-0.50, 0.16)

    def __post_init__(self):
        finite("grill height", self.height)
        box("grill area", (self.x_range[0], self.y_range[0]),
             (self.x_range[1], self.y_range[1]), 2)

    def contains(self, xy, tol: float = 1e-9) -> bool:
        """Whether the point (x, y) lies in the grill area (m)."""
        x, y = float(xy[0]), float(xy[1])
        return (self.x_range[0] - tol <= x <= self.x_range[1] + tol
                and self.y_range[0] - tol <= y <= self.y_range[1] + tol)


@dataclass(frozen=True)
class TableConfig:
    """The table (tray) beside the grill where finished burgers are placed (paper Fig. 1).

    Attributes:
        height: Surface height (m).
        x_range: Table area along world x (m).
        y_range: Table area along world y (m).
    """

    height: float = 0.10
    x_range: tuple = (0.20, 0.55)
    y_range: tuple = (0.45, 0.80)

    def __post_init__(self):
        finite("table height", self.height)
        box("table area", (self.x_range[0], self.y_range[0]),
             (self.x_range[1], self.y_range[1]), 2)


@dataclass(frozen=True)
class TaskLimits:
    """Spatula task-space bounds (paper Constraint 1, eq. 4); the values are ours.

    Attributes:
        p_min, p_max: Spatula-centre position box (m); p_z stays above the grill.
        v_max: Bound on |v_x|, |v_y|, |v_z| (m/s).
        a_max: Bound on |a_x|, |a_y|, |a_z| (m/s²).
        pitch_range: Bounds of the pitch o_y (rad), the orientation part of eq. (4). Our
            choice: ±1.2 rad (69°) keeps roll-pitch-yaw away from its singularity at
            ±π/2 (where the rpy end-orientation constraints lose a direction) and holds every
            pitch the behaviours command (scoop 0.314, pickup −0.05; the flip's x axis bound
            of eq. 26, x̂_x ≥ 0.6, allows |o_y| ≤ 0.93; the turn backs of the ten Table I plans
            reach −0.78). Roll and yaw get no bounds: the flip rolls the blade over (o_x
            wraps at ±π) and the arm may point the blade anywhere around its base; the
            flip's x-axis bounds and the scoop's attitude band bound them where it matters.
    """

    p_min: tuple = (0.0, -0.9, 0.072)
    p_max: tuple = (1.2, 0.95, 0.9)
    v_max: float = 3.0
    a_max: float = 40.0
    pitch_range: tuple = (-1.2, 1.2)

    def __post_init__(self):
        box("task position", self.p_min, self.p_max, 3)
        positive("v_max", self.v_max)
        positive("a_max", self.a_max)
        box("pitch range", self.pitch_range[:1], self.pitch_range[1:], 1)
        if max(abs(float(v)) for v in self.pitch_range) >= 1.5707963267948966:
            raise ConfigError(f"pitch range must lie inside (-pi/2, pi/2) rad (rpy is singular "
                              f"at ±pi/2), got {self.pitch_range}")


@dataclass(frozen=True)
class CellConfig:
    """Everything about the cell, bundled; the default is the paper's setting."""

    robot: RobotConfig = field(default_factory=RobotConfig)
    spatula: SpatulaConfig = field(default_factory=SpatulaConfig)
    burger: BurgerConfig = field(default_factory=BurgerConfig)
    grill: GrillConfig = field(default_factory=GrillConfig)
    table: TableConfig = field(default_factory=TableConfig)
    limits: TaskLimits = field(default_factory=TaskLimits)
    gravity: tuple = GRAVITY
    physics: PhysicsConfig = field(default_factory=PhysicsConfig)
    space: SpaceConfig = field(default_factory=SpaceConfig)

    def __post_init__(self):
        finite("gravity", self.gravity, (3,))

    def boxes(self) -> tuple[CellBox, ...]:
        """The solid boxes the arm keeps ``space.margin`` from: grill, table, walls."""
        return cell_boxes(self.grill, self.table, self.space)


TABLE1_LOCATIONS = (  # Table I of the paper: p^b (m), robot base frame (shared/data/paper_table1.csv)
    (0.64, -0.33, 0.073), (0.75, 0.00, 0.073), (0.76, 0.09, 0.072), (0.64, -0.33, 0.072),
    (0.68, -0.31, 0.072), (0.69, -0.16, 0.072), (0.73, -0.13, 0.072), (0.73, -0.18, 0.072),
    (0.75, -0.45, 0.072), (0.84, 0.12, 0.072),
)
MORE_LOCATIONS = (  # five places off Table I, spread over the grill's reach (robot base frame)
    (0.62, -0.05, 0.072), (0.70, 0.05, 0.072), (0.80, -0.30, 0.072), (0.85, -0.10, 0.072),
    (0.66, -0.45, 0.072),
)
LOCATION_SETS = {"table1": TABLE1_LOCATIONS, "more": MORE_LOCATIONS}
"""The named burger-location sets of ``flipkit validate`` and ``flipkit compare-ik``
(``--locations``): the paper's ten Table I points, and five more of flipkit's choosing."""
