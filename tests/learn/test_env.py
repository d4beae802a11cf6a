"""SocialNavEnv: the Gymnasium contract, determinism, vector envs, episode ends, rendering."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import arena.core.errors
import arena.learn
import arena.learn.env
from arena.learn.env import SocialNavEnv
from tests.learn.helpers import small_cfg, small_robot

VARIANTS = {
    "discrete": (),
    "continuous": ("learning.env.action.type=continuous",),
    "continuous_normalized": (
        "learning.env.action.type=continuous", "learning.env.action.normalize=true",
    ),
    "custom_grid": ("learning.env.action.discretization=custom",),
    "pedestrians": ("learning.env.observation.pedestrians.enabled=true",),
    "semantic": (
        "learning.env.observation.semantic={enabled: true, size: 16, roi: 8.0}",
        "learning.env.observation.lidar=false",
    ),
    "laser_stack_flat": (
        "learning.env.observation.laser_stack=3",
        "learning.env.observation.flatten=true",
        "learning.env.observation.pedestrians.enabled=true",
    ),
}


@pytest.mark.parametrize("variant", list(VARIANTS))
@pytest.mark.filterwarnings("ignore:.*symmetric and normalized space")  # Arena's raw units
def test_check_env(variant):
    env = SocialNavEnv(small_cfg(*VARIANTS[variant]), robot=small_robot())
    check_env(env, skip_render_check=True)


def rollout(env: SocialNavEnv, seed: int, n: int = 25) -> list:
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(7)
    out = [obs]
    for _ in range(n):
        a = rng.integers(env.action_space.n)
        obs, r, term, trunc, info = env.step(a)
        out.append((obs, r, term, trunc, info["outcome"]))
        if term or trunc:
            obs, _ = env.reset()
            out.append(obs)
    return out


def _equal(a, b) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, tuple | list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def test_same_seed_same_actions_same_rollout():
    cfg = small_cfg("learning.env.observation.pedestrians.enabled=true")
    a = rollout(SocialNavEnv(cfg, robot=small_robot()), seed=3)
    b = rollout(SocialNavEnv(cfg, robot=small_robot()), seed=3)
    assert _equal(a, b)
    c = rollout(SocialNavEnv(cfg, robot=small_robot()), seed=4)
    assert not _equal(a, c)


def test_episode_index_advances_and_seed_restarts():
    env = SocialNavEnv(small_cfg(), robot=small_robot())
    _, info = env.reset(seed=1)
    assert info["episode_index"] == 0
    assert env.reset()[1]["episode_index"] == 1
    assert env.reset(options={"episode": 5})[1]["episode_index"] == 5
    assert env.reset(seed=1)[1]["episode_index"] == 0


def test_truncates_at_max_steps_with_timeout_outcome():
    env = SocialNavEnv(small_cfg("learning.env.max_steps=3"), robot=small_robot())
    env.reset(seed=0)
    stop = 6  # jackal's "stop" action: the robot stays
    for _ in range(2):
        assert env.step(stop)[3] is False
    _, r, term, trunc, info = env.step(stop)
    assert trunc and not term and info["outcome"] == "timeout" and not info["is_success"]
    assert info["reward_terms"]["max_steps_exceeded"] == -10.0
    assert r == pytest.approx(sum(info["reward_terms"].values()))


def test_goal_reached_terminates_with_success():
    env = SocialNavEnv(small_cfg("learning.env.action.type=continuous"), robot=small_robot())
    env.reset(seed=0)
    driver = env.driver
    driver.goals[0, :2] = driver.state.robots.poses[0, :2]  # goal under the robot
    _, _, term, trunc, info = env.step(np.zeros(2, np.float32))
    assert term and not trunc and info["outcome"] == "success" and info["is_success"]
    assert info["reward_terms"]["goal_reached"] == 15.0


def test_action_period_runs_several_sim_steps():
    env = SocialNavEnv(small_cfg("learning.env.action_period=0.3"), robot=small_robot())
    env.reset(seed=0)
    *_, info = env.step(0)
    assert info["time"] == pytest.approx(0.3)


def test_gym_make_registered_id():
    assert arena.learn.ENV_ID in gym.registry
    env = gym.make(arena.learn.ENV_ID, config=small_cfg(), robot=small_robot())
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    env.close()


def test_render_rgb_array():
    env = SocialNavEnv(small_cfg(), robot=small_robot(), render_mode="rgb_array")
    env.reset(seed=0)
    env.step(0)
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8


@pytest.mark.parametrize("kind", ["sync", "async"])
def test_vector_envs(kind):
    cfg, robot = small_cfg(), small_robot()
    fns = [lambda: SocialNavEnv(cfg, robot=robot) for _ in range(2)]
    vec = gym.vector.SyncVectorEnv(fns) if kind == "sync" else gym.vector.AsyncVectorEnv(fns)
    try:
        obs, _ = vec.reset(seed=[0, 1])
        assert obs["lidar"].shape == (2, 24)
        for _ in range(3):
            obs, rew, *_ = vec.step(np.array([0, 6]))
        assert rew.shape == (2,) and np.all(np.isfinite(rew))
    finally:
        vec.close()


@pytest.mark.parametrize("reward", ["default", "rule_13", "base_semantic"])
def test_one_robot_scalar_reward_input_matches_the_batched_input(reward):
    """The driver's scalar reward input carries the bits of its batched input, field by field,
    and the scalar reward path returns the batched reward output."""
    import dataclasses

    from arena.learn.rewards import RewardInput

    env = SocialNavEnv(small_cfg(f"learning.env.reward={reward}"), robot=small_robot())
    fn = env.driver.reward_fn
    single = fn.single
    seen = []

    def checked(inp):
        batch = inp.batched()
        assert isinstance(batch, RewardInput)
        for f in dataclasses.fields(inp):
            if f.name == "batched":
                continue
            got = np.asarray(getattr(inp, f.name), dtype=getattr(batch, f.name).dtype)
            assert got.tobytes() == getattr(batch, f.name)[0].tobytes(), f.name
        out = single(inp)
        ref = fn(batch)
        assert out.total.tobytes() == ref.total.tobytes()
        assert out.done.tolist() == ref.done.tolist()
        assert out.reason.tolist() == ref.reason.tolist()
        assert all(out.terms[k].tobytes() == v.tobytes() for k, v in ref.terms.items())
        seen.append(inp.step)
        return out

    fn.single = checked
    env.reset(seed=2)
    rng = np.random.default_rng(0)
    for _ in range(60):
        _, _, term, trunc, _ = env.step(rng.integers(env.action_space.n))
        if term or trunc:
            env.reset()
    assert len(seen) == 60


def test_gym_make_takes_config_keys_as_keywords():
    """Keywords are config keys: a preset name, blocks merged as overrides, dotted overrides."""
    env = gym.make(
        "arena/SocialNav-v0", robot="burger", map={"type": "empty", "width": 10},
        task={"robots": {"min_goal_distance": 3.0}}, overrides=["task.obstacles.dynamic=2"],
    )
    cfg = env.unwrapped.cfg
    assert cfg.robot == "burger" and cfg.map == {"type": "empty", "width": 10}
    assert cfg.task.obstacles["dynamic"] == 2 and cfg.task.obstacles["static"] == 4  # merged
    obs, _ = env.reset(seed=0)
    # one robot, one scan: (beams,), the burger's 360 beams
    assert obs["lidar"].shape == env.observation_space["lidar"].shape == (360,)
    env.close()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"robots": "burger"}, "SocialNavEnv: unknown keyword argument 'robots'; did you mean "
                               "'robot'?"),
        ({"robot": "burgr"}, "SocialNavEnv(robot='burgr'): robot: unknown robot 'burgr'"),
        ({"map": {"type": "empty", "width": "x"}}, "SocialNavEnv(map={'type': 'empty', "
                                                   "'width': 'x'}): map.width: "),
        ({"seed": object()}, "SocialNavEnv(seed=...): a value of type object is not config data"),
    ],
)
def test_bad_keywords_are_one_line_config_errors(kwargs, message):
    with pytest.raises(arena.core.errors.ConfigError) as e:
        gym.make("arena/SocialNav-v0", **kwargs)
    assert str(e.value).startswith(message) and "\n" not in str(e.value)


def test_environments_import_from_the_package():
    from arena.learn import BatchedSocialNavEnv, MultiRobotEnv, SocialNavEnv
    from arena.learn.batched import BatchedSocialNavEnv as batched
    from arena.learn.multi import MultiRobotEnv as multi

    assert BatchedSocialNavEnv is batched and MultiRobotEnv is multi
    assert SocialNavEnv is arena.learn.env.SocialNavEnv
    with pytest.raises(AttributeError, match="has no attribute 'Nope'"):
        arena.learn.Nope  # noqa: B018


def test_stacked_scans_keep_their_stack_axis():
    env = SocialNavEnv(small_cfg("learning.env.observation.laser_stack=3"), robot=small_robot())
    obs, _ = env.reset(seed=0)
    assert obs["lidar"].shape == (3, 24)
