"""Global plans that fit the robot: narrow doors (footprint) and coarse maps (subdivided cells)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from arena.config import load_config
from arena.core.errors import PlanningError
from arena.core.types import Outcome, Pose2D
from arena.experiment import run_episode
from arena.maps.grid import OccupancyGrid
from arena.nav import NavigationConfig, NavigationStack
from arena.nav.build import stack_from_config
from arena.nav.planning import subdivide
from arena.robots.presets import load_robot
from arena.sim.native2d import Native2DBackend
from tests.conftest import make_episode

JACKAL = load_robot("jackal")  # circumscribed radius 0.267 m, footprint 0.42 × 0.33 m


def _door_map(door: float, res: float = 0.05) -> OccupancyGrid:
    """10 × 6 m room, a 0.2 m wall at x ∈ [5, 5.2] with a door ``door`` m wide centred at y = 3."""
    h, w = round(6.0 / res), round(10.0 / res)
    occ = np.zeros((h, w), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    ys = (np.arange(h) + 0.5) * res
    wall_cols = slice(round(5.0 / res), round(5.2 / res))
    occ[np.abs(ys - 3.0) > door / 2, wall_cols] = True
    return OccupancyGrid.from_occupied(occ, res)


def _stack(**kw) -> NavigationStack:
    return stack_from_config(
        NavigationConfig(**kw), robot_radius=JACKAL.radius,
        footprint_radius=JACKAL.inscribed_radius,
    )


def _edge_clearance(grid: OccupancyGrid, path: np.ndarray) -> float:
    """Least distance (m) from the polyline to the square of any occupied cell (exact)."""
    pts = np.concatenate([
        np.linspace(a, b, max(2, int(np.hypot(*(b - a)) / 0.02)))
        for a, b in itertools.pairwise(path)
    ])
    rows, cols = np.nonzero(grid.occupied)
    centres = grid.cell_to_world(np.stack([rows, cols], axis=1))
    half = grid.resolution / 2
    d = np.maximum(np.abs(pts[:, None, :] - centres[None, :, :]) - half, 0.0)
    return float(np.min(np.hypot(d[..., 0], d[..., 1])))


def test_inscribed_radius_of_the_jackal_is_half_its_width():
    assert JACKAL.inscribed_radius == pytest.approx(0.165)
    assert load_robot("burger").inscribed_radius == pytest.approx(0.105)  # a circle


def test_plan_goes_through_a_door_the_footprint_fits():
    grid = _door_map(0.6)  # Arena's experiment_rooms doors; 0.6 m < 2 · (0.267 + 0.05)
    stack = _stack()
    stack.reset(grid, Pose2D(2.0, 3.0, 0.0), Pose2D(8.0, 3.0, 0.0))
    assert stack.footprint_plan
    path = stack.path
    # It crosses the wall through the door, with the footprint's half width to spare.
    xs = np.linspace(5.0, 5.2, 5)
    ys = np.interp(xs, path[:, 0], path[:, 1])
    assert np.all(np.abs(ys - 3.0) < 0.3 - JACKAL.inscribed_radius)
    assert _edge_clearance(grid, path) >= JACKAL.inscribed_radius


def test_a_replan_in_a_narrow_passage_plans_once():
    """Start and goal apart for the circle: no full search of the circle's region first."""
    stack = _stack()
    calls = []
    plan = stack.global_planner.plan
    stack.global_planner.plan = lambda grid, s, g: calls.append(grid) or plan(grid, s, g)
    stack.reset(_door_map(0.6), Pose2D(2.0, 3.0, 0.0), Pose2D(8.0, 3.0, 0.0))
    assert calls == [stack.inflated_footprint]
    assert stack.replan(Pose2D(2.5, 3.0, 0.0))
    assert calls[1:] == [stack.inflated_footprint]


def test_no_plan_through_a_door_narrower_than_the_footprint():
    stack = _stack()
    with pytest.raises(PlanningError):
        stack.reset(_door_map(0.4), Pose2D(2.0, 3.0, 0.0), Pose2D(8.0, 3.0, 0.0))


def test_wide_routes_keep_the_circumscribed_clearance():
    """Where the robot's circle fits, the plan is the one made with it (no narrow shortcut)."""
    grid = _door_map(1.2)
    stack = _stack()
    stack.reset(grid, Pose2D(2.0, 3.0, 0.0), Pose2D(8.0, 3.0, 0.0))
    assert not stack.footprint_plan
    assert _edge_clearance(grid, stack.path) >= JACKAL.radius


def test_jackal_drives_through_a_0_6_m_door(tmp_path):
    grid = _door_map(0.6)
    ep = make_episode(grid, [(JACKAL, (2.0, 3.0, 0.0), (8.0, 3.0, 0.0))])
    cfg = load_config(None, ["output.video=false"])
    res = run_episode(cfg, ep, Native2DBackend(), None)
    assert res.outcome == Outcome.SUCCESS, res.error
    assert res.collisions == 0


def _coarse_map() -> OccupancyGrid:
    """15 × 15 m at 0.5 m cells (Arena's map10): border walls, staggered 1 m blocks 1.5 m apart."""
    n = 30
    occ = np.zeros((n, n), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    for r in range(4, 26, 5):
        for c in range(4 + (r // 5) % 2 * 2, 26, 5):
            occ[r:r + 2, c:c + 2] = True
    return OccupancyGrid.from_occupied(occ, 0.5)


def _coarse_trips(grid: OccupancyGrid, n: int = 12) -> list[tuple[tuple, tuple]]:
    """``n`` start/goal poses ≥ 0.9 m (centre to centre) from every wall cell, seeded."""
    rng = np.random.default_rng(1)
    cells = np.argwhere(grid.distance > 0.9)
    trips = []
    for _ in range(n):
        a, b = grid.cell_to_world(cells[rng.choice(len(cells), 2)])
        trips.append(((*a, rng.uniform(-3.0, 3.0)), (*b, 0.0)))
    return trips


def test_subdivide_keeps_the_walls():
    grid = _coarse_map()
    fine = subdivide(grid, 0.1)
    assert fine.resolution == pytest.approx(0.1)
    assert fine.origin == grid.origin and fine.size_m == grid.size_m
    pts = np.random.default_rng(0).uniform(0.0, 15.0, size=(2000, 2))
    assert np.array_equal(fine.is_occupied(pts), grid.is_occupied(pts))
    small = _door_map(0.6)
    assert subdivide(small, 0.1) is small
    huge = OccupancyGrid.from_occupied(np.zeros((2000, 2000), dtype=bool), 0.5)  # 1 km
    assert subdivide(huge, 0.1).resolution == pytest.approx(0.25)  # 16 million cells at most


def test_coarse_map_plan_keeps_the_robot_off_the_walls():
    """0.5 m cells: a 0.317 m inflation once marked no cell, and plans kept 0.25 m from walls."""
    grid = _coarse_map()
    stack = _stack()
    coarse = _stack(planning_resolution=1.0)  # the old behaviour: plan on the 0.5 m cells
    old = []
    for start, goal in _coarse_trips(grid):
        stack.reset(grid, Pose2D(*start), Pose2D(*goal))
        assert _edge_clearance(grid, stack.path) >= JACKAL.radius
        coarse.reset(grid, Pose2D(*start), Pose2D(*goal))
        old.append(_edge_clearance(grid, coarse.path))
    assert min(old) < JACKAL.radius


def test_jackal_reaches_goals_on_a_coarse_map_without_touching_walls():
    """Before the fix 2 of these 12 trips stalled at a block until the timeout."""
    grid = _coarse_map()
    cfg = load_config(None, ["output.video=false"])
    for start, goal in _coarse_trips(grid):
        ep = make_episode(grid, [(JACKAL, start, goal)])
        res = run_episode(cfg, ep, Native2DBackend(), None)
        assert res.outcome == Outcome.SUCCESS, (start, goal, res.error)
        assert res.collisions == 0, (start, goal)
