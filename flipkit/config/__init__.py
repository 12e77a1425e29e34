"""Configuration layer: the cell in frozen dataclasses, SI units (m, kg, s, rad, N·m).

Every default names its source: the paper (Kolathaya et al., RA-L 2018) where it gives a
value, the URDF, a cited measurement, or a stated choice of ours where the paper is silent.
Constructors validate their arguments and raise :class:`~flipkit.errors.ConfigError`.

* :mod:`~flipkit.config.cell`: robot, spatula, burger, grill, table, task limits, Table I;
* :mod:`~flipkit.config.physics`: the simulated cell's physical parameters and their ranges;
* :mod:`~flipkit.config.space`: the cell's solid boxes (grill, table, back wall) and the
  margin the whole arm keeps from them;
* :mod:`~flipkit.config.uncertainty`: the scoop's outcome spread and the camera's error that
  robust flips plan for;
* :mod:`~flipkit.config.urdf`: URDFs named portably (plan files), with their sha256;
* :mod:`~flipkit.config.checks`: the argument checks they share.
"""

from flipkit.config.cell import (GRAVITY, LOCATION_SETS, MORE_LOCATIONS, TABLE1_LOCATIONS,
                                 BurgerConfig, CellConfig,
                                 GrillConfig, RobotConfig, SpatulaConfig, TableConfig, TaskLimits)
from flipkit.config.physics import (KNOWN_PARAMETERS, PHYSICAL_RANGES, PLANNED_PARAMETERS,
                                    PhysicsConfig, known_physics, with_parameter)
from flipkit.config.space import BACK_WALL, CellBox, SpaceConfig
from flipkit.config.uncertainty import ScoopUncertainty, SensingUncertainty
from flipkit.config.urdf import default_urdf, portable_urdf, resolve_urdf, urdf_sha256

__all__ = ["BACK_WALL", "GRAVITY", "KNOWN_PARAMETERS", "LOCATION_SETS", "MORE_LOCATIONS",
           "PHYSICAL_RANGES", "PLANNED_PARAMETERS", "TABLE1_LOCATIONS",
           "BurgerConfig", "CellBox", "CellConfig", "GrillConfig", "PhysicsConfig", "RobotConfig",
           "ScoopUncertainty", "SensingUncertainty", "SpaceConfig", "SpatulaConfig", "TableConfig", "TaskLimits",
           "default_urdf", "known_physics", "portable_urdf", "resolve_urdf", "urdf_sha256",
           "with_parameter"]
