"""Tests of the barn and rosnav map generators (Arena-Rosnav's ``barn`` and ``rosnav``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError
from scipy import ndimage

from arena.core.errors import MapError
from arena.core.types import Pose2D
from arena.maps.generators.barn import BarnGenerator, barn_automaton, barn_connected
from arena.maps.generators.base import MAP_GENERATORS
from arena.maps.generators.rosnav import RosnavIndoorGenerator, RosnavOutdoorGenerator
from arena.maps.grid import OccupancyGrid
from arena.maps.sources import MAP_SOURCES
from arena.nav.global_planners.astar import AStarPlanner

GENERATORS = {
    "barn": BarnGenerator,
    "rosnav_indoor": RosnavIndoorGenerator,
    "rosnav_outdoor": RosnavOutdoorGenerator,
}
ROBOT_RADIUS = 0.3  # m
CROSS = ndimage.generate_binary_structure(2, 1)


def build(name: str, seed: int, **params) -> OccupancyGrid:
    cls = GENERATORS[name]
    return cls(cls.Params(**params)).build(np.random.default_rng(seed)).grid


def cell_pose(grid: OccupancyGrid, cell) -> Pose2D:
    x, y = grid.cell_to_world(np.asarray(cell))
    return Pose2D(float(x), float(y))


def assert_barn_crossable(grid: OccupancyGrid, cell_size: float = 0.5) -> None:
    """Plan from the left side to the right side of a barn map for ROBOT_RADIUS.

    BARN's crossing goes from just inside the left side wall to just inside the right one: the
    start column is the first fine column where a robot fits beside the one-cell side wall.
    """
    inflated = grid.inflate(ROBOT_RADIUS)
    wall = round(cell_size / grid.resolution)
    col_s = wall + math.ceil(ROBOT_RADIUS / grid.resolution) + 1
    col_g = grid.width - 1 - col_s
    # A* without corner cutting connects exactly the 4-connected free cells.
    labels, _ = ndimage.label(inflated.free, structure=CROSS)
    common = np.intersect1d(labels[:, col_s], labels[:, col_g])
    common = common[common > 0]
    assert common.size, "no free region touches both the left and the right side"
    rows_s = np.flatnonzero(labels[:, col_s] == common[0])
    rows_g = np.flatnonzero(labels[:, col_g] == common[0])
    start = cell_pose(grid, (rows_s[len(rows_s) // 2], col_s))
    goal = cell_pose(grid, (rows_g[len(rows_g) // 2], col_g))
    path = AStarPlanner().plan(inflated, start, goal)
    assert path[0][0] < 1.0 and path[-1][0] > grid.size_m[0] - 1.0


def assert_rosnav_crossable(grid: OccupancyGrid) -> None:
    """Plan between two far-apart free cells of the largest free component after inflation.

    Start and goal are the component's cells with the smallest and the largest ``row + col``.
    """
    inflated = grid.inflate(ROBOT_RADIUS)
    labels, n = ndimage.label(inflated.free, structure=CROSS)
    assert n > 0
    biggest = np.argmax(np.bincount(labels.ravel())[1:]) + 1
    cells = np.argwhere(labels == biggest)
    s = cells.sum(axis=1)
    start, goal = cells[np.argmin(s)], cells[np.argmax(s)]
    assert np.abs(goal - start).sum() * grid.resolution > 5.0  # far apart (m, L1)
    path = AStarPlanner().plan(inflated, cell_pose(grid, start), cell_pose(grid, goal))
    assert len(path) >= 2


def check_paths(name: str, seeds) -> None:
    for seed in seeds:
        grid = build(name, seed)
        if name == "barn":
            assert_barn_crossable(grid)
        else:
            assert_rosnav_crossable(grid)


# -- registry and output format -------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_registered(name: str) -> None:
    assert name in MAP_GENERATORS and name in MAP_SOURCES
    source = MAP_SOURCES.build({"type": name, "width": 10.0, "height": 12.0})
    assert source.build(np.random.default_rng(0)).grid.data.shape == (240, 200)


@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_shape_resolution_origin_and_borders(name: str) -> None:
    for seed in range(5):
        grid = build(name, seed, width=20.0, height=15.0)
        assert grid.data.shape == (300, 400)  # (height / resolution, width / resolution)
        assert grid.resolution == 0.05 and grid.origin == (0.0, 0.0)
        occ = grid.occupied
        assert occ[0].all() and occ[-1].all() and occ[:, 0].all() and occ[:, -1].all()


def test_coarse_cells_are_repeated() -> None:
    grid = build("rosnav_outdoor", 3, width=10.0, height=10.0, cell_size=0.5, resolution=0.1)
    blocks = grid.occupied.reshape(20, 5, 20, 5)
    # Every 5 × 5 block of output cells is one generator cell: all equal.
    assert (blocks.all(axis=(1, 3)) == blocks.any(axis=(1, 3))).all()


@pytest.mark.parametrize(
    "bad",
    [
        {"resolution": 0.3},  # cell_size 0.5 not a whole multiple
        {"width": 30.2},  # not a whole number of cells
        {"height": 0.0},
    ],
)
def test_invalid_sizes_rejected(bad) -> None:
    for cls in GENERATORS.values():
        with pytest.raises(ValidationError):
            cls.Params(**bad)


def test_rosnav_too_small_rejected() -> None:
    with pytest.raises(ValidationError, match="corridor_radius"):
        RosnavIndoorGenerator.Params(width=5.0, height=5.0, corridor_radius=4)


# -- determinism ----------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_deterministic(name: str) -> None:
    assert build(name, 7) == build(name, 7)
    assert build(name, 7) != build(name, 8)


# -- parameter effects ----------------------------------------------------------------------------
def occupied_fraction(name: str, seeds=range(10), **params) -> float:
    return float(np.mean([build(name, s, **params).occupied.mean() for s in seeds]))


def test_barn_fill_pct_raises_occupancy() -> None:
    low = occupied_fraction("barn", fill_pct=0.1)
    high = occupied_fraction("barn", fill_pct=0.3)
    assert high > low + 0.02


def test_indoor_iterations_free_more() -> None:
    few = occupied_fraction("rosnav_indoor", iterations=5)
    many = occupied_fraction("rosnav_indoor", iterations=50)
    assert many < few - 0.05


def test_outdoor_obstacle_num_raises_occupancy() -> None:
    few = occupied_fraction("rosnav_outdoor", obstacle_num=5)
    many = occupied_fraction("rosnav_outdoor", obstacle_num=40)
    assert many > few + 0.02


# -- algorithm details ----------------------------------------------------------------------------
def test_barn_automaton_rules() -> None:
    # fill 0: only the top/bottom rows; smoothing keeps them (≥ 3 filled neighbours beyond them).
    g = barn_automaton(np.random.default_rng(0), 10, 8, 0.0, 5)
    assert g[0].all() and g[-1].all() and not g[1:-1].any()
    # fill 1: everything stays filled.
    assert barn_automaton(np.random.default_rng(0), 10, 8, 1.0, 5).all()


def test_barn_connectivity_check() -> None:
    grid = np.zeros((9, 12), dtype=bool)
    grid[0] = grid[-1] = True
    assert barn_connected(grid, 2)
    wall = grid.copy()
    wall[:, 6] = True  # a full vertical wall splits left from right
    assert not barn_connected(wall, 1)
    gap = wall.copy()
    gap[4, 6] = False  # a one-cell gap: enough for a point robot, not for an inflated one
    assert barn_connected(gap, 1)
    assert not barn_connected(gap, 2)


def test_barn_gives_up_with_clear_error() -> None:
    gen = BarnGenerator(BarnGenerator.Params(fill_pct=0.6, robot_radius=1.0, max_tries=3))
    with pytest.raises(MapError, match="max_tries"):
        gen.build(np.random.default_rng(0))


def test_indoor_corridors_are_wide_enough() -> None:
    # Every free cell lies in a free (2r + 1)² block of generator cells: corridors are 2r + 1 wide.
    r = 4
    for seed in range(5):
        occ = build("rosnav_indoor", seed, resolution=0.5).occupied
        free = ~occ
        core = ndimage.binary_erosion(free, np.ones((2 * r + 1, 2 * r + 1), bool))
        covered = ndimage.binary_dilation(core, np.ones((2 * r + 1, 2 * r + 1), bool))
        assert (covered == free).all()
        _, n = ndimage.label(free, structure=CROSS)
        assert n == 1  # a tree of corridors is one connected region


def test_outdoor_obstacles_are_squares_inside_the_border() -> None:
    occ = build("rosnav_outdoor", 0, resolution=0.5, obstacle_num=1).occupied
    inner = occ[1:-1, 1:-1]
    assert inner.sum() == 9
    rows, cols = np.nonzero(inner)
    assert np.ptp(rows) == 2 and np.ptp(cols) == 2


# -- navigability ---------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(GENERATORS))
def test_path_exists_100_seeds(name: str) -> None:
    # About 4 s per generator at the default 30 × 30 m size (600 × 600 cells).
    check_paths(name, range(100))
