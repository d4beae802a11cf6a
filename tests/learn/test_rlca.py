"""rlca pieces without torch: the velocity observation, the rotation penalty, the reward file,
the training-config blocks (extractor, multi-robot vector env)."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from arena.learn.config import ObservationConfig
from arena.learn.env import SocialNavEnv
from arena.learn.observations import ObservationBuilder, ObsInput
from arena.learn.rewards import RewardFunction, build_term, packaged_reward
from arena.learn.train_config import PPOConfig, TrainConfig
from tests.learn.helpers import small_cfg, small_robot
from tests.learn.test_rewards import make_input


def _inp(twists):
    n = len(twists)
    return ObsInput(
        poses=np.zeros((n, 3)), twists=np.asarray(twists, float), goals=np.ones((n, 2)),
        scans=np.ones((n, 1, 8)), last_action=np.zeros((n, 3)),
        ped_pos=np.zeros((n, 0, 2)), ped_vel=np.zeros((n, 0, 2)),
        ped_kind=np.zeros((n, 0), np.int64), ped_state=np.zeros((n, 0), np.int64),
        ped_mask=np.zeros((n, 0), bool),
    )


def test_velocity_observation_is_the_measured_twist_clipped_to_the_limits():
    robot = small_robot(8)
    lim = robot.limits()
    b = ObservationBuilder(ObservationConfig(velocity=True, last_action=False), robot)
    assert b.keys == ("goal", "lidar", "velocity")
    out = b.build(_inp([[0.5, 0.0, -0.3], [99.0, 0.0, -99.0]]))["velocity"]
    assert out.dtype == np.float32 and out.shape == (2, 3)
    np.testing.assert_allclose(out[0], [0.5, 0.0, -0.3], rtol=1e-6)
    np.testing.assert_allclose(out[1], [lim.vx_max, 0.0, -lim.omega_max], rtol=1e-6)
    assert b.dict_space["velocity"].contains(out[1])


def test_env_velocity_follows_the_robot():
    cfg = small_cfg("learning.env.observation.velocity=true",
                    "learning.env.action={type: continuous}")
    env = SocialNavEnv(cfg, robot=small_robot(8))
    obs, _ = env.reset(seed=0)
    np.testing.assert_array_equal(obs["velocity"], [0.0, 0.0, 0.0])
    for _ in range(5):
        obs, *_ = env.step(np.array([0.6, 0.2]))
    twist = env.driver.state.robots.twists[0]
    np.testing.assert_allclose(obs["velocity"], twist, rtol=1e-6)
    assert obs["velocity"][0] > 0.3 and obs["velocity"][1] == 0.0  # diff drive: vy = 0
    assert env.observation_space.contains(obs)


def test_rotation_penalty_on_commanded_yaw_rate():
    t = build_term("rotation_penalty")
    inp = make_input(action=[[0.5, 0.0, 0.69], [0.5, 0.0, -1.5]])
    np.testing.assert_allclose(t(inp).reward, [0.0, -0.15])
    assert not t(inp).done.any()
    t2 = build_term("rotation_penalty", factor=0.2, threshold=0.0)
    np.testing.assert_allclose(t2(inp).reward, [-0.138, -0.3])
    with pytest.raises(Exception, match="factor"):
        build_term("rotation_penalty", factor=-1.0)


def test_rlca_reward_file_is_long_et_al():
    spec = packaged_reward("rlca")
    assert set(spec) == {"goal_reached", "collision", "approach_goal", "rotation_penalty"}
    fn = RewardFunction("rlca")
    # 0.4 m of progress, a 1.0 rad/s turn: 2.5 · 0.4 − 0.1 · 1.0
    inp = make_input(prev_goal_distance=[5.0, 5.0], goal_distance=[4.6, 5.2],
                     action=[[0.5, 0.0, 1.0], [0.5, 0.0, 0.1]])
    np.testing.assert_allclose(fn(inp).total, [0.9, -0.5])
    out = fn(make_input(goal_reached=[True, False], collision=[False, True]))
    np.testing.assert_allclose(out.total, [15.0, -15.0])
    assert out.done.all()


def test_extractor_and_multi_robot_settings_are_validated():
    ppo = PPOConfig.model_validate({"extractor": {"type": "rlca_conv", "fc": 64}})
    assert ppo.extractor.type == "rlca_conv" and ppo.extractor.filters == [32, 32]
    assert PPOConfig().extractor.type == "flatten"
    for bad in ({"type": "rlca_conv", "filter": [8]}, {"type": "nope"},
                {"type": "rlca_conv", "filters": [8], "kernels": [3, 3], "strides": [1]}):
        with pytest.raises(ValidationError):
            PPOConfig.model_validate({"extractor": bad})
    tc = TrainConfig.model_validate({"vec_env": "multi_robot", "n_envs": 5,
                                     "robots_per_world": [2, 3]})
    assert tc.robots_per_world == [2, 3]
    with pytest.raises(ValidationError, match="n_envs"):
        TrainConfig.model_validate({"vec_env": "multi_robot", "n_envs": 4,
                                    "robots_per_world": [2, 3]})
    with pytest.raises(ValidationError, match="robots_per_world"):
        TrainConfig.model_validate({"vec_env": "multi_robot", "n_envs": 4})
    with pytest.raises(ValidationError, match="only applies"):
        TrainConfig.model_validate({"vec_env": "dummy", "robots_per_world": [2]})


def test_batched_env_serves_the_velocity_part_unchanged():
    """BatchedSocialNavEnv builds observations through ObservationBuilder: no edit needed."""
    from arena.learn.batched import BatchedSocialNavEnv

    cfg = small_cfg("learning.env.observation.velocity=true",
                    "learning.env.action={type: continuous}")
    env = BatchedSocialNavEnv(cfg, num_envs=2, robot=small_robot(8))
    env.reset(seed=0)
    for _ in range(4):
        obs, *_ = env.step(np.tile([0.6, 0.3], (2, 1)))
    assert obs["velocity"].shape == (2, 3)
    np.testing.assert_allclose(obs["velocity"][:, 1], 0.0)
    assert np.all(obs["velocity"][:, 0] > 0.3)
