"""Argument checks shared by the configuration dataclasses; each raises ConfigError."""

from __future__ import annotations

import math

import numpy as np

from flipkit.errors import ConfigError, brief

COUNT_WORDS = {2: "two", 3: "three", 6: "six"}


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


def real_vector(name: str, values, n: int, unit: str, error: type = ConfigError) -> np.ndarray:
    """``values`` as ``n`` finite floats: a sequence or array of real numbers, not text, a
    mapping, booleans or complex numbers.

    Raises:
        ConfigError: (``error``) One line naming ``name``, the count and unit, and the value.
    """
    try:
        arr = np.asarray(values)
    except (TypeError, ValueError):  # a ragged sequence
        arr = None
    count = COUNT_WORDS.get(n, str(n))
    if arr is None or arr.dtype.kind not in "iuf" or arr.shape != (n,):
        raise error(f"{name} must be {count} finite numbers ({unit}), got {brief(values)}")
    arr = arr.astype(float)
    if not np.all(np.isfinite(arr)):
        raise error(f"{name} must be {count} finite numbers ({unit}), got {arr.tolist()}")
    return arr


def real_number(name: str, value, unit: str) -> float:
    """``value`` as a finite float: a real number, not text, a boolean or an array.

    Raises:
        ConfigError: One line naming ``name``, the unit and the value.
    """
    if (isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer,
                                                                      np.floating))
            or not math.isfinite(value)):
        raise ConfigError(f"{name} must be a finite number ({unit}), got {brief(value)}")
    return float(value)
