"""Arena's rosmap generators: outdoor, canteen, warehouse, office (arena.maps.generators.rosmap)."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from scipy import ndimage

from arena.core.geometry import point_segment_distance, polygon_edges, polygons_overlap
from arena.core.types import Pose2D
from arena.maps.generators.base import MAP_GENERATORS
from arena.maps.generators.rosmap import CanteenMap, OfficeMap, OutdoorMap, WarehouseMap
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import polygon_mask
from arena.nav.global_planners.astar import AStarPlanner

GENERATORS = {
    "outdoor": OutdoorMap,
    "canteen": CanteenMap,
    "warehouse": WarehouseMap,
    "office": OfficeMap,
}


def _build(cls, seed: int, **params):
    return cls(cls.Params(**params)).build(np.random.default_rng(seed))


def _signature(result) -> list[tuple]:
    return [(o.name, o.model, tuple(np.round(o.pose, 12))) for o in result.obstacles]


# -- registry and the room -----------------------------------------------------------------------
@pytest.mark.parametrize("name", list(GENERATORS))
def test_registered_with_rosmap_tag(name):
    assert MAP_GENERATORS.get(name) is GENERATORS[name]


@pytest.mark.parametrize("cls", GENERATORS.values())
def test_grid_is_the_walled_room(cls):
    r = _build(cls, 0)
    assert r.grid == OccupancyGrid.empty(20.0, 20.0, 0.05)
    assert len(r.obstacles) > 0


# -- determinism ---------------------------------------------------------------------------------
@pytest.mark.parametrize("cls", GENERATORS.values())
def test_same_seed_same_map(cls):
    a, b = _build(cls, 7), _build(cls, 7)
    assert a.grid == b.grid
    assert _signature(a) == _signature(b)


@pytest.mark.parametrize("cls", GENERATORS.values())
def test_different_seeds_differ(cls):
    sigs = {tuple(_signature(_build(cls, s))) for s in range(5)}
    assert len(sigs) > 1


# -- geometry: no overlaps, inside the room --------------------------------------------------------
def _min_distance(p, q) -> float:
    if polygons_overlap(p, q):
        return 0.0
    pa, pb = polygon_edges(p)
    qa, qb = polygon_edges(q)
    return float(
        min(point_segment_distance(p, qa, qb).min(), point_segment_distance(q, pa, pb).min())
    )


@pytest.mark.parametrize("cls", GENERATORS.values())
@pytest.mark.parametrize("seed", range(5))
def test_footprints_disjoint_and_inside(cls, seed):
    r = _build(cls, seed)
    # Interiors must be disjoint; the bays of one warehouse rack share an edge, so test footprints
    # shrunk by 1 mm towards their centre.
    polys = [o.polygon for o in r.obstacles]
    polys = [c + (p - c) * 0.999 for p in polys for c in [p.mean(axis=0)]]
    names = [o.name for o in r.obstacles]
    assert len(set(names)) == len(names)
    for i in range(len(polys)):
        assert polys[i].min() > 0.05 and polys[i][:, 0].max() < 19.95
        assert polys[i][:, 1].max() < 19.95
        for j in range(i + 1, len(polys)):
            assert not polygons_overlap(polys[i], polys[j]), (names[i], names[j])


def test_outdoor_trees_keep_the_robot_gap():
    p = OutdoorMap.Params(obstacle_extra_radius=0, obstacle_num=60)
    r = OutdoorMap(p).build(np.random.default_rng(3))
    polys = [o.polygon for o in r.obstacles]
    gaps = [_min_distance(a, b) for i, a in enumerate(polys) for b in polys[i + 1 :]]
    assert min(gaps) >= p.gap - 1e-9


# -- parameter effects -----------------------------------------------------------------------------
def test_outdoor_obstacle_num():
    few = [len(_build(OutdoorMap, s, obstacle_num=2).obstacles) for s in range(5)]
    many = [len(_build(OutdoorMap, s, obstacle_num=15).obstacles) for s in range(5)]
    assert all(n <= 2 for n in few) and sum(many) > sum(few)
    assert {o.model for o in _build(OutdoorMap, 0).obstacles} == {"tree"}


def test_outdoor_extra_radius_spacing():
    r = _build(OutdoorMap, 1, obstacle_extra_radius=5)
    xy = np.array([o.pose[:2] for o in r.obstacles])
    cheb = np.abs(xy[:, None] - xy[None]).max(axis=2) + np.eye(len(xy)) * 1e9
    assert cheb.min() >= 11 * 0.5 - 1e-9  # (2r + 1) cells of 0.5 m
    assert len(_build(OutdoorMap, 1, obstacle_extra_radius=1).obstacles) == 15


def test_canteen_obstacle_num():
    few = sum(
        Counter(o.model for o in _build(CanteenMap, s, obstacle_num=3).obstacles)["table"]
        for s in range(3)
    )
    many = sum(Counter(o.model for o in _build(CanteenMap, s).obstacles)["table"] for s in range(3))
    assert few == 9 and many > few


def test_canteen_chair_chance():
    none = Counter(o.model for o in _build(CanteenMap, 2, chair_chance=0.0).obstacles)
    assert none["chair"] == 0 and none["table"] > 0
    full = _build(CanteenMap, 2, chair_chance=1.0)
    c = Counter(o.model for o in full.obstacles)
    assert c["chair"] == 4 * c["table"]
    # Chairs sit just outside their table and face it.
    tables = np.array([o.pose for o in full.obstacles if o.model == "table"])
    for ch in (o for o in full.obstacles if o.model == "chair"):
        d = np.hypot(*(tables[:, :2] - ch.pose[:2]).T)
        k = int(np.argmin(d))
        assert d[k] == pytest.approx(0.45 + 0.225 + 0.05)
        to_table = np.arctan2(*(tables[k, 1::-1] - ch.pose[1::-1]))
        assert np.cos(to_table - ch.pose[2]) == pytest.approx(1.0)
    yaws = tables[:, 2]
    assert np.all((yaws >= 0) & (yaws < np.pi))


def test_warehouse_pallet_jacks_and_shelves():
    for n in (0, 3, 5):
        for s in range(3):
            # Without racks the hall always has room for every jack; with racks, never more.
            c = Counter(
                o.model for o in _build(WarehouseMap, s, pallet_jacks=n, rack_chance=0.0).obstacles
            )
            jacks = sum(v for k, v in c.items() if k.startswith("pallet_jack"))
            assert jacks == n
            full = Counter(o.model for o in _build(WarehouseMap, s, pallet_jacks=n).obstacles)
            assert sum(v for k, v in full.items() if k.startswith("pallet_jack")) <= n
    shelves = [
        Counter(o.model for o in _build(WarehouseMap, s).obstacles)["warehouse_shelf"]
        for s in range(10)
    ]
    assert all(n % 2 == 0 for n in shelves) and min(shelves) >= 6  # a real hall of racks
    sparse = [
        Counter(o.model for o in _build(WarehouseMap, s, layout="arena").obstacles)[
            "warehouse_shelf"
        ]
        for s in range(10)
    ]
    assert sum(sparse) < sum(shelves)  # Arena's PR #118 layout, kept as an option, is sparser
    r = _build(WarehouseMap, 0)
    yaws = {round(float(o.pose[2]) % np.pi, 9) for o in r.obstacles if o.model == "warehouse_shelf"}
    assert yaws <= {0.0, round(np.pi / 2, 9)}


def test_office_rows():
    assert len(_build(OfficeMap, 0, row_chance=0.0).obstacles) == 0
    for s in range(5):
        c = Counter(o.model for o in _build(OfficeMap, s, row_chance=1.0).obstacles)
        assert c["office_desk"] == 2 * c["separator"] == c["office_chair"] > 0
    full = sum(len(_build(OfficeMap, s, row_chance=1.0).obstacles) for s in range(10))
    some = sum(len(_build(OfficeMap, s, row_chance=0.5).obstacles) for s in range(10))
    assert full > some


def test_office_workplace_layout():
    r = _build(OfficeMap, 1, row_chance=1.0)
    seps = [o for o in r.obstacles if o.model == "separator"]
    desks = np.array([o.pose for o in r.obstacles if o.model == "office_desk"])
    chairs = np.array([o.pose for o in r.obstacles if o.model == "office_chair"])
    for s in seps:
        dx = (np.abs(desks[:, 0] - s.pose[0]) < 1e-9) & (np.abs(desks[:, 1] - s.pose[1]) < 2)
        assert sorted(np.round(desks[dx, 1] - s.pose[1], 9)) == [-0.5, 0.5]
        cx = (np.abs(chairs[:, 0] - s.pose[0]) < 1e-9) & (np.abs(chairs[:, 1] - s.pose[1]) < 2)
        assert sorted(np.round(chairs[cx, 1] - s.pose[1], 9)) == [-1.25, 1.25]


# -- navigability ----------------------------------------------------------------------------------
def _path_exists(result, robot_radius: float) -> None:
    grid = result.grid
    mask = polygon_mask(grid, [o.polygon for o in result.obstacles])
    inflated = grid.with_occupied(mask).inflate(robot_radius)
    free = ~inflated.occupied
    labels, n = ndimage.label(free)
    assert n >= 1
    sizes = np.bincount(labels.ravel())[1:]
    big = labels == (1 + int(np.argmax(sizes)))
    # The largest free region is (nearly) all of the free space: nothing big is cut off.
    assert big.sum() >= 0.95 * free.sum()
    rows, cols = np.nonzero(big)
    # Deterministic far-apart endpoints: the region cells nearest two opposite corners.
    a = int(np.argmin(rows + cols))
    b = int(np.argmax(rows + cols))
    start = Pose2D(*grid.cell_to_world([rows[a], cols[a]]), 0.0)
    goal = Pose2D(*grid.cell_to_world([rows[b], cols[b]]), 0.0)
    assert np.hypot(goal.x - start.x, goal.y - start.y) > 20.0
    path = AStarPlanner(AStarPlanner.Params(smooth=False, clearance_weight=0.0)).plan(
        inflated, start, goal
    )
    assert len(path) >= 2


@pytest.mark.parametrize("cls", GENERATORS.values())
@pytest.mark.parametrize("seed", range(20))
def test_navigable(cls, seed):
    _path_exists(_build(cls, seed), 0.3)


@pytest.mark.slow
@pytest.mark.parametrize("cls", GENERATORS.values())
def test_navigable_100_seeds(cls):
    for seed in range(100):
        _path_exists(_build(cls, seed), 0.3)


@pytest.mark.parametrize("cls", GENERATORS.values())
def test_navigable_for_a_bigger_robot(cls):
    for seed in range(5):
        _path_exists(_build(cls, seed, robot_radius=0.5), 0.5)


def test_dense_canteen_still_navigable():
    # Far more tables than fit: the rejections keep the aisles open.
    for seed in range(5):
        _path_exists(_build(CanteenMap, seed, obstacle_num=60, chair_chance=1.0), 0.3)
