"""OccupancyGrid: construction, validation, transforms, masks, distance field and inflation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import MapError
from arena.maps import FREE, OCCUPIED, UNKNOWN, OccupancyGrid


def _grid(data, resolution=1.0, origin=(0.0, 0.0), **kw) -> OccupancyGrid:
    return OccupancyGrid(np.asarray(data, dtype=np.int8), resolution, origin, **kw)


# -- construction and validation -------------------------------------------------------------
def test_constants_follow_nav_msgs():
    assert (FREE, OCCUPIED, UNKNOWN) == (0, 100, -1)


def test_data_is_int8_read_only_copy():
    src = np.zeros((2, 3), dtype=np.int8)
    g = OccupancyGrid(src, 0.5)
    assert g.data.dtype == np.int8
    assert not g.data.flags.writeable
    # The caller's array must stay theirs: writable and not aliased.
    assert src.flags.writeable
    src[0, 0] = OCCUPIED
    assert g.data[0, 0] == FREE


def test_fields_are_normalised():
    g = OccupancyGrid(np.zeros((2, 2), dtype=np.int64), 1, origin=np.array([-20, -20]))
    assert g.resolution == 1.0
    assert isinstance(g.resolution, float)
    assert g.origin == (-20.0, -20.0)
    assert all(isinstance(v, float) for v in g.origin)


@pytest.mark.parametrize(
    "data",
    [
        [[0, 50]],  # not a nav_msgs class
        np.array([[0, 255]], dtype=np.uint8),  # would wrap to -1 in int8
        np.array([[0, 356]], dtype=np.int64),  # would wrap to 100 in int8
        np.array([[0.0, 0.5]]),  # would truncate to 0
        [[1, 0]],
    ],
)
def test_bad_values_rejected(data):
    with pytest.raises(MapError, match="occupancy values"):
        OccupancyGrid(np.asarray(data), 0.1)


@pytest.mark.parametrize("data", [np.zeros(4), np.zeros((0, 3)), np.zeros((2, 2, 2))])
def test_bad_shapes_rejected(data):
    with pytest.raises(MapError, match="2-D"):
        OccupancyGrid(data.astype(np.int8), 0.1)


@pytest.mark.parametrize("res", [0.0, -0.1, math.nan, math.inf])
def test_bad_resolution_rejected(res):
    with pytest.raises(MapError, match="resolution"):
        OccupancyGrid(np.zeros((2, 2), dtype=np.int8), res)


@pytest.mark.parametrize("origin", [(math.nan, 0.0), (0.0, math.inf), (1.0, 2.0, 3.0)])
def test_bad_origin_rejected(origin):
    with pytest.raises(MapError, match="origin"):
        OccupancyGrid(np.zeros((2, 2), dtype=np.int8), 0.1, origin)


def test_from_occupied():
    mask = np.array([[True, False, False], [False, False, True]])
    g = OccupancyGrid.from_occupied(mask, 0.5, origin=(1.0, 2.0))
    np.testing.assert_array_equal(g.data, [[100, 0, 0], [0, 0, 100]])
    assert g.resolution == 0.5
    assert g.origin == (1.0, 2.0)
    # mask row 0 is the row at the origin: (1.25, 2.25) is the centre of cell (0, 0).
    assert g.is_occupied([1.25, 2.25])
    assert not g.is_occupied([1.75, 2.25])
    assert g.is_occupied([2.25, 2.75])  # cell (1, 2)


def test_empty_with_walls():
    g = OccupancyGrid.empty(3.0, 2.0, resolution=0.5, origin=(-1.0, -1.0))
    assert (g.height, g.width) == (4, 6)
    assert g.origin == (-1.0, -1.0)
    border = np.ones((4, 6), dtype=bool)
    border[1:-1, 1:-1] = False
    np.testing.assert_array_equal(g.data[border], OCCUPIED)
    np.testing.assert_array_equal(g.data[~border], FREE)
    assert int(g.free.sum()) == 8


def test_empty_without_walls():
    g = OccupancyGrid.empty(1.0, 0.5, resolution=0.05, walls=False)
    assert (g.height, g.width) == (10, 20)
    assert not g.occupied.any()
    assert g.free.all()


def test_shape_size_bounds():
    g = _grid(np.zeros((30, 40)), resolution=0.1, origin=(-20.0, -20.0))
    assert (g.height, g.width) == (30, 40)
    assert g.size_m == pytest.approx((4.0, 3.0))
    assert g.bounds == pytest.approx((-20.0, -20.0, -16.0, -17.0))


def test_equality():
    a = _grid([[0, 100], [-1, 0]], 0.1, (1.0, 2.0))
    assert a == _grid([[0, 100], [-1, 0]], 0.1, (1.0, 2.0))
    assert a != _grid([[0, 100], [-1, 100]], 0.1, (1.0, 2.0))
    assert a != _grid([[0, 100], [-1, 0]], 0.2, (1.0, 2.0))
    assert a != _grid([[0, 100], [-1, 0]], 0.1, (1.0, 2.5))
    assert a != _grid([[0, 100], [-1, 0]], 0.1, (1.0, 2.0), unknown_is_occupied=True)
    assert a != "map"


# -- transforms -----------------------------------------------------------------------------------
def test_cell_centres_with_arena_origin():
    g = _grid(np.zeros((400, 400)), resolution=0.1, origin=(-20.0, -20.0))
    np.testing.assert_allclose(g.cell_to_world([0, 0]), [-19.95, -19.95])
    # [row, col] = [3, 7]: x from the column, y from the row.
    np.testing.assert_allclose(g.cell_to_world([3, 7]), [-19.25, -19.65])
    np.testing.assert_allclose(g.cell_to_world([399, 399]), [19.95, 19.95])


def test_world_to_cell_floors_and_goes_off_map():
    g = _grid(np.zeros((400, 400)), resolution=0.1, origin=(-20.0, -20.0))
    np.testing.assert_array_equal(g.world_to_cell([-20.0, -20.0]), [0, 0])
    np.testing.assert_array_equal(g.world_to_cell([0.0, 0.0]), [200, 200])
    np.testing.assert_array_equal(g.world_to_cell([-19.25, -19.65]), [3, 7])
    np.testing.assert_array_equal(g.world_to_cell([-20.05, 20.05]), [400, -1])


def test_world_cell_round_trip_every_cell():
    g = _grid(np.zeros((23, 31)), resolution=0.1, origin=(-20.0, -20.0))
    rows, cols = np.mgrid[0 : g.height, 0 : g.width]
    cells = np.stack([rows, cols], axis=-1)
    back = g.world_to_cell(g.cell_to_world(cells))
    np.testing.assert_array_equal(back, cells)
    assert back.shape == (23, 31, 2)


def test_world_round_trip_of_points_stays_in_cell():
    g = _grid(np.zeros((50, 50)), resolution=0.1, origin=(-20.0, -20.0))
    rng = np.random.default_rng(0)
    pts = rng.uniform(-20.0, -15.0, size=(200, 2))
    centres = g.cell_to_world(g.world_to_cell(pts))
    # The centre of the cell holding a point is at most half a cell away per axis.
    assert np.all(np.abs(centres - pts) <= 0.05 + 1e-12)


def test_contains_half_open_bounds():
    g = _grid(np.zeros((3, 4)), resolution=0.5, origin=(-1.0, 2.0))  # x ∈ [-1, 1), y ∈ [2, 3.5)
    pts = [[-1.0, 2.0], [0.999, 3.499], [1.0, 2.5], [0.0, 3.5], [-1.001, 2.5], [0.0, 1.999]]
    np.testing.assert_array_equal(g.contains(pts), [True, True, False, False, False, False])


def test_is_occupied_off_map_and_unknown():
    data = np.array([[0, 100], [-1, 0]], dtype=np.int8)
    g = _grid(data, resolution=1.0, origin=(0.0, 0.0))
    pts = [[0.5, 0.5], [1.5, 0.5], [0.5, 1.5], [1.5, 1.5], [-0.5, 0.5], [0.5, 2.5], [5.0, 5.0]]
    np.testing.assert_array_equal(
        g.is_occupied(pts), [False, True, False, False, True, True, True]
    )
    g2 = _grid(data, resolution=1.0, unknown_is_occupied=True)
    np.testing.assert_array_equal(g2.is_occupied(pts[:4]), [False, True, True, False])


def test_masks():
    g = _grid([[0, 100, -1]])
    np.testing.assert_array_equal(g.occupied, [[False, True, False]])
    np.testing.assert_array_equal(g.free, [[True, False, False]])
    g2 = _grid([[0, 100, -1]], unknown_is_occupied=True)
    np.testing.assert_array_equal(g2.occupied, [[False, True, True]])
    assert not g.occupied.flags.writeable
    assert not g.free.flags.writeable


# -- distance field -------------------------------------------------------------------------------
def test_distance_matches_brute_force():
    rng = np.random.default_rng(42)
    occ = rng.random((15, 12)) < 0.12
    occ[7, 5] = True  # at least one
    res = 0.25
    g = OccupancyGrid.from_occupied(occ, res, origin=(-3.0, 4.0))
    rows, cols = np.nonzero(occ)
    expected = np.empty(occ.shape)
    for r in range(occ.shape[0]):
        for c in range(occ.shape[1]):
            expected[r, c] = np.min(np.hypot(rows - r, cols - c)) * res
    np.testing.assert_allclose(g.distance, expected, rtol=0, atol=1e-12)
    assert np.all(g.distance[occ] == 0.0)
    assert not g.distance.flags.writeable


def test_distance_counts_unknown_only_if_blocking():
    data = np.zeros((1, 5), dtype=np.int8)
    data[0, 0] = UNKNOWN
    data[0, 4] = OCCUPIED
    np.testing.assert_allclose(_grid(data, 0.5).distance, [[2.0, 1.5, 1.0, 0.5, 0.0]])
    np.testing.assert_allclose(
        _grid(data, 0.5, unknown_is_occupied=True).distance, [[0.0, 0.5, 1.0, 0.5, 0.0]]
    )


def test_distance_without_obstacles_is_inf():
    g = _grid(np.zeros((3, 3)))
    assert np.all(np.isinf(g.distance))


def test_distance_at():
    g = OccupancyGrid.from_occupied([[True, False, False, False]], 0.5, origin=(0.0, 0.0))
    np.testing.assert_allclose(
        g.distance_at([[0.1, 0.1], [1.3, 0.2], [1.9, 0.4], [-0.1, 0.1], [0.1, 0.6]]),
        [0.0, 1.0, 1.5, 0.0, 0.0],  # last two off the map → 0
    )


# -- inflation ------------------------------------------------------------------------------------
def test_inflate_single_cell_gives_disk():
    occ = np.zeros((11, 11), dtype=bool)
    occ[5, 5] = True
    g = OccupancyGrid.from_occupied(occ, 0.1, origin=(-20.0, -20.0))
    grown = g.inflate(0.2)  # 2 cells
    # Cells with dr² + dc² ≤ 4: the centre, 4 at distance 1, 4 at √2, 4 at 2 → 13 cells.
    expected = np.zeros((11, 11), dtype=bool)
    for dr in range(-2, 3):
        for dc in range(-2, 3):
            if dr * dr + dc * dc <= 4:
                expected[5 + dr, 5 + dc] = True
    assert expected.sum() == 13
    np.testing.assert_array_equal(grown.occupied, expected)
    assert not grown.occupied[5 + 2, 5 + 1]  # √5 > 2
    assert grown.resolution == g.resolution
    assert grown.origin == g.origin
    assert g.occupied.sum() == 1  # the original is untouched


def test_inflate_zero_is_identity_and_keeps_unknown():
    data = np.zeros((5, 5), dtype=np.int8)
    data[0, 0] = OCCUPIED
    data[4, 4] = UNKNOWN
    data[0, 1] = UNKNOWN
    g = _grid(data)
    assert g.inflate(0.0) == g
    grown = g.inflate(1.0)
    assert grown.data[4, 4] == UNKNOWN  # far away: stays unknown
    assert grown.data[0, 1] == OCCUPIED  # inflated over
    assert grown.data[1, 1] == FREE  # √2 > 1


@pytest.mark.parametrize("radius", [-0.1, math.nan])
def test_inflate_rejects_bad_radius(radius):
    with pytest.raises(MapError, match="radius"):
        _grid(np.zeros((2, 2))).inflate(radius)


def test_with_occupied():
    g = _grid([[0, -1], [0, 0]])
    out = g.with_occupied([[False, True], [True, False]])
    np.testing.assert_array_equal(out.data, [[0, 100], [100, 0]])
    with pytest.raises(MapError, match="shape"):
        g.with_occupied(np.zeros((3, 3), dtype=bool))
