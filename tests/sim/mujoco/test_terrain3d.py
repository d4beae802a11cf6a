"""Terrain in the 3-D world: height field and boxes match the height map under a ray cast."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import MapError
from arena.maps.grid import OccupancyGrid
from arena.maps.terrain import HeightMap, terrain_course
from arena.sim.mujoco.mjcf import compile_model, to_mjcf
from arena.sim.mujoco.scene import WorldParams
from arena.sim.mujoco.sdf import to_sdf
from arena.sim.mujoco.terrain import height_field, terrain_boxes
from arena.sim.mujoco.world import build_world
from tests.mujoco_kit import require_mujoco

mujoco = require_mujoco()


def _ground_below(model, points: np.ndarray) -> np.ndarray:
    """Height (m) of the first surface a ray straight down from z = 10 m meets at each point."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    gid = np.zeros(1, dtype=np.int32)
    down = np.array([0.0, 0.0, -1.0])
    return np.array([10.0 - mujoco.mj_ray(model, data, np.array([x, y, 10.0]), down, None, 1, -1,
                                          gid) for x, y in points])


@pytest.mark.parametrize("mode", ["hfield", "boxes"])
def test_ray_cast_down_meets_the_height_map_at_cell_centres(mode):
    world = terrain_course(None, np.random.default_rng(1))
    scene = build_world(world.grid, terrain=world.heights, params=WorldParams(terrain=mode))
    model = compile_model(scene)
    rng = np.random.default_rng(0)
    rows, cols = world.heights.shape
    cells = np.stack([rng.integers(1, rows - 1, 400), rng.integers(1, cols - 1, 400)], axis=1)
    # every part of the course gets sampled points too, not only the level ground
    for x0, y0, x1, y1 in world.features.values():
        pts = np.stack([rng.uniform(x0, x1, 40), rng.uniform(y0, y1, 40)], axis=1)
        cells = np.concatenate([cells, world.grid.world_to_cell(pts)])
    # A ray exactly through a height-field vertex is degenerate (it lies on six triangles'
    # edges; MuJoCo may miss them all next to a step), so the rays pass 10 um off the centre:
    # at a 0.5 m rise over one 0.1 m cell that moves the surface by at most 60 um.
    centres = world.grid.cell_to_world(cells) + np.array([1e-5, 0.7e-5])
    expected = world.heights.heights[cells[:, 0], cells[:, 1]]
    np.testing.assert_allclose(_ground_below(model, centres), expected, atol=1e-4)


def test_hfield_rows_follow_the_map_rows_and_between_centres_stay_within_the_neighbours():
    h = np.zeros((6, 8))
    h[4, 2] = 0.7  # one raised cell, off-centre, so a flipped field would miss it
    hm = HeightMap(h, 0.5, (-1.0, 2.0))
    grid = OccupancyGrid.empty(4.0, 3.0, 0.5, walls=False, origin=(-1.0, 2.0))
    model = compile_model(build_world(grid, terrain=hm))
    peak = grid.cell_to_world(np.array([[4, 2]]))
    assert _ground_below(model, peak)[0] == pytest.approx(0.7, abs=1e-6)
    assert _ground_below(model, grid.cell_to_world(np.array([[1, 5]])))[0] == pytest.approx(0.0)
    half_way = peak + np.array([[0.25, 0.0]])
    assert 0.0 < _ground_below(model, half_way)[0] < 0.7


def test_level_and_zero_terrain():
    grid = OccupancyGrid.empty(2.0, 2.0, 0.1, walls=False)
    assert height_field(HeightMap.flat(grid)) is None
    assert terrain_boxes(HeightMap.flat(grid)) is None
    model = compile_model(build_world(grid, terrain=HeightMap.flat(grid, 0.3)))
    got = _ground_below(model, grid.cell_to_world(np.array([[5, 5], [10, 12]])))
    np.testing.assert_allclose(got, 0.3, atol=1e-5)


def test_terrain_is_exported_in_mjcf_and_sdf_and_refused_when_it_does_not_cover_the_map():
    world = terrain_course(None, np.random.default_rng(0))
    scene = build_world(world.grid, terrain=world.heights)
    xml = to_mjcf(scene)
    assert '<hfield name="terrain"' in xml and 'type="hfield"' in xml
    sdf = to_sdf(scene)
    boxes = terrain_boxes(world.heights)
    assert boxes is not None
    terrain_model = sdf.split('<model name="terrain">')[1].split("</model>")[0]
    assert terrain_model.count("_collision") == len(boxes.geoms)
    assert terrain_model.count("_visual") == len(boxes.geoms)
    small = HeightMap(np.zeros((10, 10)), 0.1)
    with pytest.raises(MapError, match="covers"):
        build_world(world.grid, terrain=small)
    with pytest.raises(MapError, match="terrain boxes"):
        terrain_boxes(world.heights, max_boxes=10)
