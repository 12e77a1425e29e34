"""Checks of JSON values read from a plan file; each raises ConfigError naming the key path."""

from __future__ import annotations

import json

import numpy as np

from flipkit.errors import ConfigError


def check_array(name: str, value, shape: tuple) -> np.ndarray:
    """``value`` as a finite float array of ``shape`` (``None`` entries match any size)."""
    try:
        arr = np.array(value)
    except (TypeError, ValueError):  # ragged nesting
        arr = np.array(None)
    if arr.dtype.kind not in "iuf":
        raise ConfigError(f"{name}: expected an array of numbers")
    arr = arr.astype(float)
    if arr.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, arr.shape)):
        want = ", ".join("n" if s is None else str(s) for s in shape)
        raise ConfigError(f"{name}: expected shape ({want}), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name}: contains a non-finite number (NaN or inf)")
    return arr


# Nodes per segment read: the planners use 21 (N = 20), the scaling study up to 81; verify's
# time grows with the nodes, and this bound keeps a file from making it run for minutes.
MAX_NODES = 1001


def check_times(name: str, value) -> np.ndarray:
    """A segment's node times ``t`` (s): N+1 of them, N even in [2, MAX_NODES − 1], finite
    and strictly increasing.

    Raises:
        ConfigError: One line naming ``name`` and, for a grid that does not increase, the
            first pair of node times out of order.
    """
    t = check_array(name, value, (None,))
    n = t.size
    if n < 3 or n % 2 == 0 or n > MAX_NODES:
        raise ConfigError(f"{name}: expected N+1 node times with N even in [2, "
                          f"{MAX_NODES - 1}], got {n}")
    steps = np.diff(t)
    if not np.all(steps > 0):
        i = int(np.argmax(steps <= 0))
        raise ConfigError(f"{name}: node times must increase strictly, got t[{i}] = "
                          f"{t[i]:.9g} s, t[{i + 1}] = {t[i + 1]:.9g} s")
    return t


def check_number(name: str, value, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        raise ConfigError(f"{name}: expected a number, got {value!r}")
    if not np.isfinite(value) or (positive and value <= 0):
        raise ConfigError(f"{name}: expected a {'positive ' if positive else ''}finite number, "
                          f"got {value!r}")
    return float(value)


def check_choice(name: str, value, choices) -> str:
    if value not in choices:
        raise ConfigError(f"{name}: {value!r} is not one of {', '.join(map(repr, choices))}")
    return value


def check_text(name: str, value) -> str:
    if not isinstance(value, str):
        raise ConfigError(f"{name}: expected a string, got {value!r}")
    return value


def check_keys(obj, path: str, keys) -> dict:
    """The required ``keys`` of the JSON object ``obj`` at ``path``."""
    if not isinstance(obj, dict):
        raise ConfigError(f"{path or 'top level'}: expected a JSON object")
    for key in keys:
        if key not in obj:
            raise ConfigError(f"{path + '.' if path else ''}{key}: missing key")
    return {key: obj[key] for key in keys}


def check_nested(path: str, build, obj, keys):
    """``build(**fields)`` with errors prefixed by ``path``."""
    kwargs = check_keys(obj, path, keys)
    try:
        return build(**kwargs)
    except ConfigError as exc:
        raise ConfigError(f"{path}.{exc}") from None


def dumps(obj, level: int = 0) -> str:
    """JSON text with one line per vector or matrix row (stable key order, no NaN)."""
    pad, end = " " * (level + 1), "\n" + " " * level
    if isinstance(obj, dict) and obj:
        return "{\n" + ",\n".join(f"{pad}{json.dumps(k)}: {dumps(v, level + 1)}"
                                   for k, v in obj.items()) + end + "}"
    if isinstance(obj, list) and any(isinstance(v, (dict, list)) for v in obj):
        return "[\n" + ",\n".join(pad + dumps(v, level + 1) for v in obj) + end + "]"
    return json.dumps(obj, allow_nan=False)
