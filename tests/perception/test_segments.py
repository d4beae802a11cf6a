"""Scan segments and their features on scans of known shapes (the project's own lidar)."""

from __future__ import annotations

import numpy as np
import pytest

from arena.maps.grid import OccupancyGrid
from arena.perception.segments import FEATURES, scan_points, segment_scan
from arena.sensors.lidar2d import Lidar2D
from arena.sensors.spec import LidarSpec

SPEC = LidarSpec(angle_min=-np.pi, angle_max=np.pi, num_beams=720, range_max=12.0)
F = {name: k for k, name in enumerate(FEATURES)}


def scan(circles: list[tuple[float, float, float]]):
    occ = np.zeros((200, 200), dtype=bool)  # 10 x 10 m at 0.05 m, a wall along y = 8 m
    occ[160:162, 20:180] = True
    lidar = Lidar2D(SPEC)
    lidar.bind(OccupancyGrid.from_occupied(occ, 0.05))
    c = np.array(circles, dtype=np.float64).reshape(-1, 3)
    ranges = lidar.scan(np.array([5.0, 5.0, 0.0]), c[:, :2], c[:, 2])
    return scan_points(ranges, SPEC.angles(), SPEC.range_max)


def nearest(segs, xy):
    k = int(np.argmin(np.hypot(*(segs.centroids - np.asarray(xy)).T)))
    return segs.features[k], segs.centroids[k]


def test_a_leg_a_body_and_a_wall_have_the_features_that_tell_them_apart():
    # sensor at (5, 5) facing +x: a leg (r 0.07) 2 m ahead, a body (r 0.25) 2 m to the left,
    # the wall 3 m to the left (y = 8 m)
    pts, valid = scan([(7.0, 5.0, 0.07), (5.0, 7.0, 0.25)])
    segs = segment_scan(pts, valid, max_points=400)
    assert segs.features.shape[1] == len(FEATURES)
    leg, c_leg = nearest(segs, (2.0, 0.0))
    assert np.hypot(*(c_leg - [1.95, 0.0])) < 0.05  # the visible arc's centroid
    assert leg[F["radius"]] == pytest.approx(0.07, abs=0.02)
    assert leg[F["circularity"]] < 1e-5 and leg[F["width"]] < 0.15
    body, _ = nearest(segs, (0.0, 1.8))
    assert body[F["radius"]] == pytest.approx(0.25, abs=0.03) and body[F["width"]] > 0.3
    assert body[F["circularity"]] < 1e-5  # an arc: a circle fits, a line does not
    wall, c_wall = nearest(segs, (3.0, 3.0))  # a piece of the wall, ahead to the left
    assert c_wall[1] == pytest.approx(3.0, abs=0.05)
    assert wall[F["linearity"]] < 1e-5 and wall[F["width"]] > 1.0


def test_small_and_long_segments_are_dropped_and_an_empty_scan_gives_none():
    pts, valid = scan([(7.0, 5.0, 0.07)])
    walls_too = segment_scan(pts, valid, max_points=400)
    legs_only = segment_scan(pts, valid, max_points=40)
    assert len(legs_only) < len(walls_too)
    assert all(b1 - b0 <= 40 for b0, b1 in legs_only.bounds.tolist())
    none = segment_scan(pts, np.zeros(len(pts), dtype=bool))
    assert len(none) == 0 and none.features.shape == (0, len(FEATURES))
