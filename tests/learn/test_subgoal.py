"""Subgoal ("spacial horizon", arena_specs §8.1): the pure function, the tracker, the env."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from arena.learn.config import SubgoalObsConfig
from arena.learn.driver import SubgoalTracker
from arena.learn.env import SocialNavEnv
from arena.learn.observations import goal_polar
from arena.learn.paths import project_on_path, subgoal_on_path
from arena.maps.grid import OccupancyGrid
from tests.learn.helpers import small_cfg, small_robot
from tests.learn.test_env import _equal, rollout

L_PATH = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 6.0]])


def test_subgoal_on_l_shaped_path_by_hand():
    # projection of (1, 0.5) is (1, 0) at arc length 1; 5 m further: 3 m along x, 2 m up
    assert subgoal_on_path(L_PATH, np.array([1.0, 0.5]), 5.0) == pytest.approx([4.0, 2.0])
    # from the start, 2.5 m ahead lies on the first leg
    assert subgoal_on_path(L_PATH, np.array([0.0, 0.0]), 2.5) == pytest.approx([2.5, 0.0])
    # exactly at the corner
    assert subgoal_on_path(L_PATH, np.array([0.0, 0.0]), 4.0) == pytest.approx([4.0, 0.0])
    # on the second leg (projection (4, 1), arc length 5): 1 m ahead
    assert subgoal_on_path(L_PATH, np.array([4.3, 1.0]), 1.0) == pytest.approx([4.0, 2.0])


def test_subgoal_is_the_goal_when_closer_than_the_horizon():
    # 5.39 m from the goal in a straight line but only 5 m of path remain → goal
    assert subgoal_on_path(L_PATH, np.array([6.0, 1.0]), 5.2) == pytest.approx([4.0, 6.0])
    # straight-line distance to the goal (3.16 m) within the horizon → goal
    assert subgoal_on_path(L_PATH, np.array([1.0, 5.0]), 3.5) == pytest.approx([4.0, 6.0])
    # a one-point path is its goal
    assert subgoal_on_path(L_PATH[-1:], np.array([0.0, 0.0]), 1.0) == pytest.approx([4.0, 6.0])


def test_project_on_path():
    s, d = project_on_path(L_PATH, np.array([5.0, 3.0]))
    assert s == pytest.approx(7.0) and d == pytest.approx(1.0)
    s, d = project_on_path(L_PATH, np.array([-1.0, 0.0]))
    assert s == pytest.approx(0.0) and d == pytest.approx(1.0)


def _walled_grid() -> OccupancyGrid:
    """8 × 8 m, a wall at y ∈ [3.9, 4.1] from x = 0 to x = 6 (gap on the right)."""
    occ = np.zeros((80, 80), dtype=bool)
    occ[39:41, :60] = True
    return OccupancyGrid.from_occupied(occ, 0.1)


def test_tracker_plans_around_the_wall_and_replans():
    cfg = SubgoalObsConfig(enabled=True, horizon=2.0, replan_period=1.0)
    tr = SubgoalTracker(cfg, inscribed=0.3, n_robots=1)
    poses = np.array([[1.0, 1.0, 0.0]])
    goals = np.array([[1.0, 7.0, 0.0]])
    tr.reset(_walled_grid(), poses, goals, 0.0)
    path = tr.paths[0]
    assert path[0] == pytest.approx([1.0, 1.0], abs=0.1)
    assert path[-1] == pytest.approx([1.0, 7.0], abs=0.1)
    assert path[:, 0].max() > 6.0  # through the gap
    # the subgoal lies 2 m along the path, heading right (towards the gap), not up the wall
    sub = tr.current[0]
    assert np.hypot(*(sub - poses[0, :2])) == pytest.approx(2.0, abs=0.05)
    assert sub[0] > 2.5
    first = tr.paths[0]
    tr.update(poses, goals, 0.5)  # neither due nor strayed: same path
    assert tr.paths[0] is first
    tr.update(np.array([[1.0, 3.0, 0.0]]), goals, 0.6)  # > 1 m off the path: replanned
    assert tr.paths[0] is not first and tr.plan_time[0] == 0.6
    second = tr.paths[0]
    tr.update(np.array([[1.0, 3.0, 0.0]]), goals, 1.6)  # replan_period elapsed
    assert tr.paths[0] is not second


def test_tracker_falls_back_to_a_straight_segment_without_a_path():
    occ = np.zeros((80, 80), dtype=bool)
    occ[39:41, :] = True  # a wall with no gap
    tr = SubgoalTracker(SubgoalObsConfig(enabled=True), inscribed=0.3, n_robots=1)
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    tr.reset(grid, np.array([[1.0, 1.0, 0.0]]), np.array([[1.0, 7.0, 0.0]]), 0.0)
    assert tr.paths[0] == pytest.approx(np.array([[1.0, 1.0], [1.0, 7.0]]))
    assert tr.current[0] == pytest.approx([1.0, 6.0])


SUBGOAL = (
    "learning.env.observation.subgoal={enabled: true, horizon: 1.0}",
    "learning.env.observation.pedestrians.enabled=true",
)


@pytest.mark.filterwarnings("ignore:.*symmetric and normalized space")
def test_env_with_subgoal_passes_check_env():
    env = SocialNavEnv(small_cfg(*SUBGOAL), robot=small_robot())
    check_env(env, skip_render_check=True)


def test_env_with_subgoal_is_deterministic():
    cfg = small_cfg(*SUBGOAL)
    a = rollout(SocialNavEnv(cfg, robot=small_robot()), seed=3)
    b = rollout(SocialNavEnv(cfg, robot=small_robot()), seed=3)
    assert _equal(a, b)


def test_goal_observation_refers_to_the_subgoal_reward_to_the_goal():
    env = SocialNavEnv(small_cfg(*SUBGOAL), robot=small_robot())
    obs, info = env.reset(seed=0)
    d = env.driver
    assert info["goal_distance"] > 1.0  # min_goal_distance 3 m
    pose = d.state.robots.poses
    assert obs["goal"][0] == pytest.approx(1.0, abs=1e-5)  # ρ = horizon (empty room)
    expected = goal_polar(pose, d.subgoals.current)[0]
    assert obs["goal"] == pytest.approx(expected.astype(np.float32))
    obs, _, _, _, info = env.step(0)
    # the reward's approach_goal term sees the final goal's distance change
    assert info["goal_distance"] == pytest.approx(float(d.goal_distance()[0]))
    assert obs["goal"] == pytest.approx(
        goal_polar(d.state.robots.poses, d.subgoals.current)[0].astype(np.float32)
    )
    # without subgoals the same episode observes the final goal
    plain = SocialNavEnv(small_cfg(SUBGOAL[1]), robot=small_robot())
    obs2, _ = plain.reset(seed=0)
    assert obs2["goal"][0] == pytest.approx(info_goal := float(plain.driver.goal_distance()[0]))
    assert info_goal > 1.0


def test_multi_robot_env_with_subgoals():
    from pettingzoo.test import parallel_api_test

    from arena.learn.multi import MultiRobotEnv

    env = MultiRobotEnv(small_cfg(SUBGOAL[0]), n_robots=2, robot=small_robot())
    parallel_api_test(env, num_cycles=20)
    env.reset(seed=1)
    assert env.driver.subgoals is not None and len(env.driver.subgoals.paths) == 2


def test_subgoal_config_validates():
    from arena.config.loader import load_config
    from arena.core.errors import ConfigError

    with pytest.raises(ConfigError):
        load_config(None, ["learning.env.observation.subgoal.horizon=0"])
    with pytest.raises(ConfigError):
        load_config(None, ["learning.env.observation.subgoal.horizn=3"])
