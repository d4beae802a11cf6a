"""Back-face culling of obstacle polygons: the same ranges with half the edges tested."""

from __future__ import annotations

import numpy as np
from matplotlib.path import Path

from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import make_obstacle
from arena.scene.state import StaticWorld
from arena.sensors.lidar2d import Lidar2D
from arena.sensors.lidar2d.model import polygon_sides
from arena.sensors.spec import LidarSpec

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def edges(poly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return poly, np.roll(poly, -1, axis=0)


def test_sides_of_closed_polygons_open_chains_and_shared_corners():
    ccw_a, ccw_b = edges(SQUARE)
    cw_a, cw_b = edges(SQUARE[::-1] + np.array([3.0, 0.0]))
    # a clockwise square sharing the first's start corner (0, 0): each closes on its own
    touch_a, touch_b = edges(-SQUARE[[0, 3, 2, 1]])
    open_a = np.array([[5.0, 5.0], [6.0, 5.0]])
    open_b = np.array([[6.0, 5.0], [6.0, 6.0]])
    flat_a, flat_b = edges(np.array([[7.0, 0.0], [8.0, 0.0], [9.0, 0.0]]))  # zero area
    a = np.concatenate([ccw_a, cw_a, touch_a, open_a, flat_a])
    b = np.concatenate([ccw_b, cw_b, touch_b, open_b, flat_b])
    side = polygon_sides(a, b)
    assert side.tolist() == [1.0] * 4 + [-1.0] * 4 + [-1.0] * 4 + [0.0] * 2 + [0.0] * 3
    assert polygon_sides(np.zeros((0, 2)), np.zeros((0, 2))).shape == (0,)


def _scene(rng: np.random.Generator) -> StaticWorld:
    obstacles = tuple(
        make_obstacle(f"o{k}", model, [float(x), float(y), float(t)])
        for k, (model, x, y, t) in enumerate(
            zip(rng.choice(["cuboid", "shelf", "table", "chair"], 12), rng.uniform(1, 9, 12),
                rng.uniform(1, 9, 12), rng.uniform(-np.pi, np.pi, 12), strict=True)
        )
    )
    return StaticWorld.build(OccupancyGrid.empty(10.0, 10.0, 0.05), obstacles)


def test_culled_ranges_equal_testing_every_edge_bit_for_bit():
    rng = np.random.default_rng(7)
    spec = LidarSpec(angle_min=-np.pi, angle_max=np.pi, num_beams=720, range_max=30.0)
    checked = 0
    for _ in range(4):
        world = _scene(rng)
        culled = Lidar2D(spec)
        culled.bind(world.grid, world.segments_a, world.segments_b)
        assert np.count_nonzero(culled._seg_side) == len(world.segments_a)  # all closed
        every = Lidar2D(spec)
        every.bind(world.grid, world.segments_a, world.segments_b)
        every._seg_side = np.zeros(len(world.segments_a))  # no culling
        for _ in range(60):
            pose = np.array([*rng.uniform(0.3, 9.7, 2), rng.uniform(-np.pi, np.pi)])
            if any(Path(o.polygon).contains_point(pose[:2], radius=0.02)
                   or Path(o.polygon[::-1]).contains_point(pose[:2], radius=0.02)
                   for o in world.obstacles):  # (the radius' sign grows CCW polygons)
                continue
            got, want = culled.scan(pose), every.scan(pose)
            assert got.tobytes() == want.tobytes()
            checked += 1
    assert checked > 150


def test_a_sensor_inside_a_polygon_does_not_see_that_obstacle():
    world = StaticWorld.build(OccupancyGrid.empty(10.0, 10.0, 0.05),
                              (make_obstacle("box", "cuboid", [5.0, 5.0, 0.0]),))
    spec = LidarSpec(angle_min=0.0, angle_max=0.0, num_beams=1, range_max=30.0)
    lidar = Lidar2D(spec)
    lidar.bind(world.grid, world.segments_a, world.segments_b)
    assert lidar.scan(np.array([5.0, 5.0, 0.0]))[0] > 4.0  # the map's wall, not the box
    assert lidar.scan(np.array([2.0, 5.0, 0.0]))[0] < 3.0  # from outside: the box
