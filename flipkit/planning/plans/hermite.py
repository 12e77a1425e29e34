"""The extremes of the cubic Hermite interpolant of (q, q̇) between samples: what a
controller's spline asks of the arm between two points.

On interval i, q = c0 τ³ + c1 τ² + c2 τ + c3 (τ ∈ [0, h], scipy's coefficients), so q̈ is
linear (its extremes at the interval's ends) and q̇ a parabola (its extremes at the ends, the
samples' own q̇, or at its vertex τ* = −c1 / (3 c0), clipped to the interval). ``flipkit
verify`` bounds a plan's interpolant with these (:mod:`~flipkit.planning.plans.verify`), and
the stream check a written stream's (:mod:`~flipkit.planning.plans.stream_check`).
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicHermiteSpline


def hermite_extremes(t, q, qd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q̈ at each interval's start and end and q̇ at its vertex, each (n − 1) × nq, for the
    interpolant of ``q`` and ``qd`` (n × nq, rad and rad/s) on the grid ``t`` (n, s)."""
    c = CubicHermiteSpline(t, q, qd, axis=0).c  # (4, n − 1, nq)
    h = np.diff(t)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.clip(np.nan_to_num(-c[1] / (3 * c[0]), nan=0.0, posinf=0.0, neginf=0.0), 0, h)
    return 2 * c[1], 6 * c[0] * h + 2 * c[1], 3 * c[0] * tau**2 + 2 * c[1] * tau + c[2]


__all__ = ["hermite_extremes"]
