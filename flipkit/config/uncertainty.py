"""What a plan cannot know about the burger before the scoop: the scenario set of robust flips.

A flip is planned for where the scoop will leave the burger on the blade
(:mod:`flipkit.model.scoop`). That place depends on things the cell does not measure before it
scoops: where exactly the burger was put down, and its friction on the blade. A robust flip's
one joint trajectory lands every scenario of this set on its spot
(:class:`~flipkit.transcription.constraints.flight.ScenarioLanding`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flipkit.errors import ConfigError


@dataclass(frozen=True)
class ScoopUncertainty:
    """The spread of the scoop's outcome that a robust flip plans for.

    Attributes:
        placement_sigma: Standard deviation (m) of the burger's placement, per axis. A burger
            put down by hand or by a dispenser: 5 mm, the value the Table I trials perturb by
            (no source; the paper gives none).
        mu_scale: Range of the factor on the burger-blade friction coefficient: ±20 %, the
            trials' range. The coefficient itself has only a loose source (foods on a test
            surface 0.04-0.52, :class:`~flipkit.config.BurgerConfig`).
        k_sigma: Placement scenarios lie ``k_sigma`` standard deviations off p^b (2: 95 % of
            placements per axis fall between them).
    """

    placement_sigma: float = 0.005
    mu_scale: tuple = (0.8, 1.2)
    k_sigma: float = 2.0

    def __post_init__(self):
        lo, hi = (float(v) for v in self.mu_scale)
        if not (math.isfinite(self.placement_sigma) and self.placement_sigma >= 0):
            raise ConfigError(f"placement_sigma must be >= 0 m, got {self.placement_sigma!r}")
        if not (0 < lo <= 1 <= hi < math.inf):
            raise ConfigError(f"mu_scale must be a range lo <= 1 <= hi, got {self.mu_scale!r}")
        if not (math.isfinite(self.k_sigma) and self.k_sigma >= 0):
            raise ConfigError(f"k_sigma must be >= 0, got {self.k_sigma!r}")
        object.__setattr__(self, "mu_scale", (lo, hi))

    @property
    def placement(self) -> float:
        """Distance (m) of the placement scenarios from p^b, per axis."""
        return self.k_sigma * self.placement_sigma


__all__ = ["ScoopUncertainty"]
