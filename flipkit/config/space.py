"""The cell's solid boxes the whole arm keeps clear of (paper Sec. I: "operate within the
boundaries of the walls and grill"), and the clearance margin.

The grill and the table are the boxes under their surfaces (:class:`~flipkit.config.cell.GrillConfig`,
:class:`~flipkit.config.cell.TableConfig`); the back wall stands behind the grill. Every box is
axis-aligned in the world frame (= robot base frame), in metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from flipkit.config.checks import box, finite, positive
from flipkit.errors import ConfigError

# Both the grill and the table stand on the floor the robot's base stands on (z = 0): the
# paper's photo (Fig. 1) shows grill and arm on one counter; the depth of the bodies below
# their surfaces does not matter to the arm, which stays above them.
SOLID_BOTTOM = 0.0  # m, our choice


@dataclass(frozen=True)
class CellBox:
    """An axis-aligned solid box of the cell.

    Attributes:
        name: Its name in constraints and reports (``grill``, ``table``, ``wall``, ...).
        lower, upper: Opposite corners (m, world frame).
    """

    name: str
    lower: tuple
    upper: tuple

    def __post_init__(self):
        if not self.name or not isinstance(self.name, str):
            raise ConfigError(f"cell box name must be a non-empty string, got {self.name!r}")
        box(f"cell box {self.name!r}", self.lower, self.upper, 3)

    @property
    def center(self) -> tuple:
        """Centre (m)."""
        return tuple((a + b) / 2 for a, b in zip(self.lower, self.upper))

    @property
    def size(self) -> tuple:
        """Edge lengths along x, y, z (m)."""
        return tuple(b - a for a, b in zip(self.lower, self.upper))


# The back wall: the paper's cell (Fig. 1) has a wall behind the grill but gives no distance.
# Our choice: its face 0.17 m beyond the grill area's far edge (x = 0.88 m; a scoop at the
# farthest Table I burger, x = 0.84 m, puts the blade tip at 0.92 m), 10 cm thick, 2 m wide
# and 1.5 m high (above the arm's reach: base at z = 0, UR10 reach 1.3 m).
BACK_WALL = CellBox("wall", (1.05, -1.0, SOLID_BOTTOM), (1.15, 1.0, 1.5))


@dataclass(frozen=True)
class SpaceConfig:
    """Space limits of the whole arm.

    Attributes:
        margin: Least distance (m) between any part of the arm (links, spatula) and any box of
            the cell, where a segment applies the pair (default 2 cm, ours).
        walls: Boxes besides the grill and the table (default the back wall
            :data:`BACK_WALL`); a hood or a second wall is added here.
        handle_radius: Radius (m) of the spatula handle's capsule (our choice: a 2 cm thick
            handle, grill spatulas' handles are 1.5-2.5 cm).
    """

    margin: float = 0.02
    walls: tuple = field(default_factory=lambda: (BACK_WALL,))
    handle_radius: float = 0.01

    def __post_init__(self):
        finite("clearance margin", self.margin)
        if self.margin < 0:
            raise ConfigError(f"clearance margin must be >= 0 m, got {self.margin!r}")
        positive("handle radius", self.handle_radius)
        if not all(isinstance(w, CellBox) for w in self.walls):
            raise ConfigError("walls must be CellBox instances")
        names = [w.name for w in self.walls]
        if len(set(names)) != len(names) or {"grill", "table"} & set(names):
            raise ConfigError(f"wall names must be unique and not grill/table, got {names}")


def cell_boxes(grill, table, space: SpaceConfig) -> tuple[CellBox, ...]:
    """The cell's boxes: the grill (its area, up to its surface h_g), the table (its area, up
    to its top) and the walls of ``space``."""
    return (CellBox("grill", (grill.x_range[0], grill.y_range[0], SOLID_BOTTOM),
                    (grill.x_range[1], grill.y_range[1], grill.height)),
            CellBox("table", (table.x_range[0], table.y_range[0], SOLID_BOTTOM),
                    (table.x_range[1], table.y_range[1], table.height)),
            *space.walls)
