"""Dijkstra and Theta* global planners: optimality, any-angle length, free paths, failures."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from arena.core.errors import GoalOccupied, NoPathFound, StartOccupied
from arena.core.geometry import polyline_length
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.costmap import INSCRIBED, LETHAL, Costmap
from arena.nav.global_planners import (
    GLOBAL_PLANNERS,
    DijkstraPlanner,
    ThetaStarPlanner,
    plan_on_costmap,
    segment_is_free,
)

RES = 0.1


def _centre(grid: OccupancyGrid, cell: tuple[int, int]) -> Pose2D:
    x, y = grid.cell_to_world(np.array(cell))
    return Pose2D(float(x), float(y))


def _graph(occ: np.ndarray, res: float, penalty: np.ndarray | None = None) -> coo_matrix:
    """8-connected grid graph without corner cutting, built with vectorised shifts.

    Edge cost ``ℓ · (1 + (p(u) + p(v)) / 2)`` with an optional per-cell ``penalty``.
    """
    h, w = occ.shape
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, costs = [], [], []
    for dr, dc in itertools.product((-1, 0, 1), repeat=2):
        if dr == dc == 0:
            continue
        r0, r1 = max(0, -dr), h - max(0, dr)
        c0, c1 = max(0, -dc), w - max(0, dc)
        a = (slice(r0, r1), slice(c0, c1))
        b = (slice(r0 + dr, r1 + dr), slice(c0 + dc, c1 + dc))
        ok = ~occ[a] & ~occ[b]
        if dr and dc:
            ok &= ~occ[r0:r1, c0 + dc : c1 + dc] & ~occ[r0 + dr : r1 + dr, c0:c1]
        rows.append(idx[a][ok])
        cols.append(idx[b][ok])
        step = np.full(int(ok.sum()), res * math.hypot(dr, dc))
        if penalty is not None:
            step = step * (1 + 0.5 * (penalty[a][ok] + penalty[b][ok]))
        costs.append(step)
    return coo_matrix(
        (np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))), shape=(h * w, h * w)
    ).tocsr()


def _random_grid(seed: int, shape: tuple[int, int] = (24, 31), density: float = 0.3):
    rng = np.random.default_rng(seed)
    occ = rng.random(shape) < density
    free = np.argwhere(~occ)
    s, g = free[rng.choice(len(free), size=2, replace=False)]
    return occ, (int(s[0]), int(s[1])), (int(g[0]), int(g[1]))


def _exact(name: str):
    if name == "theta_star":
        return GLOBAL_PLANNERS.build({"type": name})
    return GLOBAL_PLANNERS.build({"type": name, "clearance_weight": 0.0, "smooth": False})


def test_registry_has_the_three_planners() -> None:
    assert {"astar", "dijkstra", "theta_star"} <= set(GLOBAL_PLANNERS.names())
    assert isinstance(GLOBAL_PLANNERS.build({"type": "dijkstra"}), DijkstraPlanner)
    assert isinstance(GLOBAL_PLANNERS.build({"type": "theta_star"}), ThetaStarPlanner)


@pytest.mark.parametrize("seed", range(30))
def test_astar_and_dijkstra_equal_brute_force(seed: int) -> None:
    occ, s, g = _random_grid(1000 + seed, density=0.25)
    grid = OccupancyGrid.from_occupied(occ, RES, origin=(0.4, -1.3))
    dist = dijkstra(_graph(occ, RES), indices=s[0] * occ.shape[1] + s[1])
    best = dist[g[0] * occ.shape[1] + g[1]]
    for name in ("astar", "dijkstra"):
        planner = _exact(name)
        if not np.isfinite(best):
            with pytest.raises(NoPathFound):
                planner.plan(grid, _centre(grid, s), _centre(grid, g))
            continue
        path = planner.plan(grid, _centre(grid, s), _centre(grid, g))
        assert polyline_length(path) == pytest.approx(best, rel=1e-9, abs=1e-9), name


@pytest.mark.parametrize("seed", range(30))
def test_theta_star_no_longer_than_astar_and_line_of_sight(seed: int) -> None:
    occ, s, g = _random_grid(2000 + seed, shape=(40, 45), density=0.2)
    grid = OccupancyGrid.from_occupied(occ, RES, origin=(-2.0, 0.7))
    start, goal = _centre(grid, s), _centre(grid, g)
    try:
        grid_path = _exact("astar").plan(grid, start, goal)
    except NoPathFound:
        with pytest.raises(NoPathFound):
            _exact("theta_star").plan(grid, start, goal)
        return
    path = _exact("theta_star").plan(grid, start, goal)
    assert polyline_length(path) <= polyline_length(grid_path) + 1e-9
    np.testing.assert_allclose(path[0], start.xy)
    np.testing.assert_allclose(path[-1], goal.xy)
    for a, b in itertools.pairwise(path):
        assert segment_is_free(grid, a, b)
        # Independent check: dense sampling of the segment touches no occupied cell.
        n = max(2, int(np.ceil(np.linalg.norm(b - a) / RES * 50)))
        pts = a + np.linspace(0, 1, n)[:, None] * (b - a)
        assert not grid.is_occupied(pts).any()


def test_theta_star_arbitrary_endpoints_are_exact() -> None:
    occ, s, g = _random_grid(7, shape=(40, 40), density=0.15)
    grid = OccupancyGrid.from_occupied(occ, RES)
    rng = np.random.default_rng(3)
    start = _centre(grid, s)
    goal = _centre(grid, g)
    start = Pose2D(start.x + rng.uniform(-0.049, 0.049), start.y + rng.uniform(-0.049, 0.049))
    goal = Pose2D(goal.x + rng.uniform(-0.049, 0.049), goal.y + rng.uniform(-0.049, 0.049))
    path = _exact("theta_star").plan(grid, start, goal)
    np.testing.assert_allclose(path[0], start.xy)
    np.testing.assert_allclose(path[-1], goal.xy)
    for a, b in itertools.pairwise(path):
        assert segment_is_free(grid, a, b)


def test_theta_star_is_strictly_shorter_on_open_diagonal() -> None:
    grid = OccupancyGrid.empty(6.0, 4.0, RES)
    start, goal = Pose2D(0.55, 0.55), Pose2D(5.45, 2.25)
    theta = _exact("theta_star").plan(grid, start, goal)
    astar = _exact("astar").plan(grid, start, goal)
    straight = math.hypot(goal.x - start.x, goal.y - start.y)
    assert len(theta) == 2
    assert polyline_length(theta) == pytest.approx(straight)
    assert polyline_length(theta) < polyline_length(astar) - 0.1


def test_theta_star_bends_at_a_wall() -> None:
    occ = np.zeros((40, 40), dtype=bool)
    occ[0:30, 20] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    path = _exact("theta_star").plan(grid, Pose2D(0.5, 0.5), Pose2D(3.5, 0.5))
    assert len(path) >= 3
    assert path[1:-1, 1].max() >= 3.0  # goes round the wall's end at y = 3 m
    for a, b in itertools.pairwise(path):
        assert segment_is_free(grid, a, b)


def test_dijkstra_smoothing_and_clearance_defaults_give_free_path() -> None:
    occ, s, g = _random_grid(11, shape=(50, 50), density=0.15)
    grid = OccupancyGrid.from_occupied(occ, RES)
    path = DijkstraPlanner().plan(grid, _centre(grid, s), _centre(grid, g))
    for a, b in itertools.pairwise(path):
        assert segment_is_free(grid, a, b)
    # Same search cost as A* (whose default shares the edge cost), so the same smoothed path.
    astar = GLOBAL_PLANNERS.build({"type": "astar"}).plan(grid, _centre(grid, s), _centre(grid, g))
    assert polyline_length(path) == pytest.approx(polyline_length(astar), rel=1e-6)


@pytest.mark.parametrize("name", ["dijkstra", "theta_star"])
def test_typed_failures(name: str) -> None:
    occ = np.zeros((30, 30), dtype=bool)
    occ[5, 5] = True
    occ[18:25, 18] = occ[18:25, 24] = occ[18, 18:25] = occ[24, 18:25] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    planner = GLOBAL_PLANNERS.build({"type": name})
    with pytest.raises(StartOccupied):
        planner.plan(grid, Pose2D(0.55, 0.55), Pose2D(1.5, 1.5))
    with pytest.raises(StartOccupied, match="off the map"):
        planner.plan(grid, Pose2D(-0.5, 0.5), Pose2D(1.5, 1.5))
    with pytest.raises(GoalOccupied):
        planner.plan(grid, Pose2D(1.5, 1.5), Pose2D(0.55, 0.55))
    with pytest.raises(GoalOccupied, match="off the map"):
        planner.plan(grid, Pose2D(1.5, 1.5), Pose2D(0.5, 9.0))
    with pytest.raises(NoPathFound):
        planner.plan(grid, Pose2D(0.25, 0.25), Pose2D(2.15, 2.15))


@pytest.mark.parametrize("name", ["dijkstra", "theta_star"])
def test_diagonal_gap_is_not_a_passage(name: str) -> None:
    occ = np.zeros((20, 20), dtype=bool)
    occ[:10, 10] = True
    occ[10, :10] = True
    occ[10:, 11] = True
    occ[9, 11:] = True
    grid = OccupancyGrid.from_occupied(occ, RES)
    with pytest.raises(NoPathFound):
        GLOBAL_PLANNERS.build({"type": name}).plan(grid, Pose2D(0.25, 0.25), Pose2D(1.85, 1.85))


@pytest.mark.parametrize("name", ["dijkstra", "theta_star"])
def test_same_cell_gives_two_points(name: str) -> None:
    grid = OccupancyGrid.empty(2.0, 2.0, RES)
    path = GLOBAL_PLANNERS.build({"type": name}).plan(grid, Pose2D(0.51, 0.51), Pose2D(0.55, 0.58))
    assert path.shape == (2, 2)


def _path_cost(cm: Costmap, path: np.ndarray, penalty: np.ndarray) -> float:
    cells = cm.world_to_cell(path)
    total = 0.0
    for a, b in itertools.pairwise(cells):
        step = cm.resolution * math.hypot(*(b - a))
        total += step * (1 + 0.5 * (penalty[tuple(a)] + penalty[tuple(b)]))
    return total


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("h_weight", [0.0, 1.0])
def test_costmap_planning_equals_brute_force(seed: int, h_weight: float) -> None:
    rng = np.random.default_rng(3000 + seed)
    costs = rng.integers(0, 253, (25, 30)).astype(np.uint8)
    costs[rng.random((25, 30)) < 0.2] = LETHAL
    free = np.argwhere(costs < INSCRIBED)
    s, g = free[rng.choice(len(free), 2, replace=False)]
    cm = Costmap(costs, RES, (1.0, 2.0))
    weight = 2.5
    penalty = weight * np.minimum(costs, 252) / 252.0
    occ = costs >= INSCRIBED
    dist = dijkstra(_graph(occ, RES, penalty), indices=s[0] * 30 + s[1])
    best = dist[g[0] * 30 + g[1]]
    start = Pose2D(*cm.cell_to_world(s))
    goal = Pose2D(*cm.cell_to_world(g))
    if not np.isfinite(best):
        with pytest.raises(NoPathFound):
            plan_on_costmap(cm, start, goal, cost_weight=weight, heuristic_weight=h_weight)
        return
    path = plan_on_costmap(cm, start, goal, cost_weight=weight, heuristic_weight=h_weight)
    assert _path_cost(cm, path, penalty) == pytest.approx(best, rel=1e-9)


def test_costmap_planning_detours_around_costly_band() -> None:
    costs = np.zeros((40, 60), dtype=np.uint8)
    costs[5:40, 30] = 250  # a costly (not lethal) band with a free gap at the bottom
    cm = Costmap(costs, RES, (0.0, 0.0))
    start, goal = Pose2D(1.0, 3.0), Pose2D(5.0, 3.0)
    cheap = plan_on_costmap(cm, start, goal, cost_weight=0.0)
    careful = plan_on_costmap(cm, start, goal, cost_weight=50.0)
    assert (cm.cost_at(cheap) == 250).any()
    assert not (cm.cost_at(careful) == 250).any()
    assert careful[:, 1].min() < 0.5  # through the gap below the band
    smooth = plan_on_costmap(cm, start, goal, cost_weight=50.0, smooth=True)
    assert len(smooth) < len(careful)
    assert polyline_length(smooth) <= polyline_length(careful) + 1e-9
    with pytest.raises(StartOccupied):
        plan_on_costmap(cm, Pose2D(3.05, 1.55), goal, lethal_threshold=250)
    with pytest.raises(ValueError, match="cost_weight"):
        plan_on_costmap(cm, start, goal, cost_weight=-1.0)
