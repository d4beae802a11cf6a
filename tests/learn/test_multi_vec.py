"""MultiRobotVecEnv (multi-robot PPO slots) and a multi-robot PPO smoke run with rlca_conv."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("stable_baselines3")
pytest.importorskip("tensorboard")

from arena.learn.multi import MultiRobotEnv
from arena.learn.multi_vec import MultiRobotVecEnv
from arena.learn.policy import NumpyPolicy, laser_meta
from arena.learn.train import read_run, train
from arena.learn.train_config import TrainSettings
from tests.learn.helpers import small_cfg, small_robot

RLCA_OBS = (
    "learning.env.observation={lidar: true, goal: true, last_action: false, velocity: true, "
    "laser_stack: 3}",
    "learning.env.action={type: continuous, normalize: true}",
    "learning.env.reward=rlca",
)


def _venv(max_steps: int = 40) -> MultiRobotVecEnv:
    cfg = small_cfg(*RLCA_OBS, f"learning.env.max_steps={max_steps}")
    return MultiRobotVecEnv(cfg, [2, 3], robot=small_robot(16))


def _rollout(venv: MultiRobotVecEnv, seed: int, steps: int):
    venv.seed(seed)
    obs = venv.reset()
    rng = np.random.default_rng(0)
    out = [obs]
    for _ in range(steps):
        a = rng.uniform(-1, 1, (venv.num_envs, 2)).astype(np.float32)
        out.append(venv.step(a))
    return out


def test_slots_shapes_and_autoreset():
    venv = _venv(max_steps=6)
    assert venv.num_envs == 5
    obs = _rollout(venv, 1, 0)[0]
    assert obs["lidar"].shape == (5, 3, 16) and obs["goal"].shape == (5, 2)
    assert obs["velocity"].shape == (5, 3)
    assert venv.observation_space.contains({k: v[0] for k, v in obs.items()})
    steps = _rollout(venv, 1, 8)[1:]
    for k, (o, r, d, infos) in enumerate(steps):
        assert r.shape == (5,) and d.shape == (5,) and len(infos) == 5
        for sl in venv.slices:  # a world ends for all of its robots at once
            assert d[sl].all() or not d[sl].any()
        for j in np.flatnonzero(d):
            assert "terminal_observation" in infos[j] and "episode" in infos[j]
            assert isinstance(infos[j]["TimeLimit.truncated"], bool)
        if k == 5:  # the step limit (6 env steps) truncates every world: all restart
            assert d.all() and all(i["TimeLimit.truncated"] for i in infos)
            np.testing.assert_array_equal(o["velocity"], 0.0)  # new episode, at rest


def test_first_finisher_ends_its_world():
    venv = _venv(max_steps=200)
    venv.seed(3)
    venv.reset()
    # put robot 0 of world 0 on its goal (a test-only write into native2d's pose array): it
    # succeeds, robot 1 of the same world is cut (truncated), world 1 goes on
    d = venv.worlds[0].driver
    d.backend.engine.poses[0, :2] = d.goals[0, :2]
    _, _, dones, infos = venv.step(np.zeros((5, 2), np.float32))
    assert dones[0] and dones[1] and not dones[2:].any()
    assert infos[0]["outcome"] == "success" and not infos[0]["TimeLimit.truncated"]
    assert infos[1]["outcome"] == "cut" and infos[1]["TimeLimit.truncated"]
    assert infos[0]["is_success"] and not infos[1]["is_success"]


def test_respawn_restarts_only_the_finisher():
    cfg = small_cfg(*RLCA_OBS, "learning.env.max_steps=200", "task.robots.min_goal_distance=2")
    venv = MultiRobotVecEnv(cfg, [2, 3], robot=small_robot(16), respawn=True)
    venv.seed(3)
    venv.reset()
    d = venv.worlds[0].driver
    others = d.state.robots.poses[1].copy()
    old_goal = d.goals[0].copy()
    d.backend.engine.poses[0, :2] = d.goals[0, :2]  # robot 0 of world 0 arrives (test-only write)
    obs, _, dones, infos = venv.step(np.zeros((5, 2), np.float32))
    # only robot 0's slot ends; its world goes on, robot 1 keeps driving (it stood still)
    assert dones.tolist() == [True, False, False, False, False]
    assert infos[0]["outcome"] == "success" and infos[0]["is_success"]
    assert "terminal_observation" in infos[0] and "episode" in infos[0]
    assert venv.worlds[0].agents == ["robot_0", "robot_1"]
    np.testing.assert_allclose(d.state.robots.poses[1], others, atol=1e-12)
    # robot 0 has a new start and goal: min_goal_distance apart, clear of robot 1
    start, goal = d.state.robots.poses[0], d.goals[0]
    assert not np.allclose(goal, old_goal)
    assert np.hypot(*(goal[:2] - start[:2])) >= 2.0
    assert np.hypot(*(start[:2] - others[:2])) >= 2 * d.radius
    assert d.robot_steps.tolist() == [0, 1] and d.steps == 1
    # its new observation: fresh laser stack, zero velocity, the new goal
    np.testing.assert_array_equal(obs["velocity"][0], 0.0)
    np.testing.assert_array_equal(obs["lidar"][0, 0], obs["lidar"][0, 2])
    np.testing.assert_array_equal(obs["lidar"][0, 2], d.state.robots.scans[0].astype(np.float32))
    # robot 0's next episode counts from its respawn
    _, _, dones, infos = venv.step(np.zeros((5, 2), np.float32))
    assert not dones.any()
    # the world's time limit ends every robot's episode at once and restarts the world
    venv2 = MultiRobotVecEnv(small_cfg(*RLCA_OBS, "task.timeout=0.6"), [2], robot=small_robot(16),
                             respawn=True)
    venv2.seed(1)
    venv2.reset()
    ends = [venv2.step(np.zeros((2, 2), np.float32))[2].tolist() for _ in range(6)]  # 0.1 s
    assert ends == [[False, False]] * 5 + [[True, True]]
    assert venv2.worlds[0].driver.steps == 0  # the world restarted


def test_respawn_rollouts_are_reproducible():
    cfg = small_cfg(*RLCA_OBS, "learning.env.max_steps=200", "task.robots.min_goal_distance=1")

    def run():
        venv = MultiRobotVecEnv(cfg, [3], robot=small_robot(16), respawn=True)
        out = _rollout(venv, 5, 60)
        n_done = sum(int(s[2].sum()) for s in out[1:])
        return out, n_done

    a, n = run()
    b, _ = run()
    assert n > 0  # robots finished (collisions with random actions) and respawned
    for x, y in zip(a[1:], b[1:], strict=True):
        for k in x[0]:
            np.testing.assert_array_equal(x[0][k], y[0][k])
        np.testing.assert_array_equal(x[1], y[1])
        np.testing.assert_array_equal(x[2], y[2])


def test_same_seed_same_rollout():
    a = _rollout(_venv(), 7, 12)
    b = _rollout(_venv(), 7, 12)
    for x, y in zip(a[1:], b[1:], strict=True):
        for k in x[0]:
            np.testing.assert_array_equal(x[0][k], y[0][k])
        np.testing.assert_array_equal(x[1], y[1])
        np.testing.assert_array_equal(x[2], y[2])


def test_robots_see_each_other_on_the_lidar():
    """native2d: another robot is an obstacle of the laser (a return short of its centre)."""
    cfg = small_cfg("task.obstacles={type: random, static: 0, dynamic: 0}",
                    "map={type: empty, width: 16, height: 16, resolution: 0.1}")
    robot = small_robot(360)
    env = MultiRobotEnv(cfg, n_robots=2, robot=robot)
    angles = np.asarray(laser_meta(robot.laser)["angles"])
    seen = 0
    for seed in range(4):
        env.reset(seed=seed)
        st = env.driver.state
        p = st.robots.poses
        for i, j in ((0, 1), (1, 0)):
            dx, dy = p[j, :2] - p[i, :2]
            dist = float(np.hypot(dx, dy))
            bearing = (np.arctan2(dy, dx) - p[i, 2] + np.pi) % (2 * np.pi) - np.pi
            gap = np.abs((angles - bearing + np.pi) % (2 * np.pi) - np.pi)
            if gap.min() > 0.01:
                continue  # outside the laser's 270°
            rng = float(st.robots.scans[i][int(np.argmin(gap))])
            assert dist - robot.radius - 0.1 < rng < dist, (seed, i, rng, dist)
            seen += 1
    assert seen >= 3


TINY = {
    "ppo": {"batch_size": 32, "minibatch_size": 16, "n_epochs": 1,
            "net_arch": {"pi": [16], "vf": [16]}, "share_features_extractor": False,
            "extractor": {"type": "rlca_conv", "filters": [4, 4], "fc": 16}},
    "train": {"total_steps": 64, "n_envs": 4, "vec_env": "multi_robot",
              "robots_per_world": [2, 2], "checkpoint_every": 32,
              "eval": {"episodes": 1, "every": 32}},
}


def test_multi_robot_ppo_smoke_run_with_rlca_extractor_and_resume(tmp_path):
    cfg = small_cfg(*RLCA_OBS)
    robot = small_robot(16)
    run = tmp_path / "run"
    res = train(cfg, TrainSettings.model_validate(TINY), run, robot=robot)
    assert res.steps == 64
    man = read_run(run)
    assert man["steps_done"] == 64
    pol = NumpyPolicy.load(run / "policy.npz")
    assert pol.meta["extractor"]["type"] == "rlca_conv"
    assert set(pol.keys) == {"lidar", "goal", "velocity"}
    data = json.loads(json.dumps(TINY))
    data["train"]["total_steps"] = 128
    res2 = train(cfg, TrainSettings.model_validate(data), run, resume=True, robot=robot)
    assert res2.steps == 128 and read_run(run)["steps_done"] == 128


def test_respawn_needs_several_robots():
    from arena.learn.env import SocialNavEnv

    env = SocialNavEnv(small_cfg(*RLCA_OBS), robot=small_robot(16))
    env.reset(seed=0)
    with pytest.raises(ValueError, match="multi-robot worlds"):
        env.driver.respawn(0, 2.0, 0.25)
