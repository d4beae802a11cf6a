"""MultiRobotEnv: the PettingZoo parallel API and determinism."""

import numpy as np
from pettingzoo.test import parallel_api_test

from arena.learn.multi import MultiRobotEnv
from tests.learn.helpers import small_cfg, small_robot


def test_parallel_api():
    env = MultiRobotEnv(small_cfg(), n_robots=2, robot=small_robot())
    parallel_api_test(env, num_cycles=50)


def test_agents_have_own_goals_and_rewards_and_rollouts_repeat():
    def run():
        env = MultiRobotEnv(
            small_cfg("learning.env.observation.pedestrians.enabled=true"),
            n_robots=3, robot=small_robot(),
        )
        obs, infos = env.reset(seed=2)
        assert env.agents == ["robot_0", "robot_1", "robot_2"]
        goals = {a: infos[a]["goal_distance"] for a in env.agents}
        assert len(set(goals.values())) == 3
        out = []
        for k in range(10):
            acts = {a: (k + i) % 7 for i, a in enumerate(env.agents)}
            obs, rew, *_ = env.step(acts)
            out.append((sorted(rew.items()), {a: o["lidar"].copy() for a, o in obs.items()}))
        return out

    a, b = run(), run()
    assert [x[0] for x in a] == [x[0] for x in b]
    for (_, oa), (_, ob) in zip(a, b, strict=True):
        assert all(np.array_equal(oa[k], ob[k]) for k in oa)
