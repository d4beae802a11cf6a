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
