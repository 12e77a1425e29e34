"""Argument checks shared by the configuration dataclasses; each raises ConfigError."""

from __future__ import annotations

import math

import numpy as np

from flipkit.errors import ConfigError


def finite(name: str, values, shape: tuple[int, ...] | None = None) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    if shape is not None and arr.shape != shape:
        raise ConfigError(f"{name} must have shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def positive(name: str, value: float) -> None:
    if not (math.isfinite(value) and value > 0):
        raise ConfigError(f"{name} must be a positive finite number, got {value!r}")


def box(name: str, lower, upper, n: int) -> None:
    lo, hi = finite(f"{name} lower", lower, (n,)), finite(f"{name} upper", upper, (n,))
    if np.any(lo >= hi):
        raise ConfigError(f"{name}: lower bound must be below upper bound, got {lo} >= {hi}")


def whole(name: str, value, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int, or ConfigError: an integer (a bool is not one) in [low, high]."""
    if (isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low
            or (high is not None and value > high)):
        what = (f"an integer in [{low}, {high}]" if high is not None
                else "a non-negative integer" if low == 0 else "a positive integer" if low == 1
                else f"an integer >= {low}")
        raise ConfigError(f"{name} must be {what}, got {value!r}")
    return int(value)
