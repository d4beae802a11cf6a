"""Walls as merged boxes: exact cover of the blocking cells, and few boxes on real maps."""

from __future__ import annotations

import numpy as np
import pytest

import arena.plugins  # noqa: F401  (map generators)
from arena.core.errors import MapError
from arena.core.rng import derive_rng
from arena.maps.generators import MAP_GENERATORS
from arena.maps.grid import OccupancyGrid
from arena.maps.io import load_map
from arena.maps.sources import packaged_worlds, resolve_world
from arena.sim.mujoco.scene import WorldParams
from arena.sim.mujoco.walls import merge_boxes
from arena.sim.mujoco.world import wall_body


def assert_exact_cover(mask: np.ndarray, rects: np.ndarray) -> None:
    """Every True cell in exactly one rectangle, no False cell in any."""
    count = np.zeros(mask.shape, dtype=np.int64)
    for r0, c0, r1, c1 in rects:
        assert r0 < r1 and c0 < c1
        count[r0:r1, c0:c1] += 1
    assert count.max(initial=0) <= 1, "rectangles overlap"
    np.testing.assert_array_equal(count == 1, mask)


@pytest.mark.parametrize("fill", [0.05, 0.3, 0.7, 1.0])
def test_random_grids_are_covered_exactly(fill: float) -> None:
    rng = np.random.default_rng(7)
    for _ in range(20):
        shape = tuple(rng.integers(1, 40, size=2))
        mask = rng.random(shape) < fill
        assert_exact_cover(mask, merge_boxes(mask))


def test_blocky_walls_merge_into_rectangles() -> None:
    mask = np.zeros((30, 40), dtype=bool)
    mask[5:25, 10:20] = True  # one 20 x 10 block
    mask[0, :] = True          # a wall along the bottom row
    rects = merge_boxes(mask)
    assert rects.tolist() == [[0, 0, 1, 40], [5, 10, 25, 20]]
    assert len(merge_boxes(np.zeros((5, 5), dtype=bool))) == 0


# box counts of the packaged worlds (occupied cells -> boxes): long straight walls give one box
PACKAGED_BOXES = {"campus": 11, "corridor": 19, "empty_room": 4, "hospital_floor": 30,
                  "small_office": 28}


@pytest.mark.parametrize("world", sorted(PACKAGED_BOXES))
def test_packaged_worlds_few_boxes(world: str) -> None:
    assert world in packaged_worlds()
    grid = load_map(resolve_world(world))
    rects = merge_boxes(grid.occupied)
    assert_exact_cover(grid.occupied, rects)
    assert len(rects) == PACKAGED_BOXES[world]
    assert grid.occupied.sum() > 300 * len(rects)


def test_generated_240_map_few_boxes() -> None:
    spec = {"type": "rosnav_indoor", "width": 12, "height": 12, "resolution": 0.05}
    grid = MAP_GENERATORS.build(spec, source="test").build(derive_rng(0, "map")).grid
    assert grid.data.shape == (240, 240)
    rects = merge_boxes(grid.occupied)
    assert_exact_cover(grid.occupied, rects)
    assert len(rects) == 9  # of 16,000 occupied cells


def test_wall_boxes_in_world_coordinates() -> None:
    grid = OccupancyGrid.empty(3.0, 2.0, 0.1, origin=(-1.0, 5.0))
    body = wall_body(grid, WorldParams(wall_height=2.5))
    assert len(body.geoms) == 4
    bottom = body.geoms[0]  # row 0: y in [5.0, 5.1], x over the whole width
    assert bottom.type == "box"
    np.testing.assert_allclose(bottom.pos, (0.5, 5.05, 1.25))
    np.testing.assert_allclose(bottom.size, (1.5, 0.05, 1.25))


def test_too_many_boxes_is_one_line() -> None:
    mask = np.zeros((20, 20), dtype=bool)
    mask[::2, ::2] = True  # a checkerboard of single cells: 100 boxes
    grid = OccupancyGrid.from_occupied(mask, 0.1)
    with pytest.raises(MapError, match=r"^big.yaml: its walls need 100 boxes in 3-D, more than "
                       r"max_wall_boxes=50 "):
        wall_body(grid, WorldParams(max_wall_boxes=50), source="big.yaml")
