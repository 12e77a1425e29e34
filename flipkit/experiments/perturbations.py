"""How each simulated trial's cell differs from the plan's model: the Table I perturbations."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flipkit.config import SensingUncertainty
from flipkit.config.checks import whole
from flipkit.errors import ConfigError


@dataclass(frozen=True)
class Perturbations:
    """How each trial's real cell differs from the plan's model.

    Attributes:
        position_sigma: Standard deviation (m) of the Gaussian burger placement error, drawn
            independently in x and in y. Default 5 mm (a burger put down by hand).
        grill_offset: Half-width a (m) of the uniform grill-height offset U(−a, a).
            Default 2 mm.
        mu_scale: Range (lo, hi) of the uniform factor on the burger–spatula friction
            coefficient μ (the burger–grill friction is unchanged). Default (0.8, 1.2).
        mass_scale: Range (lo, hi) of the uniform factor on the burger mass, in MuJoCo and in
            the arm's payload (not in the feed-forward). Default (0.9, 1.1).
        sensing_sigma: Standard deviation (m) of the camera's error on the burger's place on
            the blade, per axis (sense-plan-act only). Default the error re-plans plan for,
            5 mm (:class:`~flipkit.config.SensingUncertainty`, with its source).
    """

    position_sigma: float = 0.005
    grill_offset: float = 0.002
    mu_scale: tuple = (0.8, 1.2)
    mass_scale: tuple = (0.9, 1.1)
    sensing_sigma: float = SensingUncertainty().sigma

    def __post_init__(self):
        for name in ("position_sigma", "grill_offset", "sensing_sigma"):
            if not (np.isfinite(getattr(self, name)) and getattr(self, name) >= 0):
                raise ConfigError(f"{name} must be a non-negative number (m)")
        for name in ("mu_scale", "mass_scale"):
            lo, hi = (float(v) for v in getattr(self, name))
            if not (0 < lo <= hi < np.inf):
                raise ConfigError(f"{name} must be a range 0 < lo <= hi, got {(lo, hi)}")
            object.__setattr__(self, name, (lo, hi))

    def draw(self, rng: np.random.Generator) -> dict:
        """One trial's perturbation: ``dx_m``, ``dy_m``, ``grill_offset_m`` (m),
        ``mu_factor``, ``mass_factor``, ``sense_dx_m``, ``sense_dy_m`` (m), drawn in this
        order."""
        dx, dy = rng.normal(0.0, self.position_sigma, 2)
        out = {"dx_m": float(dx), "dy_m": float(dy),
               "grill_offset_m": float(rng.uniform(-self.grill_offset, self.grill_offset)),
               "mu_factor": float(rng.uniform(*self.mu_scale)),
               "mass_factor": float(rng.uniform(*self.mass_scale))}
        sx, sy = rng.normal(0.0, self.sensing_sigma, 2)
        return {**out, "sense_dx_m": float(sx), "sense_dy_m": float(sy)}


MAX_TRIALS = 10_000  # trials per location of a validation


def check_seed(seed) -> int:
    """``seed`` as an int, or :class:`ConfigError` (one line): a non-negative integer."""
    return whole("seed", seed)


def check_trials(trials) -> int:
    """``trials`` (per location) as an int, or :class:`ConfigError` (one line): an integer in
    [1, :data:`MAX_TRIALS`]."""
    return whole("trials", trials, 1, MAX_TRIALS)


def trial_rng(seed: int, trial: int, location) -> np.random.Generator:
    """The random generator of trial ``trial`` (0, 1, …) at the burger location ``location``
    (x, y, z) (m) of a run seeded ``seed``.

    Seeded by numpy's ``SeedSequence`` of the seed, the trial and the location in µm, so
    that every trial of every location has a stream of its own: Table I's 10 × 10 trials are
    100 perturbations, not 10 repeated at each location, and runs with different seeds share
    no draw (``default_rng(seed + trial)`` would make seed 3's trial 0 seed 0's trial 3). Every
    parameter setting of a run sees the same draws at a location (common random numbers).

    Raises:
        ConfigError: ``seed`` or ``trial`` is not a non-negative integer, or ``location`` is
            not three finite numbers.
    """
    trial = whole("trial", trial)
    loc = np.asarray(location, float).ravel()
    if loc.shape != (3,) or not np.all(np.isfinite(loc)):
        raise ConfigError(f"trial location must be three finite numbers (m), got {location!r}")
    where = [int(round(v * 1e6)) % 2**32 for v in loc]  # µm, wrapped to non-negative
    return np.random.default_rng(np.random.SeedSequence([check_seed(seed), trial, *where]))


__all__ = ["MAX_TRIALS", "Perturbations", "check_seed", "check_trials", "trial_rng"]
