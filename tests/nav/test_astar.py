"""A* planner: optimality against an independent Dijkstra, free paths, smoothing, typed failures."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from arena.core.errors import ConfigError, GoalOccupied, NoPathFound, StartOccupied
from arena.core.geometry import polyline_length
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.global_planners import GLOBAL_PLANNERS, AStarPlanner

RES = 0.1


def _planner(**kw: object) -> AStarPlanner:
    return GLOBAL_PLANNERS.build({"type": "astar", **kw})


def _centre(grid: OccupancyGrid, cell: tuple[int, int]) -> Pose2D:
    x, y = grid.cell_to_world(np.array(cell))
    return Pose2D(float(x), float(y))


def _graph(occ: np.ndarray, res: float, penalty: np.ndarray | None = None) -> coo_matrix:
    """8-connected grid graph without corner cutting, built independently of the planner."""
    h, w = occ.shape
    rows, cols, costs = [], [], []
    for r in range(h):
        for c in range(w):
            if occ[r, c]:
                continue
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    if dr == dc == 0:
                        continue
                    rr, cc = r + dr, c + dc
                    if not (0 <= rr < h and 0 <= cc < w) or occ[rr, cc]:
                        continue
                    if dr and dc and (occ[r, cc] or occ[rr, c]):
                        continue
                    step = res * math.hypot(dr, dc)
                    if penalty is not None:
                        step *= 1.0 + 0.5 * (penalty[r, c] + penalty[rr, cc])
                    rows.append(r * w + c)
                    cols.append(rr * w + cc)
                    costs.append(step)
    return coo_matrix((costs, (rows, cols)), shape=(h * w, h * w)).tocsr()


def _random_grid(seed: int, shape: tuple[int, int] = (24, 31), density: float = 0.3):
    rng = np.random.default_rng(seed)
    occ = rng.random(shape) < density
    free = np.argwhere(~occ)
    s, g = free[rng.choice(len(free), size=2, replace=False)]
    return occ, (int(s[0]), int(s[1])), (int(g[0]), int(g[1]))


def _cells_of(grid: OccupancyGrid, path: np.ndarray) -> np.ndarray:
    return grid.world_to_cell(path)


@pytest.mark.parametrize("seed", range(14))
def test_cost_equals_dijkstra(seed: int) -> None:
    occ, s, g = _random_grid(seed)
    grid = OccupancyGrid.from_occupied(occ, RES, origin=(-1.0, 2.0))
    dist = dijkstra(_graph(occ, RES), indices=s[0] * occ.shape[1] + s[1])
    best = dist[g[0] * occ.shape[1] + g[1]]
    planner = _planner(clearance_weight=0.0, smooth=False)
    if not np.isfinite(best):
        with pytest.raises(NoPathFound):
            planner.plan(grid, _centre(grid, s), _centre(grid, g))
        return
    path = planner.plan(grid, _centre(grid, s), _centre(grid, g))
    assert polyline_length(path) == pytest.approx(best, rel=1e-9, abs=1e-9)
    cells = _cells_of(grid, path)
    assert not occ[cells[:, 0], cells[:, 1]].any()
    steps = np.abs(np.diff(cells, axis=0))
    assert steps.max() <= 1  # 8-neighbours only
    for (r0, c0), (r1, c1) in itertools.pairwise(cells):
        if r0 != r1 and c0 != c1:  # diagonal: no corner cutting
            assert not occ[r0, c1] and not occ[r1, c0]


@pytest.mark.parametrize("seed", range(10))
def test_clearance_cost_equals_dijkstra_with_same_costs(seed: int) -> None:
    occ, s, g = _random_grid(100 + seed, density=0.2)
    grid = OccupancyGrid.from_occupied(occ, RES)
    weight, scale = 2.0, 0.25
    penalty = weight * np.exp(-grid.distance / scale)
    dist = dijkstra(_graph(occ, RES, penalty), indices=s[0] * occ.shape[1] + s[1])
    best = dist[g[0] * occ.shape[1] + g[1]]
    if not np.isfinite(best):
        return
    path = _planner(clearance_weight=weight, clearance_scale=scale, smooth=False).plan(
        grid, _centre(grid, s), _centre(grid, g)
    )
    cells = _cells_of(grid, path)
    cost = 0.0
    for a, b in itertools.pairwise(cells):
        step = RES * math.hypot(*(b - a))
        cost += step * (1 + 0.5 * (penalty[tuple(a)] + penalty[tuple(b)]))
    assert cost == pytest.approx(best, rel=1e-9)


def test_clearance_keeps_path_off_walls() -> None:
    # A 4 m wide room with a pillar: the clearance cost should route through the middle.
    occ = np.zeros((40, 80), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    start, goal = Pose2D(0.5, 0.5), Pose2D(7.5, 0.5)
    plain = _planner(clearance_weight=0.0, smooth=False).plan(grid, start, goal)
    kept = _planner(clearance_weight=3.0, clearance_scale=0.5, smooth=False).plan(grid, start, goal)
    assert np.median(grid.distance_at(kept)) > np.median(grid.distance_at(plain))


def test_weighted_heuristic_is_bounded_suboptimal() -> None:
    occ, s, g = _random_grid(1, shape=(40, 40), density=0.25)  # a connected sample
    grid = OccupancyGrid.from_occupied(occ, RES)
    opt = polyline_length(_planner(clearance_weight=0, smooth=False).plan(
        grid, _centre(grid, s), _centre(grid, g)))
    w = 1.8
    sub = polyline_length(_planner(clearance_weight=0, smooth=False, heuristic_weight=w).plan(
        grid, _centre(grid, s), _centre(grid, g)))
    assert opt - 1e-9 <= sub <= w * opt + 1e-9


def test_four_connected_moves_only_orthogonally() -> None:
    grid = OccupancyGrid.empty(3.0, 3.0, RES)
    path = _planner(diagonal=False, smooth=False, clearance_weight=0).plan(
        grid, _centre(grid, (2, 2)), _centre(grid, (20, 25))
    )
    steps = np.abs(np.diff(grid.world_to_cell(path), axis=0)).sum(axis=1)
    assert np.all(steps == 1)
    assert polyline_length(path) == pytest.approx(RES * (18 + 23))


def _segment_cells(grid: OccupancyGrid, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    n = max(2, int(np.ceil(np.linalg.norm(b - a) / grid.resolution * 100)))
    pts = a + np.linspace(0, 1, n)[:, None] * (b - a)
    return grid.world_to_cell(pts)


@pytest.mark.parametrize("seed", range(12))
def test_smoothing_never_crosses_occupied_cells(seed: int) -> None:
    occ, s, g = _random_grid(200 + seed, shape=(40, 50), density=0.22)
    grid = OccupancyGrid.from_occupied(occ, RES, origin=(0.3, -0.7))
    rng = np.random.default_rng(seed)
    # Start and goal anywhere inside their cells, not only at the centres.
    start = _centre(grid, s)
    goal = _centre(grid, g)
    start = Pose2D(start.x + rng.uniform(-0.049, 0.049), start.y + rng.uniform(-0.049, 0.049))
    goal = Pose2D(goal.x + rng.uniform(-0.049, 0.049), goal.y + rng.uniform(-0.049, 0.049))
    try:
        raw = _planner(smooth=False).plan(grid, start, goal)
    except NoPathFound:
        return
    smooth = _planner(smooth=True).plan(grid, start, goal)
    assert len(smooth) <= len(raw)
    assert polyline_length(smooth) <= polyline_length(raw) + 1e-9
    np.testing.assert_allclose(smooth[0], start.xy)
    np.testing.assert_allclose(smooth[-1], goal.xy)
    for a, b in itertools.pairwise(smooth):
        cells = _segment_cells(grid, a, b)
        assert grid.in_bounds(cells).all()
        assert not occ[cells[:, 0], cells[:, 1]].any()


def test_smoothing_straightens_an_open_room() -> None:
    grid = OccupancyGrid.empty(6.0, 4.0, RES)
    path = _planner().plan(grid, Pose2D(0.5, 0.5), Pose2D(5.5, 3.2))
    assert len(path) == 2


def test_endpoints_are_exact_and_same_cell_gives_two_points() -> None:
    grid = OccupancyGrid.empty(2.0, 2.0, RES)
    start, goal = Pose2D(0.52, 0.53, 1.0), Pose2D(1.37, 1.21, -2.0)
    path = _planner(smooth=False).plan(grid, start, goal)
    np.testing.assert_allclose(path[0], start.xy)
    np.testing.assert_allclose(path[-1], goal.xy)
    same = _planner().plan(grid, Pose2D(0.51, 0.51), Pose2D(0.55, 0.58))
    assert same.shape == (2, 2)


def test_start_occupied() -> None:
    occ = np.zeros((20, 20), dtype=bool)
    occ[5, 5] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    with pytest.raises(StartOccupied, match=r"0\.550, 0\.550"):
        _planner().plan(grid, Pose2D(0.55, 0.55), Pose2D(1.5, 1.5))
    with pytest.raises(StartOccupied, match="off the map"):
        _planner().plan(grid, Pose2D(-0.5, 0.5), Pose2D(1.5, 1.5))


def test_start_occupied_by_inflation_only() -> None:
    occ = np.zeros((30, 30), dtype=bool)
    occ[10, 10] = True
    grid = OccupancyGrid.from_occupied(occ, RES).inflate(0.3)
    near = Pose2D(1.25, 1.05)  # free in the raw map, inside the inflated disc
    with pytest.raises(StartOccupied):
        _planner().plan(grid, near, Pose2D(2.5, 2.5))


def test_goal_occupied() -> None:
    occ = np.zeros((20, 20), dtype=bool)
    occ[15, 12] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    with pytest.raises(GoalOccupied, match=r"1\.250, 1\.550"):
        _planner().plan(grid, Pose2D(0.5, 0.5), Pose2D(1.25, 1.55))
    with pytest.raises(GoalOccupied, match="off the map"):
        _planner().plan(grid, Pose2D(0.5, 0.5), Pose2D(0.5, 5.0))


def test_enclosed_goal_is_no_path() -> None:
    occ = np.zeros((30, 30), dtype=bool)
    occ[18:25, 18] = occ[18:25, 24] = occ[18, 18:25] = occ[24, 18:25] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    with pytest.raises(NoPathFound, match=r"2\.150, 2\.150"):
        _planner().plan(grid, Pose2D(0.5, 0.5), Pose2D(2.15, 2.15))


def test_diagonal_gap_is_not_a_passage() -> None:
    # Two walls that touch only at a corner: 8-connected search must not slip through.
    occ = np.zeros((20, 20), dtype=bool)
    occ[:10, 10] = True
    occ[10, :10] = True
    occ[10:, 11] = True
    occ[9, 11:] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    with pytest.raises(NoPathFound):
        _planner().plan(grid, Pose2D(0.25, 0.25), Pose2D(1.85, 1.85))


def test_params_are_validated() -> None:
    with pytest.raises(ConfigError, match="heuristic_weight"):
        _planner(heuristic_weight=0.5)
    with pytest.raises(ConfigError, match="unknown key"):
        _planner(heuristc_weight=2.0)


def test_plan_is_deterministic_and_leaves_grid_untouched() -> None:
    occ, s, g = _random_grid(7, shape=(60, 60), density=0.2)
    grid = OccupancyGrid.from_occupied(occ, RES)
    before = grid.data.copy()
    a = _planner().plan(grid, _centre(grid, s), _centre(grid, g))  # a connected sample
    b = _planner().plan(grid, _centre(grid, s), _centre(grid, g))
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(grid.data, before)


@pytest.mark.slow
def test_large_grid_plans_corner_to_corner() -> None:
    # (ms per plan on this map is a figure of benchmarks/planners_global.py, not a test)
    rng = np.random.default_rng(0)
    occ = rng.random((1000, 1000)) < 0.2
    occ[:5, :5] = occ[-5:, -5:] = False
    grid = OccupancyGrid.from_occupied(occ, 0.05)
    planner = _planner()
    start, goal = Pose2D(0.1, 0.1), Pose2D(49.9, 49.9)
    path = planner.plan(grid, start, goal)
    np.testing.assert_allclose(path[0], start.xy)
    np.testing.assert_allclose(path[-1], goal.xy)
    cells = grid.world_to_cell(path)
    assert (grid.data[cells[:, 0], cells[:, 1]] == 0).all()  # waypoints on free cells
