import itertools

import numpy as np
import pytest

from arena.core.errors import SamplingError
from arena.core.rng import derive_rng
from arena.maps.grid import OccupancyGrid
from arena.maps.sources import MAP_SOURCES, MapResult
from arena.nav.global_planners.astar import AStarPlanner
from arena.robots.presets import load_robot
from arena.sim.native2d.collisions import Footprint, ObstacleIndex, first_obstacle_hit, hits_grid
from arena.sim.state import StaticWorld
from arena.tasks.random_task import RandomTask
from arena.tasks.sampling import line_of_sight


def office() -> MapResult:
    return MAP_SOURCES.build({"type": "world", "name": "small_office"}).build(
        np.random.default_rng(0)
    )


def sample(task, m, robot, seed=0, index=0):
    return task.sample(
        m, [robot], index=index, seed=seed, rng=derive_rng(seed, "episode", index, "task")
    )


def test_same_seed_same_episode_different_seed_differs():
    task = RandomTask(RandomTask.Params(agents=8, obstacles=3))
    m, jackal = office(), load_robot("jackal")
    a, b, c = sample(task, m, jackal), sample(task, m, jackal), sample(task, m, jackal, seed=1)
    assert a.robots[0].start == b.robots[0].start and a.robots[0].goal == b.robots[0].goal
    assert np.array_equal(a.agents.waypoints, b.agents.waypoints, equal_nan=True)
    assert [o.pose.tolist() for o in a.obstacles] == [o.pose.tolist() for o in b.obstacles]
    assert a.robots[0].start != c.robots[0].start


@pytest.mark.parametrize("seed", range(6))
def test_constraints_hold(seed):
    p = RandomTask.Params(agents=10, obstacles=5, min_goal_distance=8.0)
    task = RandomTask(p)
    m, jackal = office(), load_robot("jackal")
    ep = sample(task, m, jackal, seed=seed)
    world = StaticWorld.build(ep.grid, ep.obstacles)
    fp = Footprint.make(jackal.footprint_polygon(), jackal.circumscribed_radius)
    idx = ObstacleIndex.build(world)
    r = ep.robots[0]
    for pose in (r.start.as_array(), r.goal.as_array()):
        assert not hits_grid(ep.grid, fp, pose)
        assert first_obstacle_hit(idx, fp, pose) == -1
        # Clearance: radius + clearance from every wall cell centre.
        assert ep.grid.distance_at(pose[:2]) >= jackal.radius + p.clearance - ep.grid.resolution
    assert r.start.distance_to(r.goal) >= p.min_goal_distance
    # The goal is reachable for the planner.
    from arena.experiment import planning_grid

    path = AStarPlanner().plan(planning_grid(ep).inflate(jackal.radius), r.start, r.goal)
    assert len(path) >= 2
    # Obstacles keep their clearance from each other.
    for i, a in enumerate(ep.obstacles):
        for b in ep.obstacles[i + 1 :]:
            assert np.hypot(*(a.pose[:2] - b.pose[:2])) > p.obstacle_clearance
    # Pedestrians: away from the robot start, round trips with line of sight.
    ag = ep.agents
    assert len(ag) == 10
    assert np.all(np.hypot(*(ag.positions - r.start.xy).T) > p.agent_robot_clearance)
    walkable = ep.grid.distance > 0  # not inside a wall cell
    for i in range(len(ag)):
        pts = np.vstack([ag.positions[i], ag.waypoints[i, : ag.num_waypoints[i]]])
        for a, b in itertools.pairwise(pts):
            assert line_of_sight(ep.grid, walkable, a, b)
        assert np.allclose(pts[-1], ag.positions[i])  # round trip ends where it started
    assert np.all((ag.vmax >= 0.5) & (ag.vmax <= 1.2))


def test_impossible_request_fails_clearly():
    tiny = MapResult("tiny", OccupancyGrid.empty(3.0, 3.0, 0.05))
    task = RandomTask(RandomTask.Params(agents=0, obstacles=0, min_goal_distance=10.0))
    with pytest.raises(SamplingError, match="min_goal_distance"):
        sample(task, tiny, load_robot("jackal"))
    crowded = RandomTask(RandomTask.Params(agents=0, obstacles=40, obstacle_clearance=1.0))
    with pytest.raises(SamplingError, match="obstacle"):
        sample(crowded, tiny, load_robot("jackal"))


def test_params_validation():
    from pydantic import ValidationError

    with pytest.raises(ValidationError):
        RandomTask.Params(agent_speed=(1.0, 0.5))
    with pytest.raises(ValidationError):
        RandomTask.Params(agnets=3)  # type: ignore[call-arg]


def test_never_samples_in_unknown_space():
    # A free room surrounded by a large unknown area (as in SLAM maps of buildings).
    data = np.full((200, 240), -1, dtype=np.int8)
    data[40:160, 40:200] = 0
    data[40, 40:200] = data[159, 40:200] = 100
    data[40:160, 40] = data[40:160, 199] = 100
    grid = OccupancyGrid(data, 0.05)
    task = RandomTask(RandomTask.Params(agents=6, obstacles=2, min_goal_distance=2.0))
    for seed in range(5):
        ep = sample(task, MapResult("room", grid), load_robot("burger"), seed=seed)
        pts = [ep.robots[0].start.xy, ep.robots[0].goal.xy, *ep.agents.positions]
        pts += [o.pose[:2] for o in ep.obstacles]
        pts += list(ep.agents.waypoints.reshape(-1, 2))
        cells = grid.world_to_cell(np.array(pts))
        assert np.all(grid.data[cells[:, 0], cells[:, 1]] == 0)
