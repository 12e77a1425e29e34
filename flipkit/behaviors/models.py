"""The dynamics models of a cell: the bare spatula and the spatula carrying the burger."""

from __future__ import annotations

from flipkit.behaviors.library import subbehavior
from flipkit.config import CellConfig
from flipkit.model.collision import ArmMeshes, ArmShapes
from flipkit.model.robot import Robot


class Models:
    """The two dynamics models of a cell and the arm's collision shapes.

    Built from the cell alone and read-only once built, so one :class:`Models` can serve
    every plan in its cell (a planner's owner keeps them:
    :class:`~flipkit.planning.planners.caches.PlannerCaches`).

    Args:
        cell: The cell.
        meshes: The arm's loaded link meshes to build the shapes from (default: loaded for
            these models alone).

    Attributes:
        cell: The cell. bare: The arm with the spatula alone. loaded: With the burger on the
        blade. shapes: The arm's shapes (kinematics only: the payload does not matter).
    """

    def __init__(self, cell: CellConfig, meshes: ArmMeshes | None = None):
        self.cell = cell
        self.bare = Robot(cell, with_burger=False)
        self.loaded = Robot(cell, with_burger=True)
        self.shapes = ArmShapes(self.bare, cell, meshes)

    def for_spec(self, spec) -> Robot:
        """The model of a :class:`~flipkit.behaviors.spec.Subbehavior`."""
        return self.loaded if spec.carries_burger else self.bare

    def for_segment(self, name: str) -> Robot:
        """The model of the subbehaviour ``name``."""
        return self.for_spec(subbehavior(name))
