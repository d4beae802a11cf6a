"""BatchedSocialNavEnv: vector-env contract, determinism, autoreset, agreement with SocialNavEnv."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

from arena.learn.batched import BatchedSocialNavEnv
from arena.learn.env import SocialNavEnv
from tests.learn.helpers import small_cfg, small_robot

N = 4


def make(n: int = N, *overrides: str, **kw: object) -> BatchedSocialNavEnv:
    return BatchedSocialNavEnv(small_cfg(*overrides), robot=small_robot(), num_envs=n, **kw)


def actions(env: BatchedSocialNavEnv, steps: int, seed: int = 7) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.integers(env.single_action_space.n, size=(steps, env.num_envs))


def test_spaces_shapes_dtypes() -> None:
    env = make(N, "learning.env.observation.pedestrians.enabled=true")
    single = SocialNavEnv(
        small_cfg("learning.env.observation.pedestrians.enabled=true"), robot=small_robot()
    )
    assert env.single_observation_space == single.observation_space
    assert env.single_action_space == single.action_space
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    obs, info = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    assert info["episode_index"].tolist() == [0, 1, 2, 3]
    for a in actions(env, 30):
        obs, rew, term, trunc, info = env.step(a)
        assert env.observation_space.contains(obs)
        assert rew.shape == (N,) and rew.dtype == np.float64
        assert term.shape == trunc.shape == (N,) and term.dtype == trunc.dtype == np.bool_
        assert set(info["reward_terms"]) >= set(single.driver.reward_fn.names)
        assert info["_outcome"].all() and info["outcome"].shape == (N,)
    env.action_space.seed(0)
    env.step(env.action_space.sample())


def test_flat_observation_and_continuous_actions() -> None:
    env = make(
        3, "learning.env.observation.flatten=true", "learning.env.observation.laser_stack=2",
        "learning.env.action.type=continuous",
    )
    obs, _ = env.reset(seed=0)
    assert obs.shape == (3, env.single_observation_space.shape[0]) and obs.dtype == np.float32
    env.action_space.seed(1)
    for _ in range(5):
        obs, *_ = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs)


def rollout(env: BatchedSocialNavEnv, seed: int, steps: int = 60) -> list:
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for a in actions(env, steps):
        obs, rew, term, trunc, info = env.step(a)
        out.append((obs, rew, term, trunc, info["episode_index"], info["outcome"]))
    return out


def _equal(a, b) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, tuple | list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    return bool(np.array_equal(a, b))


def test_same_seed_same_rollout() -> None:
    a = rollout(make(), 5)
    assert _equal(a, rollout(make(), 5))
    assert not _equal(a, rollout(make(), 6))
    env = make()
    first = rollout(env, 5)
    assert _equal(first, rollout(env, 5))  # reset(seed) restarts the seed's episodes


def test_world_trajectory_does_not_depend_on_n() -> None:
    one, four = make(1), make(4)
    o1, _ = one.reset(seed=2)
    o4, _ = four.reset(seed=2)
    acts = actions(four, 40)
    for a in acts:
        assert all(np.array_equal(o1[k][0], o4[k][0]) for k in o1)
        o1, r1, t1, u1, _ = one.step(a[:1])
        o4, r4, t4, u4, _ = four.step(a)
        assert r1[0] == r4[0] and t1[0] == t4[0] and u1[0] == u4[0]
        if t1[0] or u1[0]:
            break


def test_next_step_autoreset() -> None:
    env = make(N, "learning.env.max_steps=6")
    env.reset(seed=0)
    acts = actions(env, 20)
    _, _, term, trunc, info = env.step(acts[0])
    done = term | trunc
    k = 1
    while not done.any():
        _, _, term, trunc, info = env.step(acts[k])
        done = term | trunc
        k += 1
    assert k <= 6
    assert all(o is not None for o in info["outcome"][done])
    episodes = info["episode_index"].copy()
    obs, rew, term, trunc, info = env.step(acts[k])
    assert np.all(rew[done] == 0.0) and not term[done].any() and not trunc[done].any()
    # world i plays episodes i, i + N, ...
    assert np.all(info["episode_index"][done] == episodes[done] + N)
    assert np.all(info["steps"][done] == 0) and np.all(info["time"][done] == 0.0)
    assert all(o is None for o in info["outcome"][done])
    assert env.observation_space.contains(obs)


def test_same_step_autoreset_final_obs() -> None:
    env = make(N, "learning.env.max_steps=5", autoreset_mode=AutoresetMode.SAME_STEP)
    env.reset(seed=0)
    for a in actions(env, 5):
        obs, _, term, trunc, info = env.step(a)
    assert trunc.all() or (term | trunc).all()
    assert info["_final_obs"].all() and info["final_obs"][0]["lidar"].shape == obs["lidar"][0].shape
    assert np.all(info["steps"] == 0) and np.all(info["final_info"]["steps"] == 5)
    assert np.all(info["episode_index"] == np.arange(N) + N)


def _forward_action(env: BatchedSocialNavEnv) -> int:
    table = env.decoder.table
    assert table is not None
    still = np.flatnonzero(table[:, 2] == 0.0)
    return int(still[np.argmax(table[still, 0])])


def test_driving_into_a_wall_collides_like_social_nav_env() -> None:
    over = (
        "task.obstacles={type: random, static: 0, dynamic: 0}",
        "learning.env.action_period=0.5",  # 5 sim steps per env step
        "learning.env.max_steps=80",
    )
    env = make(N, *over)
    env.reset(seed=4)
    fwd = _forward_action(env)
    single = SocialNavEnv(small_cfg(*over), robot=small_robot())
    checked = 0
    ended = np.zeros(N, dtype=bool)
    final: dict[int, tuple] = {}
    for _ in range(80):
        _, rew, term, trunc, info = env.step(np.full(N, fwd))
        for i in np.flatnonzero((term | trunc) & ~ended):
            final[int(i)] = (
                bool(term[i]), info["outcome"][i], float(rew[i]),
                {k: float(v[i]) for k, v in info["reward_terms"].items() if not k.startswith("_")},
            )
        ended |= term | trunc
        if ended.all():
            break
    for i, (term_i, outcome, _, terms) in final.items():
        single.reset(seed=4, options={"episode": i})
        while True:
            _, _, t, u, sinfo = single.step(fwd)
            if t or u:
                break
        if outcome != "collision" or sinfo["outcome"] != "collision":
            continue
        checked += 1
        assert term_i and t
        assert terms["collision"] == sinfo["reward_terms"]["collision"] != 0.0
    assert checked >= 1


def test_sb3_vec_env() -> None:
    pytest.importorskip("stable_baselines3")
    from arena.learn.sb3_vec import SB3VecEnv

    venv = SB3VecEnv(small_cfg("learning.env.max_steps=5"), robot=small_robot(), num_envs=3)
    venv.seed(1)
    obs = venv.reset()
    assert obs["lidar"].shape == (3, 24)
    for _ in range(5):
        obs, rew, done, infos = venv.step(np.zeros(3, dtype=np.int64))
    assert done.all() and rew.shape == (3,)
    assert all(i["TimeLimit.truncated"] for i in infos)
    assert infos[0]["terminal_observation"]["lidar"].shape == (24,)
    assert [i["episode_index"] for i in infos] == [0, 1, 2]  # the finished episodes
    assert venv.get_attr("num_envs") == [3, 3, 3]


def test_subgoal_first_observation_matches_single_env() -> None:
    sub = (
        "map={type: rosnav_indoor}",
        "task.obstacles={type: random, static: {min: 2, max: 2, models: [shelf]}, dynamic: 2}",
        "task.robots.min_goal_distance=6.0",
        "learning.env.observation.subgoal.enabled=true",
        "learning.env.observation.subgoal.horizon=3.0",
    )
    cfg = small_cfg(*sub)
    env = BatchedSocialNavEnv(cfg, robot=small_robot(), num_envs=3)
    single = SocialNavEnv(cfg, robot=small_robot())
    assert env.single_observation_space == single.observation_space
    assert env.single_action_space == single.action_space
    assert env.trackers is not None and len(env.trackers) == 3
    obs, info = env.reset(seed=5)
    assert env.observation_space.contains(obs)
    for i in range(3):
        s_obs, s_info = single.reset(seed=5, options={"episode": i})
        assert s_info["episode_index"] == info["episode_index"][i] == i
        np.testing.assert_allclose(obs["goal"][i], s_obs["goal"], atol=1e-5)
    # the subgoal is observed, not the final goal; rewards keep the final goal
    assert np.any(np.abs(obs["goal"][:, 0] - info["goal_distance"]) > 1e-3)
    for a in actions(env, 12):
        obs, _, _, _, info = env.step(a)
        assert env.observation_space.contains(obs)
        assert np.all(obs["goal"][:, 0] <= 3.0 + 1.0 + 1e-4)  # horizon + max_deviation


@pytest.mark.parametrize(
    "extra",
    [
        ("crowd={type: pysocial}", "pedestrians.social_states=true",
         "learning.env.observation.pedestrians.enabled=true"),
        ("crowd={type: orca}", "pedestrians.social_states=false", "robot=burger"),
    ],
)
def test_world_equals_social_nav_env_on_the_same_episode(extra) -> None:
    """One engine: world i plays episode i exactly as SocialNavEnv (observations, rewards)."""
    robot = None if any(e.startswith("robot=") for e in extra) else small_robot()
    cfg = small_cfg("learning.env.max_steps=200", *extra)
    env = BatchedSocialNavEnv(cfg, robot=robot, num_envs=3)
    obs, _ = env.reset(seed=9)
    acts = actions(env, 40, seed=3)
    peds_moved = False
    for i in range(3):
        single = SocialNavEnv(cfg, robot=robot)
        s_obs, _ = single.reset(seed=9, options={"episode": i})
        first = single.driver.state.agents.positions.copy()
        assert _equal({k: v[i] for k, v in obs.items()}, s_obs)
        b_env = BatchedSocialNavEnv(cfg, robot=robot, num_envs=3)
        b_obs, _ = b_env.reset(seed=9)
        for a in acts:
            b_obs, rew, term, trunc, _ = b_env.step(a)
            s_obs, s_rew, s_term, s_trunc, _ = single.step(a[i])
            assert _equal({k: v[i] for k, v in b_obs.items()}, s_obs)
            assert rew[i] == s_rew and term[i] == s_term and trunc[i] == s_trunc
            if s_term or s_trunc:
                break
        peds_moved |= bool(np.any(single.driver.state.agents.positions != first))
    assert peds_moved
