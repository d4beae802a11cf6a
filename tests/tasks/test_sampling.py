"""Kernels and per-map caches behind the random task modes, against their plain numpy forms."""

import numpy as np
import pytest

from arena.core.geometry import rectangle, transform_points
from arena.maps.distance import clearance_map, grid_memo
from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import make_obstacle
from arena.maps.raster import polygon_mask
from arena.scene.state import Obstacle
from arena.tasks.obstacle_modes.random import walkable_mask
from arena.tasks.sampling import MaskRegions, clear_near, components, max_blocked_sq


def _box(name, x, y, theta, size=(0.8, 0.5)):
    poly = transform_points(rectangle(*size), [x, y, theta])
    return Obstacle(name, "cuboid", np.array([x, y, theta]), poly, height=1.0)


def _room():
    occ = np.zeros((60, 90), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[:, 45] = True
    occ[20:26, 45] = False  # a door
    occ[40:, 70] = True
    return OccupancyGrid.from_occupied(occ, 0.05, (-1.0, -2.0))


@pytest.mark.parametrize("seed", range(40))
def test_mask_regions_match_labels(seed):
    rng = np.random.default_rng(seed)
    h, w = rng.integers(1, 50, size=2)
    mask = rng.random((h, w)) < rng.uniform(0.2, 0.8)
    labels = components(mask)
    regions = MaskRegions(mask)
    for _ in range(8):
        r, c = int(rng.integers(-h, h)), int(rng.integers(-w, w))  # negative: numpy's rules
        got = regions.cells(r, c)
        lab = labels[r, c]
        want = np.argwhere(labels == lab) if lab else np.zeros((0, 2), dtype=np.int64)
        assert got.dtype == np.int64
        assert np.array_equal(got, want)
    with pytest.raises(IndexError):
        regions.cells(int(h), 0)


def test_mask_regions_diagonal_contact_joins():
    mask = np.zeros((4, 4), dtype=bool)
    mask[0, 0] = mask[1, 1] = mask[3, 3] = True
    regions = MaskRegions(mask)
    assert regions.cells(1, 1).tolist() == [[0, 0], [1, 1]]
    assert regions.cells(3, 3).tolist() == [[3, 3]]
    assert regions.cells(2, 2).shape == (0, 2)


@pytest.mark.parametrize("res", [0.05, 0.1, 0.03])
def test_max_blocked_sq_is_the_clearance_threshold(res):
    d2 = np.arange(20000, dtype=np.float64)
    values = np.sqrt(d2) * res - 0.5 * res
    for clearance in np.linspace(-0.1, 2.0, 97):
        close = np.flatnonzero(values <= clearance)
        assert max_blocked_sq(res, float(clearance)) == (close.max() if close.size else -1)


@pytest.mark.parametrize("seed", range(10))
def test_clear_near_equals_recomputed_clearance(seed):
    rng = np.random.default_rng(seed)
    grid = _room()
    base_blocked = grid.occupied | ~grid.free
    extra = np.zeros_like(base_blocked)
    for _ in range(4):
        r, c = rng.integers(0, grid.height), rng.integers(0, grid.width)
        extra[r : r + rng.integers(1, 8), c : c + rng.integers(1, 8)] = True
    body = float(rng.uniform(0.05, 0.5))
    want = (clearance_map(grid, base_blocked | extra) > body) & grid.free
    got = (clearance_map(grid, base_blocked) > body) & grid.free
    clear_near(got, np.argwhere(extra), max_blocked_sq(grid.resolution, body))
    assert np.array_equal(got, want)


def test_grid_memo_is_per_grid_object_and_key():
    grid = _room()
    calls = []

    def compute():
        calls.append(1)
        return len(calls)

    assert grid_memo(grid, ("test", 1), compute) == 1
    assert grid_memo(grid, ("test", 1), compute) == 1
    assert grid_memo(grid, ("test", 2), compute) == 2
    # An equal map that is another object (a rebuilt or regenerated map) is not served stale.
    assert grid_memo(_room(), ("test", 1), compute) == 3


@pytest.mark.parametrize("seed", range(6))
def test_walkable_mask_matches_full_recomputation(seed):
    rng = np.random.default_rng(seed)
    grid = _room()
    map_obstacles = [make_obstacle("M_shelf_1", "shelf", [1.0, 0.5, 0.3])] if seed % 2 else []
    placed = [
        _box(f"S_box_{k}", rng.uniform(-0.5, 3.2), rng.uniform(-1.5, 0.8), rng.uniform(-3, 3))
        for k in range(4)
    ]
    for body in (0.35, 0.2):
        blocked = grid.occupied | ~grid.free
        blocked = blocked | polygon_mask(grid, [o.polygon for o in map_obstacles + placed])
        want = (clearance_map(grid, blocked) > body) & grid.free
        got = walkable_mask(grid, map_obstacles, placed, body)
        assert np.array_equal(got, want)
        assert got.flags.writeable  # a fresh mask each call; the cached part stays intact
        got[:] = False
        assert np.array_equal(walkable_mask(grid, map_obstacles, placed, body), want)


def test_walkable_mask_follows_the_map_obstacles():
    """The per-map part is keyed by the map's own obstacles: another set is not served stale."""
    grid = _room()
    shelf = make_obstacle("M_shelf_1", "shelf", [1.0, 0.5, 0.3])
    bare = walkable_mask(grid, [], [], 0.35)
    with_shelf = walkable_mask(grid, [shelf], [], 0.35)
    assert with_shelf.sum() < bare.sum()
    assert np.array_equal(walkable_mask(grid, [], [], 0.35), bare)
