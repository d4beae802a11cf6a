"""Drawn starts and goals hold the robot's real footprint, whatever its heading."""

import numpy as np
import pytest

from arena.robots.presets import load_robot
from arena.scene.state import StaticWorld
from arena.sim.contacts import Footprint, ObstacleIndex, first_obstacle_hit, hits_grid
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.robot_modes.random import spawn_radius
from arena.tasks.world import WorldSampler

HOSPITAL = {"type": "world", "name": "hospital_floor"}


def test_spawn_radius_is_the_larger_of_radius_and_footprint():
    buddy = load_robot("buddy")
    assert buddy.radius < buddy.circumscribed_radius  # why this test exists
    assert spawn_radius(buddy) == buddy.circumscribed_radius
    burger = load_robot("burger")  # Arena's radius exceeds its circular footprint
    assert spawn_radius(burger) == burger.radius


def _assert_clear(ep, poses):
    model = ep.robots[0].model
    world = StaticWorld.build(ep.grid, ep.obstacles)
    idx = ObstacleIndex.build(world)
    fp = Footprint.make(model.footprint_polygon(), model.circumscribed_radius)
    exact = WorldSampler(ep.grid, ep.obstacles)
    for pose in poses:
        assert not hits_grid(ep.grid, fp, pose), (ep.index, pose)
        assert first_obstacle_hit(idx, fp, pose) == -1, (ep.index, pose)
        # Clear at every heading, not only the one drawn.
        assert exact.clearance(pose[None, :2])[0] >= model.circumscribed_radius, (ep.index, pose)


@pytest.mark.parametrize("robot", ["buddy", "f1tenth"])
@pytest.mark.parametrize("mode", ["random", "zones"])
def test_starts_and_goals_never_overlap_walls_or_obstacles(robot, mode):
    """Clearance 0 beyond the body: Arena's radius alone let buddy's footprint into shelves."""
    robots = {"type": mode, "clearance": 0.0, "min_goal_distance": 2.0}
    obstacles = {"type": "random", "static": 15, "dynamic": 5, "obstacle_clearance": 0.0}
    cfg = TaskConfig(robots=robots, obstacles=obstacles)
    gen = TaskGenerator(cfg, map_spec=HOSPITAL, robots=[load_robot(robot)], seed=3)
    for i in range(40):
        ep = gen.episode(i)
        r = ep.robots[0]
        _assert_clear(ep, [r.start.as_array(), r.goal.as_array()])


def test_explore_teleports_and_new_goals_hold_the_footprint():
    robots = {"type": "explore", "clearance": 0.0, "min_goal_distance": 2.0}
    obstacles = {"type": "random", "static": 15, "dynamic": 0, "obstacle_clearance": 0.0}
    cfg = TaskConfig(robots=robots, obstacles=obstacles)
    gen = TaskGenerator(cfg, map_spec=HOSPITAL, robots=[load_robot("buddy")], seed=5)
    for i in range(10):
        ep = gen.episode(i)
        ctx = gen.runtime(ep).ctx
        mode = ctx.robot_mode
        rng = np.random.default_rng(i)
        poses = []
        for _ in range(5):
            start, goal = mode.on_goal_timeout(ctx, 0, rng)
            after = mode.next_goal(ctx, 0, goal, rng)
            poses += [start.as_array(), goal.as_array(), after.as_array()]
        _assert_clear(ep, poses)
