"""The dynamics models of a cell: the bare spatula and the spatula carrying the burger."""

from __future__ import annotations

from flipkit.behaviors.library import subbehavior
from flipkit.config import CellConfig
from flipkit.model.collision import ArmShapes
from flipkit.model.robot import Robot


class Models:
    """The two dynamics models of a cell and the arm's collision shapes.

    Attributes:
        cell: The cell. bare: The arm with the spatula alone. loaded: With the burger on the
        blade. shapes: The arm's shapes (kinematics only: the payload does not matter).
    """

    def __init__(self, cell: CellConfig):
        self.cell = cell
        self.bare = Robot(cell, with_burger=False)
        self.loaded = Robot(cell, with_burger=True)
        self.shapes = ArmShapes(self.bare, cell)

    def for_spec(self, spec) -> Robot:
        """The model of a :class:`~flipkit.behaviors.spec.Subbehavior`."""
        return self.loaded if spec.carries_burger else self.bare

    def for_segment(self, name: str) -> Robot:
        """The model of the subbehaviour ``name``."""
        return self.for_spec(subbehavior(name))


_BUILT: dict = {}  # CellConfig -> Models: read-only once built, shared by every planner


def models_for(cell: CellConfig) -> Models:
    """The :class:`Models` of ``cell``, built once per (hashable) cell."""
    try:
        models = _BUILT.get(cell)
    except TypeError:  # unhashable (lists inside the config): build without keeping it
        return Models(cell)
    if models is None:
        models = _BUILT[cell] = Models(cell)
    return models
