"""Batched planar distances (flipkit.planning.kitchen.planar) against a plain per-point,
per-edge computation, on random convex polygons of mixed sizes (fixed seed), and the
degenerate ones (a point, a segment) the blade's clipped section can be."""

import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from flipkit.planning.kitchen.planar import (pad_polygons, points_polygon_distance,
                                             polygon_distances, segment_distances)


def seg_dist(p, a, b):
    """Distance from p to segment ab, written out."""
    ax, ay, bx, by, px, py = *a, *b, *p
    dx, dy = bx - ax, by - ay
    n = dx * dx + dy * dy
    s = 0.0 if n == 0 else min(1.0, max(0.0, ((px - ax) * dx + (py - ay) * dy) / n))
    return math.hypot(px - (ax + s * dx), py - (ay + s * dy))


def poly_dist(p, poly):
    """Distance from p to a convex polygon: 0 inside (3+ vertices), else to the nearest edge."""
    k = len(poly)
    d = min(seg_dist(p, poly[i], poly[(i + 1) % k]) for i in range(k))
    if k >= 3:
        signs = [(poly[(i + 1) % k][0] - poly[i][0]) * (p[1] - poly[i][1])
                 - (poly[(i + 1) % k][1] - poly[i][1]) * (p[0] - poly[i][0]) for i in range(k)]
        if all(c >= 0 for c in signs) or all(c <= 0 for c in signs):
            return 0.0
    return d


@pytest.fixture(scope="module")
def shapes():
    rng = np.random.default_rng(7)
    polys = []
    for k in (3, 4, 5, 6, 8):
        pts = rng.uniform(-0.1, 0.1, (k + 4, 2)) + rng.uniform(-0.2, 0.2, 2)
        hull = pts[ConvexHull(pts).vertices]
        polys.append(hull if rng.random() < 0.5 else hull[::-1])  # either winding
    polys += [np.array([[0.05, 0.02]]), np.array([[-0.1, 0.0], [0.1, 0.05]])]
    points = rng.uniform(-0.35, 0.35, (200, 2))
    return polys, points


def test_polygon_distances_match_the_written_out_distance(shapes):
    polys, points = shapes
    padded, counts = pad_polygons(polys)
    assert padded.shape == (len(polys), max(len(p) for p in polys), 2)
    got = polygon_distances(points, padded, counts)
    want = np.array([[poly_dist(p, poly) for p in points] for poly in polys])
    assert np.allclose(got, want, rtol=0, atol=1e-12)
    assert (got == 0).sum() > 10  # some points lie inside, and are found so


def test_one_polygon_form_agrees_and_no_polygon_is_infinitely_far(shapes):
    polys, points = shapes
    for poly in polys:
        assert np.allclose(points_polygon_distance(points, poly),
                           [poly_dist(p, poly) for p in points], rtol=0, atol=1e-12)
    assert np.all(np.isinf(points_polygon_distance(points, np.zeros((0, 2)))))


def test_segment_distances_match_the_written_out_distance(shapes):
    _polys, points = shapes
    rng = np.random.default_rng(3)
    A, B = rng.uniform(-0.2, 0.2, (6, 2)), rng.uniform(-0.2, 0.2, (6, 2))
    B[0] = A[0]  # a segment of zero length is its point
    got = segment_distances(points, A, B)
    want = np.array([[seg_dist(p, a, b) for p in points] for a, b in zip(A, B)])
    assert np.allclose(got, want, rtol=0, atol=1e-12)
