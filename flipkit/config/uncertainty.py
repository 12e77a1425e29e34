"""What a plan cannot know about the burger: the scenario sets of robust flips.

A flip is planned for where the scoop will leave the burger on the blade
(:mod:`flipkit.model.scoop`). That place depends on things the cell does not measure before it
scoops: where exactly the burger was put down, and its friction on the blade. A robust flip's
one joint trajectory lands every scenario of this set on its spot
(:class:`~flipkit.transcription.constraints.flight.ScenarioLanding`).

After the scoop the cell measures the burger's place with a camera and re-plans the flip for
it (sense-plan-act). The measurement errs (:class:`SensingUncertainty`), so the re-plan lands
a scenario set around the measured place in the same way.
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


@dataclass(frozen=True)
class SensingUncertainty:
    """The camera's error on the burger's place on the blade, which a re-plan plans for.

    Attributes:
        sigma: Standard deviation (m) of the error, per axis. An active-stereo depth camera
            (Intel RealSense D400 series datasheet: depth RMS error < 2 % at 2 m) 0.6 m above
            the blade errs by up to 1.2 cm in depth; seen from above, the burger's (x, y)
            comes from the image, and a depth error of 1.2 cm moves a point 25° off the
            optical axis by 5.6 mm sideways. 5 mm (ours, from that geometry).
        k_sigma: The re-plan's scenarios lie ``k_sigma`` standard deviations from the
            measured place, along the blade and across it (2: 95 % of measurements per axis
            fall between them).
    """

    sigma: float = 0.005
    k_sigma: float = 2.0

    def __post_init__(self):
        for name in ("sigma", "k_sigma"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")

    @property
    def reach(self) -> float:
        """Distance (m) of the re-plan's scenarios from the measured place, per axis."""
        return self.k_sigma * self.sigma


__all__ = ["ScoopUncertainty", "SensingUncertainty"]
