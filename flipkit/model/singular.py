"""The UR arm's elbow and wrist singularities, and joint bounds that keep a plan clear of them.

The spatula Jacobian of a UR arm loses rank where sin q3 = 0 (the arm stretched out or folded
onto itself: the elbow singularity) and where sin q5 = 0 (wrist 1 and wrist 3 axes aligned:
the wrist singularity); the third, with the wrist centre on the base axis, lies far from the
grill. A joint-space plan may cross either (its joint rates are bounded directly), but a
controller or an IK that follows its spatula poses cannot, and the judge of
:mod:`flipkit.baseline.classify` fails both methods there. :func:`branch_bounds` keeps q3 and
q5 on the side of the singularity where the home configuration is, ``margin`` from it.
Without these bounds the Table I plans cross sin q5 = 0 in the go to burger and fold the
elbow to q3 = π in the turn back; the default margin (:data:`SINGULARITY_MARGIN`) keeps the
Jacobian's smallest singular value near the judge's threshold over the grill
(``docs/history.md``, "Measurements behind the code's choices").
"""

from __future__ import annotations

import math

import numpy as np

from flipkit.errors import ConfigError

ELBOW, WRIST = 2, 4  # indices of q3 and q5
SINGULARITY_MARGIN = 0.2  # rad, default distance of q3 and q5 from their singular values


def branch_bounds(q_min, q_max, q_home, q_start, margin: float):
    """Joint bounds (rad) with q3 and q5 kept within (kπ + margin, (k+1)π − margin), the
    interval of q_home, widened to contain q_start (a plan may start closer than ``margin``).

    Args:
        q_min, q_max: Joint limits (rad). q_home: Configuration that fixes the branch (rad).
        q_start: Start configuration of the segment (rad). margin: Distance (rad) in
            [0, π/2); 0 leaves the bounds as they are.

    Returns:
        (lo, hi): The narrowed bounds, copies.
    """
    if not (math.isfinite(margin) and 0 <= margin < math.pi / 2):
        raise ConfigError(f"singularity margin must be in [0, pi/2) rad, got {margin!r}")
    lo, hi = np.array(q_min, float), np.array(q_max, float)
    if margin == 0:
        return lo, hi
    for j in (ELBOW, WRIST):
        k = math.floor(q_home[j] / math.pi)
        lo[j] = min(max(lo[j], k * math.pi + margin), q_start[j])
        hi[j] = max(min(hi[j], (k + 1) * math.pi - margin), q_start[j])
    return lo, hi


def branch_band(q_home, margin: float = SINGULARITY_MARGIN) -> np.ndarray:
    """The band (kπ + margin, (k+1)π − margin) of q3 and q5 that holds q_home (rad), as rows
    (lo, hi) for the joints (ELBOW, WRIST): the bounds :func:`branch_bounds` imposes on a
    plan that starts inside them.

    Returns:
        (2, 2) array: row j is (lo, hi) of joint (ELBOW, WRIST)[j] (rad).
    """
    if not (math.isfinite(margin) and 0 <= margin < math.pi / 2):
        raise ConfigError(f"singularity margin must be in [0, pi/2) rad, got {margin!r}")
    band = []
    for j in (ELBOW, WRIST):
        k = math.floor(float(q_home[j]) / math.pi)
        band.append((k * math.pi + margin, (k + 1) * math.pi - margin))
    return np.array(band)


def branch_violation(q, q_home, margin: float = SINGULARITY_MARGIN) -> np.ndarray:
    """How far (rad, ≥ 0) q3 and q5 of each configuration lie outside :func:`branch_band`.

    Args:
        q: Configurations (n, nq) or (nq,) (rad). q_home: Fixes the branch (rad).
        margin: Distance (rad) from the singular values.

    Returns:
        (n, 2) array: columns q3 (elbow) and q5 (wrist); 0 inside the band.
    """
    q = np.atleast_2d(np.asarray(q, float))
    band = branch_band(q_home, margin)
    x = q[:, [ELBOW, WRIST]]
    return np.maximum(np.maximum(band[:, 0] - x, x - band[:, 1]), 0.0)


__all__ = ["ELBOW", "SINGULARITY_MARGIN", "WRIST", "branch_band", "branch_bounds",
           "branch_violation"]
