"""Success counts with their confidence intervals, as ``flipkit validate`` reports them.

A count such as 99 of 100 says little without its uncertainty: the 95 % Wilson score interval
of 99/100 is 94.6–99.8 %. The interval treats the trials as independent draws of one success
ratio. Each trial draws its own perturbation (:func:`~flipkit.experiments.perturbations.trial_rng`),
so the trials are independent; pooled over locations, the interval is that of the ratio over
the run's locations, each weighted by its trials. scipy computes it
(``scipy.stats.binomtest(...).proportion_ci(method="wilson")``).
"""

from __future__ import annotations

from scipy.stats import binomtest

from flipkit.config.checks import whole
from flipkit.errors import ConfigError

LEVEL = 0.95  # the intervals' confidence level


def wilson(successes: int, trials: int, level: float = LEVEL) -> tuple[float, float]:
    """The Wilson score interval (low, high) of ``successes`` of ``trials`` (checked integers,
    0 ≤ successes ≤ trials, trials ≥ 1) at confidence ``level``, by scipy."""
    ci = binomtest(int(successes), int(trials)).proportion_ci(confidence_level=level,
                                                              method="wilson")
    return float(ci.low), float(ci.high)


def success_intervals(success: dict, trials: int, level: float = LEVEL) -> dict:
    """``{stage: [low, high]}``: the Wilson score interval (ratios in [0, 1]) of each stage's
    ``success[stage]`` of ``trials`` at confidence ``level``.

    Raises:
        ConfigError: ``trials`` is not a positive integer, a count is not an integer in
            [0, trials], or ``level`` is not in (0, 1).
    """
    trials = whole("trials", trials, 1)
    if not 0.0 < level < 1.0:
        raise ConfigError(f"confidence level must be in (0, 1), got {level!r}")
    return {stage: list(wilson(whole(f"{stage} successes", k, 0, trials), trials, level))
            for stage, k in success.items()}


def format_intervals(intervals: dict, level: float = LEVEL) -> str:
    """One line: ``95 % Wilson intervals: scoop 96.3–100 %, …``."""
    parts = [f"{stage} {100 * lo:.1f}–{100 * hi:.1f} %" for stage, (lo, hi) in intervals.items()]
    return f"{100 * level:.0f} % Wilson intervals: " + ", ".join(parts)


__all__ = ["LEVEL", "format_intervals", "success_intervals", "wilson"]
