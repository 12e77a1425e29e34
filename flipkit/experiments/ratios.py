"""Success counts with their confidence intervals, as ``flipkit validate`` reports them.

A count such as 99 of 100 says little without its uncertainty: the 95 % Wilson score interval
of 99/100 is 94.6–99.8 %. The interval treats the trials as independent draws of one success
ratio. Each trial draws its own perturbation (:func:`~flipkit.experiments.perturbations.trial_rng`),
so the trials are independent; pooled over locations, the interval is that of the ratio over
the run's locations, each weighted by its trials. scipy computes it
(``scipy.stats.binomtest(...).proportion_ci(method="wilson")``).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import binomtest

from flipkit.errors import ConfigError

LEVEL = 0.95  # the intervals' confidence level


def success_intervals(success: dict, trials: int, level: float = LEVEL) -> dict:
    """``{stage: [low, high]}``: the Wilson score interval (ratios in [0, 1]) of each stage's
    ``success[stage]`` of ``trials`` at confidence ``level``.

    Raises:
        ConfigError: ``trials`` is not a positive integer, a count is not an integer in
            [0, trials], or ``level`` is not in (0, 1).
    """
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 1:
        raise ConfigError(f"trials must be a positive integer, got {trials!r}")
    if not 0.0 < level < 1.0:
        raise ConfigError(f"confidence level must be in (0, 1), got {level!r}")
    out = {}
    for stage, k in success.items():
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k <= trials:
            raise ConfigError(f"{stage}: successes must be an integer in [0, {trials}], got {k!r}")
        ci = binomtest(int(k), int(trials)).proportion_ci(confidence_level=level, method="wilson")
        out[stage] = [float(ci.low), float(ci.high)]
    return out


def format_intervals(intervals: dict, level: float = LEVEL) -> str:
    """One line: ``95 % Wilson intervals: scoop 96.3–100 %, …``."""
    parts = [f"{stage} {100 * lo:.1f}–{100 * hi:.1f} %" for stage, (lo, hi) in intervals.items()]
    return f"{100 * level:.0f} % Wilson intervals: " + ", ".join(parts)


__all__ = ["LEVEL", "format_intervals", "success_intervals"]
