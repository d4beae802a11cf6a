import math

import numpy as np
import pytest

from arena.core import geometry as g
from arena.core.types import Outcome, Pose2D, Twist


def test_wrap_angle():
    a = g.wrap_angle([0.0, math.pi, -math.pi, 3 * math.pi, 7.0])
    assert np.all(a >= -math.pi) and np.all(a < math.pi)
    assert np.allclose(np.cos(a), np.cos([0.0, math.pi, -math.pi, 3 * math.pi, 7.0]))


def test_transform_roundtrip_and_batch():
    pts = np.array([[1.0, 0.0], [0.0, 2.0]])
    pose = np.array([1.0, -1.0, math.pi / 2])
    w = g.transform_points(pts, pose)
    assert np.allclose(w, [[1.0, 0.0], [-1.0, -1.0]])
    assert np.allclose(g.to_body_frame(w, pose), pts)
    batch = g.transform_points(pts, np.stack([pose, np.zeros(3)]))
    assert batch.shape == (2, 2, 2)
    assert np.allclose(batch[1], pts)


def test_pose_compose_and_twist():
    a = Pose2D(1.0, 2.0, math.pi / 2)
    b = a.compose(Pose2D(1.0, 0.0, 0.0))
    assert b.x == pytest.approx(1.0) and b.y == pytest.approx(3.0)
    assert Pose2D.from_array([1, 2]).theta == 0.0
    assert np.array_equal(Twist(1, 2, 3).as_array(), [1, 2, 3])
    with pytest.raises(ValueError):
        Pose2D.from_array([1.0])
    assert Outcome("success") is Outcome.SUCCESS


def test_polygon_area_and_point_in_polygon():
    sq = g.rectangle(2.0, 1.0)
    assert g.polygon_area(sq) == pytest.approx(2.0)
    assert g.polygon_area(sq[::-1]) == pytest.approx(-2.0)
    inside = g.points_in_polygon([[0, 0], [0.99, 0.49], [1.01, 0], [0, 0.6]], sq)
    assert inside.tolist() == [True, True, False, False]
    # Concave L-shape.
    l_shape = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=float)
    assert g.points_in_polygon([[1.5, 1.5], [0.5, 1.5], [1.5, 0.5]], l_shape).tolist() == [
        False,
        True,
        True,
    ]


def test_point_segment_distance_matches_brute_force():
    rng = np.random.default_rng(0)
    pts = rng.uniform(-3, 3, (20, 2))
    a = rng.uniform(-3, 3, (5, 2))
    b = rng.uniform(-3, 3, (5, 2))
    d = g.point_segment_distance(pts, a, b)
    t = np.linspace(0, 1, 20001)
    for j in range(5):
        seg = a[j] + t[:, None] * (b[j] - a[j])
        brute = np.min(np.linalg.norm(pts[:, None, :] - seg[None], axis=2), axis=1)
        assert np.allclose(d[:, j], brute, atol=1e-3)


def test_segments_intersect_cases():
    a1, b1 = np.array([[0.0, 0.0]]), np.array([[2.0, 2.0]])
    assert g.segments_intersect(a1, b1, [[0, 2]], [[2, 0]])[0, 0]
    assert not g.segments_intersect(a1, b1, [[3, 0]], [[4, 1]])[0, 0]
    assert g.segments_intersect(a1, b1, [[1, 1]], [[3, 3]])[0, 0]  # collinear overlap
    assert not g.segments_intersect(a1, b1, [[3, 3]], [[4, 4]])[0, 0]  # collinear apart


def test_overlaps_and_hull():
    sq = g.rectangle(1.0, 1.0)
    assert g.circles_overlap_polygon([[0.9, 0], [2, 0], [0, 0]], [0.5, 0.5, 0.1], sq).tolist() == [
        True,
        False,
        True,
    ]
    assert g.polygons_overlap(sq, sq + 0.9)
    assert not g.polygons_overlap(sq, sq + 1.1)
    assert g.polygons_overlap(g.rectangle(3, 3), sq)  # containment
    hull = g.convex_hull(np.vstack([sq, [[0, 0], [0.1, 0.2]]]))
    assert len(hull) == 4 and g.polygon_area(hull) == pytest.approx(1.0)


def test_convex_polygon_overlaps_squares_matches_sampling():
    rng = np.random.default_rng(1)
    for _ in range(20):
        poly = g.transform_points(g.rectangle(*rng.uniform(0.2, 1.5, 2)), rng.uniform(-1, 1, 3))
        centers = rng.uniform(-2, 2, (50, 2))
        got = g.convex_polygon_overlaps_squares(poly, centers, 0.1)
        # Reference: dense sampling of each square interior.
        s = np.linspace(-0.0999, 0.0999, 25)
        gx, gy = np.meshgrid(s, s)
        offs = np.stack([gx.ravel(), gy.ravel()], 1)
        for c, flag in zip(centers, got, strict=True):
            sampled = g.points_in_polygon(c + offs, poly).any()
            if sampled:
                assert flag
            # A miss by sampling but a hit by SAT is only allowed within the sampling gap.
            if flag and not sampled:
                assert np.min(g.point_segment_distance(c[None], poly, np.roll(poly, -1, 0))) < 0.15


def _reference_points_in_polygon(points, polygon):
    """The vectorised even-odd test the kernel replaced."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    a = np.asarray(polygon, dtype=np.float64)
    b = np.roll(a, -1, axis=0)
    px, py = p[:, 0:1], p[:, 1:2]
    crosses = (a[:, 1] > py) != (b[:, 1] > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_at = a[:, 0] + (py - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return np.count_nonzero(crosses & (px < x_at), axis=1) % 2 == 1


def _reference_squares(polygon, centers, half_size):
    """The vectorised separating-axis test the kernel replaced."""
    poly = np.asarray(polygon, dtype=np.float64)
    c = np.asarray(centers, dtype=np.float64).reshape(-1, 2)
    ok = (c[:, 0] - half_size < poly[:, 0].max()) & (c[:, 0] + half_size > poly[:, 0].min())
    ok &= (c[:, 1] - half_size < poly[:, 1].max()) & (c[:, 1] + half_size > poly[:, 1].min())
    edges = np.roll(poly, -1, axis=0) - poly
    normals = np.stack([-edges[:, 1], edges[:, 0]], axis=1)
    proj_poly = poly @ normals.T
    pmin, pmax = proj_poly.min(axis=0), proj_poly.max(axis=0)
    proj_c = c @ normals.T
    extent = half_size * (np.abs(normals[:, 0]) + np.abs(normals[:, 1]))
    return ok & np.all((proj_c - extent < pmax) & (proj_c + extent > pmin), axis=1)


@pytest.mark.parametrize("seed", range(30))
def test_points_in_polygon_matches_vectorised_reference(seed):
    rng = np.random.default_rng(seed)
    poly = rng.normal(size=(int(rng.integers(0, 10)), 2)) * rng.uniform(0.1, 4)
    pts = rng.normal(size=(int(rng.integers(0, 300)), 2)) * 3
    if seed % 2:  # grid-aligned: points on vertices and edges, horizontal edges
        poly, pts = np.round(poly * 4) / 4, np.round(pts * 8) / 8
        k = min(len(poly), len(pts))
        pts[:k] = poly[:k]
    got = g.points_in_polygon(pts, poly)
    want = _reference_points_in_polygon(pts, poly)
    assert got.dtype == want.dtype and np.array_equal(got, want)
    assert g.points_in_polygon([0.2, 0.1], [[0, 0], [1, 0], [1, 1]]).tolist() == [True]


@pytest.mark.parametrize("seed", range(30))
def test_convex_polygon_overlaps_squares_matches_vectorised_reference(seed):
    rng = np.random.default_rng(seed)
    if seed % 3 == 0:
        size = np.round(rng.uniform(0.2, 2, 2) * 20) / 20
        poly = g.rectangle(*size, center=(0.05 * int(rng.integers(-9, 9)), 0.025))
    elif seed % 3 == 1:
        poly = g.transform_points(g.rectangle(*rng.uniform(0.1, 2, 2)), rng.normal(size=3))
    else:
        poly = g.convex_hull(rng.normal(size=(8, 2)))
    centers = (rng.integers(-50, 50, size=(int(rng.integers(0, 600)), 2)) + 0.5) * 0.05
    for half in (0.025, 0.1):
        got = g.convex_polygon_overlaps_squares(poly, centers, half)
        want = _reference_squares(poly, centers, half)
        assert got.dtype == want.dtype and np.array_equal(got, want)


def test_polyline_length_reference_values_and_columns():
    # a 3-4-5 leg then 1 m along x: 5 + 1 m; a heading column is ignored
    pts = np.array([[0.0, 0.0, 0.3], [3.0, 4.0, -1.0], [4.0, 4.0, 2.0]])
    np.testing.assert_array_equal(g.segment_lengths(pts), [5.0, 1.0])
    assert g.polyline_length(pts) == 6.0
    assert g.polyline_length(pts[:, :2].tolist()) == 6.0
    # fewer than two points: no segment, length 0
    assert g.segment_lengths(pts[:1]).shape == (0,)
    assert g.polyline_length(np.zeros((0, 2))) == 0.0
    # hypot per segment, so the length is the same number the driven-path metrics report
    d = np.random.default_rng(3).normal(size=(50, 2)).cumsum(axis=0)
    np.testing.assert_array_equal(g.segment_lengths(d), np.hypot(*np.diff(d, axis=0).T))
