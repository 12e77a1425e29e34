"""Distances in the grill's plane between points, segments and convex polygons.

The clearance checks of :mod:`flipkit.planning.kitchen.sweep` compare a few lying burgers, or
a grid of candidate landing spots, with the hundreds of blade sections and carried-burger
strokes of a plan's footprint. The ``*_distances`` forms take all of a footprint's polygons
(or segments) at once, as padded arrays, so a check costs a few array operations instead of
one Python call per sample. All inputs are in metres; only x and y are used.
"""

from __future__ import annotations

import numpy as np

INSIDE_TOL = 1e-15  # m²: edge cross products this close to 0 count as on the edge (inside)


def point_polygon_distance(point, polygon) -> float:
    """Distance (m) in the plane from ``point`` to a convex polygon (k×2, in order; also a
    segment or a point): 0 inside it; ``inf`` for no polygon."""
    return float(points_polygon_distance(np.asarray(point, float)[None, :2], polygon)[0])


def points_polygon_distance(points, polygon) -> np.ndarray:
    """:func:`point_polygon_distance` of many points (n×2) at once."""
    P = np.asarray(points, float)[:, :2]
    poly = np.asarray(polygon, float)[:, :2]
    if len(poly) == 0:
        return np.full(len(P), np.inf)
    return polygon_distances(P, poly[None], np.array([len(poly)]))[0]


def points_segment_distance(points, a, b) -> np.ndarray:
    """:func:`point_segment_distance` of many points (n×2) at once."""
    a, b = np.asarray(a, float)[None, :2], np.asarray(b, float)[None, :2]
    return segment_distances(np.asarray(points, float)[:, :2], a, b)[0]


def point_segment_distance(point, a, b) -> float:
    """Distance (m) in the plane from ``point`` to the segment from ``a`` to ``b``."""
    return float(points_segment_distance(np.asarray(point, float)[None, :2], a, b)[0])


def segment_distances(points, A, B) -> np.ndarray:
    """Distances (m×n, m) from n points (n×2) to m segments from ``A[i]`` to ``B[i]`` (m×2)."""
    P = np.asarray(points, float)[None, :, :2]
    A, B = np.asarray(A, float)[:, None, :2], np.asarray(B, float)[:, None, :2]
    AB = B - A
    nn = np.sum(AB * AB, axis=-1)
    PA = P - A
    s = np.clip(np.sum(PA * AB, axis=-1) / np.where(nn > 0, nn, 1.0), 0.0, 1.0)
    return np.linalg.norm(PA - s[..., None] * AB, axis=-1)


def pad_polygons(polygons) -> tuple[np.ndarray, np.ndarray]:
    """Convex polygons (each k_i×2 or more columns, in order, k_i ≥ 1) as one array m×K×2,
    each padded after its own vertices with its first, and their vertex counts k_i (m,)."""
    counts = np.array([len(p) for p in polygons], int)
    K = int(counts.max()) if len(counts) else 1
    out = np.empty((len(counts), K, 2))
    for i, p in enumerate(polygons):
        q = np.asarray(p, float)[:, :2]
        out[i, :len(q)] = q
        out[i, len(q):] = q[0]
    return out, counts


def polygon_distances(points, polygons, counts) -> np.ndarray:
    """Distances (m×n, m) from n points (n×2) to m convex polygons (:func:`pad_polygons`):
    0 inside a polygon of three or more vertices; one or two vertices are a point or a
    segment. The padded vertices repeat the first, so they add edges of zero
    length."""
    P = np.asarray(points, float)[:, :2]
    polys, counts = np.asarray(polygons, float), np.asarray(counts, int)
    m, K = polys.shape[:2]
    idx = np.arange(K)[None, :] + 1
    nxt = np.where(idx < counts[:, None], idx, 0)  # the last vertex and the pads: to the first
    A = polys[:, :, None, :]  # m×K×1×2
    AB = np.take_along_axis(polys, nxt[..., None], axis=1)[:, :, None, :] - A
    PA = P[None, None] - A  # m×K×n×2
    nn = np.sum(AB * AB, axis=-1)
    s = np.clip(np.sum(PA * AB, axis=-1) / np.where(nn > 0, nn, 1.0), 0.0, 1.0)
    best = np.linalg.norm(PA - s[..., None] * AB, axis=-1).min(axis=1)
    cross = AB[..., 0] * PA[..., 1] - AB[..., 1] * PA[..., 0]  # m×K×n; 0 on padded edges
    inside = (np.all(cross >= -INSIDE_TOL, axis=1) | np.all(cross <= INSIDE_TOL, axis=1))
    best[inside & (counts >= 3)[:, None]] = 0.0
    return best


__all__ = ["INSIDE_TOL", "pad_polygons", "point_polygon_distance", "point_segment_distance",
           "points_polygon_distance", "points_segment_distance", "polygon_distances",
           "segment_distances"]
