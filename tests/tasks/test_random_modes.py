import itertools
import re

import numpy as np
import pytest
from pydantic import ValidationError

from arena.core.errors import SamplingError
from arena.maps.grid import OccupancyGrid
from arena.maps.io import save_map
from arena.nav.global_planners.astar import AStarPlanner
from arena.robots.presets import load_robot
from arena.scene.episode import episode_digest
from arena.scene.state import StaticWorld
from arena.sim.contacts import Footprint, ObstacleIndex, first_obstacle_hit, hits_grid
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.obstacle_modes.random import RandomObstacles
from arena.tasks.sampling import line_of_sight
from arena.tasks.world import WorldSampler

OFFICE = {"type": "world", "name": "small_office"}


def generator(robots=None, obstacles=None, map_spec=OFFICE, seed=0, robot="jackal"):
    cfg = TaskConfig(robots=robots or {"type": "random"}, obstacles=obstacles or {"type": "random"})
    return TaskGenerator(cfg, map_spec=map_spec, robots=[load_robot(robot)], seed=seed)


def test_same_seed_same_episode_different_seed_differs():
    obstacles = {"type": "random", "static": 3, "dynamic": 8}
    a = generator(obstacles=obstacles).episode(0)
    b = generator(obstacles=obstacles).episode(0)
    c = generator(obstacles=obstacles, seed=1).episode(0)
    assert episode_digest(a) == episode_digest(b)
    assert np.array_equal(a.agents.waypoints, b.agents.waypoints, equal_nan=True)
    assert a.robots[0].start != c.robots[0].start
    assert episode_digest(a) != episode_digest(generator(obstacles=obstacles).episode(1))


@pytest.mark.parametrize("seed", range(6))
def test_constraints_hold(seed):
    robots = {"type": "random", "min_goal_distance": 8.0}
    obstacles = {"type": "random", "static": 5, "dynamic": 10}
    ep = generator(robots, obstacles, seed=seed).episode(0)
    p = RandomObstacles.Params(**{k: v for k, v in obstacles.items() if k != "type"})
    jackal = load_robot("jackal")
    world = StaticWorld.build(ep.grid, ep.obstacles)
    fp = Footprint.make(jackal.footprint_polygon(), jackal.circumscribed_radius)
    idx = ObstacleIndex.build(world)
    exact = WorldSampler(ep.grid, ep.obstacles)
    r = ep.robots[0]
    for pose in (r.start.as_array(), r.goal.as_array()):
        assert not hits_grid(ep.grid, fp, pose)
        assert first_obstacle_hit(idx, fp, pose) == -1
        assert exact.clearance(pose[None, :2])[0] >= jackal.radius + 0.25
    assert r.start.distance_to(r.goal) >= 8.0
    from arena.maps.raster import planning_grid

    path = AStarPlanner().plan(planning_grid(ep).inflate(jackal.radius), r.start, r.goal)
    assert len(path) >= 2
    # Placed obstacles keep their gap from walls and from each other.
    placed = [o for o in ep.obstacles if o.name.startswith("S_")]
    assert len(placed) == 5
    for a in placed:
        others = WorldSampler(ep.grid, [o for o in ep.obstacles if o is not a])
        gap = others.clearance(a.polygon).min()
        assert gap >= p.obstacle_clearance - 1e-9
    ag = ep.agents
    assert len(ag) == 10
    assert np.all(np.hypot(*(ag.positions - r.start.xy).T) > p.agent_robot_clearance)
    walkable = ep.grid.distance > 0
    for i in range(len(ag)):
        pts = np.vstack([ag.positions[i], ag.waypoints[i, : ag.num_waypoints[i]]])
        for a, b in itertools.pairwise(pts):
            assert line_of_sight(ep.grid, walkable, a, b)
        assert np.allclose(pts[-1], ag.positions[i])  # round trip ends where it started
    assert np.all((ag.vmax >= 0.5) & (ag.vmax <= 1.2))


def test_counts_are_drawn_from_the_range():
    obstacles = {"type": "random", "static": [1, 4], "dynamic": {"min": 2, "max": 6}}
    g = generator(obstacles=obstacles)
    statics, people = set(), set()
    for i in range(30):
        ep = g.episode(i)
        statics.add(sum(o.name.startswith("S_") for o in ep.obstacles))
        people.add(len(ep.agents))
    assert statics == {1, 2, 3, 4}
    assert min(people) >= 2 and max(people) <= 6 and len(people) >= 4


def test_library_models_and_interactive_obstacles():
    obstacles = {
        "type": "random",
        "static": {"min": 2, "max": 2, "models": ["shelf", "table"]},
        "interactive": {"min": 1, "max": 1, "models": ["chair"]},
        "dynamic": 0,
    }
    ep = generator(obstacles=obstacles).episode(0)
    names = [o.name for o in ep.obstacles]
    assert sum(n.startswith("S_") for n in names) == 2
    assert any(n == "I_chair_1" for n in names)
    assert {o.model for o in ep.obstacles if o.name.startswith("S_")} <= {"shelf", "table"}


def test_impossible_request_fails_clearly():
    tiny = {"type": "empty", "width": 3.0, "height": 3.0}
    far = {"type": "random", "min_goal_distance": 10.0}
    with pytest.raises(SamplingError, match="min_goal_distance") as e:
        generator(far, {"type": "random", "static": 0, "dynamic": 0}, map_spec=tiny).episode(0)
    # it says how far apart free positions can be: less than the 3 m room's diagonal (the
    # walls and the jackal's radius + clearance take their share), more than its inner side
    span = float(re.search(r"at most ([0-9.]+) m apart", str(e.value)).group(1))
    inner = 3.0 - 2 * (load_robot("jackal").radius + 0.25)
    assert inner < span < 3.0 * np.sqrt(2)
    crowded = {"type": "random", "static": 40, "dynamic": 0, "obstacle_clearance": 1.0}
    near = {"type": "random", "min_goal_distance": 1.0}
    with pytest.raises(SamplingError, match="obstacle"):
        generator(near, crowded, map_spec=tiny).episode(0)


def test_params_validation():
    with pytest.raises(ValidationError, match="agent_speed"):
        RandomObstacles.Params(agent_speed=(1.0, 0.5))
    with pytest.raises(ValidationError):
        RandomObstacles.Params(agnets=3)  # type: ignore[call-arg]
    with pytest.raises(ValidationError, match="min"):
        RandomObstacles.Params(static=[5, 2])
    with pytest.raises(ValidationError, match="unknown obstacle model"):
        RandomObstacles.Params(static={"min": 1, "max": 1, "models": ["shelff"]})


def test_never_samples_in_unknown_space(tmp_path):
    data = np.full((200, 240), -1, dtype=np.int8)
    data[40:160, 40:200] = 0
    data[40, 40:200] = data[159, 40:200] = 100
    data[40:160, 40] = data[40:160, 199] = 100
    grid = OccupancyGrid(data, 0.05)
    save_map(grid, tmp_path / "room.yaml")
    spec = {"type": "file", "path": str(tmp_path / "room.yaml")}
    robots = {"type": "random", "min_goal_distance": 2.0}
    obstacles = {"type": "random", "static": 2, "dynamic": 6}
    for seed in range(5):
        ep = generator(robots, obstacles, map_spec=spec, seed=seed, robot="burger").episode(0)
        pts = [ep.robots[0].start.xy, ep.robots[0].goal.xy, *ep.agents.positions]
        pts += [o.pose[:2] for o in ep.obstacles]
        pts += list(ep.agents.waypoints.reshape(-1, 2))
        cells = grid.world_to_cell(np.array(pts))
        assert np.all(grid.data[cells[:, 0], cells[:, 1]] == 0)


@pytest.mark.parametrize("near_ok", [False, True])
def test_waypoint_kernel_matches_numpy_batch(near_ok):
    """The waypoint kernel picks what jitter + hypot + ``line_of_sight`` picked, bit for bit."""
    from arena.tasks.obstacle_modes.random import _pick_waypoint
    from arena.tasks.sampling import jitter

    ep = generator(obstacles={"type": "random", "static": 3, "dynamic": 2}).episode(0)
    grid = ep.grid
    walkable = grid.free & ~grid.occupied
    region = np.argwhere(walkable)
    rng = np.random.default_rng(1)
    lo, hi = (2.0, 8.0)
    d_min, d_max = (0.5, np.inf) if near_ok else (lo, hi)
    hits = 0
    for _ in range(200):
        a = grid.cell_to_world(region[rng.integers(len(region))]) + rng.uniform(-0.02, 0.02, 2)
        pick = rng.integers(len(region), size=16)
        state = rng.bit_generator.state
        pts = jitter(grid, region[pick], rng)
        rng.bit_generator.state = state
        u = rng.uniform(-0.5, 0.5, size=(16, 2))
        out = np.empty(2)
        found = _pick_waypoint(
            region, pick, u, float(a[0]), float(a[1]), d_min, d_max, near_ok,
            float(grid.origin[0]), float(grid.origin[1]), float(grid.resolution),
            grid.height, grid.width, walkable, out,
        )
        d = np.hypot(*(pts - a).T)
        ok = (d >= d_min) if near_ok else (d >= lo) & (d <= hi)
        want = next(
            (i for i in range(16) if ok[i] and line_of_sight(grid, walkable, a, pts[i])), -1
        )
        assert found == (want >= 0)
        if found:
            assert out.tobytes() == pts[want].tobytes()
        hits += found
    assert hits > 10


@pytest.mark.parametrize("far", [12.05, 5.05, 0.15, 0.05, 0.0])
def test_far_cells_match_the_full_map_test(far):
    """Goal cells: the kernel's shortcut keeps exactly the cells ``np.hypot`` keeps."""
    from arena.tasks.robot_modes.random import _far_cells

    grid = OccupancyGrid.empty(24.0, 16.0, 0.05, origin=(-12.0, -8.0))
    rows, cols = np.indices(grid.data.shape)
    cells = np.stack([rows.ravel(), cols.ravel()], axis=1).astype(np.int64)
    cx = grid.origin[0] + (cols + 0.5) * grid.resolution
    cy = grid.origin[1] + (rows + 0.5) * grid.resolution
    rng = np.random.default_rng(int(far * 100))
    starts = [grid.cell_to_world([100, 200]), *rng.uniform([-12, -8], [12, 8], size=(3, 2))]
    for x, y in starts:  # a cell centre first: exact ties on the circle
        want = np.flatnonzero(np.hypot(cx - x, cy - y) >= far)
        got = _far_cells(
            cells, grid.origin[0], grid.origin[1], grid.resolution, grid.width, x, y, far
        )
        assert np.array_equal(got, want)
