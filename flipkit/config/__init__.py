"""Configuration layer: the cell in frozen dataclasses, SI units (m, kg, s, rad, N·m).

Every default names its source: the paper (Kolathaya et al., RA-L 2018) where it gives a
value, the URDF, a cited measurement, or a stated choice of ours where the paper is silent.
Constructors validate their arguments and raise :class:`~flipkit.errors.ConfigError`.

* :mod:`~flipkit.config.cell`: robot, spatula, burger, grill, table, task limits, Table I;
* :mod:`~flipkit.config.physics`: the simulated cell's physical parameters and their ranges;
* :mod:`~flipkit.config.checks`: the argument checks they share.
"""

from flipkit.config.cell import (GRAVITY, TABLE1_LOCATIONS, UR10_URDF_RELATIVE, BurgerConfig,
                                 CellConfig, GrillConfig, RobotConfig, SpatulaConfig,
                                 TableConfig, TaskLimits, default_urdf)
from flipkit.config.physics import PHYSICAL_RANGES, PhysicsConfig, with_parameter

__all__ = ["GRAVITY", "PHYSICAL_RANGES", "TABLE1_LOCATIONS", "UR10_URDF_RELATIVE", "BurgerConfig",
           "CellConfig", "GrillConfig", "PhysicsConfig", "RobotConfig", "SpatulaConfig",
           "TableConfig", "TaskLimits", "default_urdf", "with_parameter"]
