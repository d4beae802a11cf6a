"""export_policy / NumpyPolicy: numpy inference equals SB3's deterministic predict."""

from __future__ import annotations

import sys
from typing import Any

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("stable_baselines3")
gym = pytest.importorskip("gymnasium")

from gymnasium import spaces  # noqa: E402
from stable_baselines3 import PPO  # noqa: E402
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize  # noqa: E402

from arena.core.errors import ConfigError  # noqa: E402
from arena.learn.policy import NumpyPolicy, export_policy  # noqa: E402

DICT_OBS = spaces.Dict(
    {
        "lidar": spaces.Box(0.0, 10.0, (2, 12), np.float32),
        "goal": spaces.Box(
            np.array([0.0, -np.pi], np.float32), np.array([30.0, np.pi], np.float32)
        ),
        "last_action": spaces.Box(-1.0, 1.0, (3,), np.float32),
    }
)
FLAT_OBS = spaces.Box(-5.0, 5.0, (17,), np.float32)
DISCRETE = spaces.Discrete(7)
BOX = spaces.Box(np.array([-0.5, -1.0], np.float32), np.array([1.0, 1.0], np.float32))


class _SpaceEnv(gym.Env[Any, Any]):
    def __init__(self, obs_space: spaces.Space[Any], act_space: spaces.Space[Any]) -> None:
        self.observation_space = obs_space
        self.action_space = act_space

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return self.observation_space.sample(), {}

    def step(self, action):
        return self.observation_space.sample(), 0.0, False, False, {}


def _model(obs_space, act_space, activation="relu"):
    import torch.nn as nn

    venv = VecNormalize(
        DummyVecEnv([lambda: _SpaceEnv(obs_space, act_space)]), norm_reward=False, clip_obs=3.0
    )
    policy = "MultiInputPolicy" if isinstance(obs_space, spaces.Dict) else "MlpPolicy"
    act = {"relu": nn.ReLU, "tanh": nn.Tanh}[activation]
    model = PPO(policy, venv, n_steps=8, batch_size=8, seed=1, device="cpu",
                policy_kwargs={"net_arch": {"pi": [32, 16], "vf": [8]}, "activation_fn": act})
    # non-trivial normalisation statistics
    rng = np.random.default_rng(0)
    obs_space.seed(2)
    batch = [obs_space.sample() for _ in range(50)]
    if isinstance(obs_space, spaces.Dict):
        for k in obs_space:
            venv.obs_rms[k].update(np.stack([b[k] for b in batch]) * rng.uniform(0.5, 2.0))
    else:
        venv.obs_rms.update(np.stack(batch) + rng.normal(size=(50, 17)))
    # give the Gaussian means a spread larger than the action box so that clipping matters
    with __import__("torch").no_grad():
        model.policy.action_net.weight.mul_(20.0)
    return model, venv


@pytest.mark.parametrize("obs_kind", ["dict", "flat"])
@pytest.mark.parametrize("act_kind", ["discrete", "box"])
def test_numpy_policy_matches_sb3(tmp_path, obs_kind, act_kind):
    obs_space = DICT_OBS if obs_kind == "dict" else FLAT_OBS
    act_space = DISCRETE if act_kind == "discrete" else BOX
    model, venv = _model(obs_space, act_space, "tanh" if obs_kind == "flat" else "relu")
    path = export_policy(model, venv, tmp_path / "p.npz")
    pol = NumpyPolicy.load(path)
    venv.training = False
    obs_space.seed(5)
    for _ in range(100):
        o = obs_space.sample()
        if obs_kind == "dict":
            expect, _ = model.predict(venv.normalize_obs({k: v[None] for k, v in o.items()}),
                                      deterministic=True)
        else:
            expect, _ = model.predict(venv.normalize_obs(o[None]), deterministic=True)
        got = pol.act(o)
        if act_kind == "discrete":
            assert got == int(expect[0])
        else:
            np.testing.assert_allclose(got, expect[0], rtol=1e-5, atol=1e-5)


def test_batch_and_errors(tmp_path):
    model, _ = _model(DICT_OBS, DISCRETE)
    pol = NumpyPolicy.load(export_policy(model, None, tmp_path / "p.npz"))
    DICT_OBS.seed(0)
    obs = [DICT_OBS.sample() for _ in range(4)]
    batch = {k: np.stack([o[k] for o in obs]) for k in DICT_OBS}
    np.testing.assert_array_equal(pol.act(batch), [pol.act(o) for o in obs])
    with pytest.raises(ValueError, match="lacks keys"):
        pol.act({"lidar": obs[0]["lidar"]})
    with pytest.raises(ConfigError, match="no policy file"):
        NumpyPolicy.load(tmp_path / "missing.npz")
    with pytest.raises(ConfigError, match="no action decoding"):
        pol.command(0)


def test_numpy_policy_needs_no_torch(tmp_path):
    model, venv = _model(FLAT_OBS, DISCRETE)
    path = export_policy(model, venv, tmp_path / "p.npz")
    import subprocess

    code = (
        "import sys; sys.modules['torch'] = None\n"
        "from arena.learn.policy import NumpyPolicy\n"
        f"p = NumpyPolicy.load({str(path)!r}); print(p.act([0.0] * 17))"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert res.returncode == 0, res.stderr


@pytest.mark.parametrize("action", ["discrete", "continuous"])
def test_random_policy_loads_and_acts(tmp_path, action):
    from arena.learn.config import EnvConfig
    from arena.learn.env import SocialNavEnv
    from arena.learn.policy import random_policy, write_random_policy
    from tests.learn.helpers import small_cfg, small_robot

    cfg = small_cfg(f"learning.env.action.type={action}")
    robot = small_robot(12)
    env = SocialNavEnv(cfg, robot=robot)
    obs, _ = env.reset(seed=0)
    path = write_random_policy(tmp_path / "r.npz", cfg.learning.env, robot, rng=1)
    pol = NumpyPolicy.load(path)
    assert pol.meta["random"] and len(pol.meta["laser"]["angles"]) == 12
    assert set(pol.keys) == set(env.observation_space.spaces)
    for _ in range(5):
        a = pol.act(obs)
        assert env.action_space.contains(np.asarray(a, env.action_space.dtype)
                                         if action == "continuous" else a)
        assert pol.command(a).shape == (3,)
        obs, *_ = env.step(a)
    mem = random_policy(cfg.learning.env, robot, rng=1)
    np.testing.assert_array_equal(mem.logits(obs), pol.logits(obs))
    flat = random_policy(EnvConfig.model_validate({"observation": {"flatten": True}}), robot,
                         hidden=(8,), rng=np.random.default_rng(0))
    assert not flat.is_dict and len(flat._w) == 2


CONV_OBS = spaces.Dict(
    {
        "lidar": spaces.Box(0.0, 10.0, (3, 40), np.float32),
        "goal": spaces.Box(
            np.array([0.0, -np.pi], np.float32), np.array([30.0, np.pi], np.float32)
        ),
        "velocity": spaces.Box(-1.0, 1.0, (3,), np.float32),
    }
)


DRLVO_OBS = spaces.Dict(
    {
        "lidar": spaces.Box(0.0, 12.0, (3, 24), np.float32),
        "semantic": spaces.Box(-2.0, 2.0, (2, 11, 11), np.float32),
        "goal": spaces.Box(
            np.array([0.0, -np.pi], np.float32), np.array([30.0, np.pi], np.float32)
        ),
    }
)
_FX = {
    "rlca_conv": (CONV_OBS, {"filters": (4, 5), "kernels": (5, 3), "strides": (2, 2), "fc": 12},
                  None),
    "drlvo_cnn": (DRLVO_OBS, {"config": {
        "scan_clip": 8.0, "scan_bins": 8, "scan_filters": [4, 5], "scan_kernels": [3, 2],
        "scan_strides": [2, 1], "map_filters": [3, 4], "map_kernels": [3, 2],
        "map_strides": [2, 1], "fc": 12}}, ["goal"]),
}


@pytest.mark.parametrize("extractor", sorted(_FX))
@pytest.mark.parametrize("shared", [True, False])
@pytest.mark.parametrize("act_kind", ["discrete", "box"])
def test_conv_policy_matches_sb3(tmp_path, extractor, shared, act_kind):
    """The conv extractors export (format 2) and numpy equals predict(deterministic)."""
    from arena.learn.extractors import DrlvoExtractor, RLCAConvExtractor

    space, kwargs, norm_keys = _FX[extractor]
    act_space = DISCRETE if act_kind == "discrete" else BOX
    venv = VecNormalize(
        DummyVecEnv([lambda: _SpaceEnv(space, act_space)]), norm_reward=False, clip_obs=3.0,
        norm_obs_keys=norm_keys,
    )
    cls = RLCAConvExtractor if extractor == "rlca_conv" else DrlvoExtractor
    model = PPO("MultiInputPolicy", venv, n_steps=8, batch_size=8, seed=3, device="cpu",
                policy_kwargs={
                    "net_arch": {"pi": [16], "vf": [8]},
                    "share_features_extractor": shared,
                    "features_extractor_class": cls,
                    "features_extractor_kwargs": kwargs,
                })
    rng = np.random.default_rng(0)
    space.seed(2)
    batch = [space.sample() for _ in range(50)]
    for k in venv.norm_obs_keys:
        venv.obs_rms[k].update(np.stack([b[k] for b in batch]) * rng.uniform(0.5, 2.0))
    with __import__("torch").no_grad():
        model.policy.action_net.weight.mul_(20.0)
    pol = NumpyPolicy.load(export_policy(model, venv, tmp_path / "c.npz"))
    assert pol.meta["format"] == 2 and pol.meta["extractor"]["type"] == extractor
    assert sorted(pol.meta["normalize"]["keys"]) == sorted(norm_keys or space.spaces)
    venv.training = False
    space.seed(5)
    obs = [space.sample() for _ in range(64)]
    stacked = {k: np.stack([o[k] for o in obs]) for k in space.spaces}
    expect, _ = model.predict(venv.normalize_obs(stacked), deterministic=True)
    got = pol.act(stacked)
    if act_kind == "discrete":
        np.testing.assert_array_equal(got, expect)
    else:
        np.testing.assert_allclose(got, expect, rtol=1e-5, atol=1e-5)
    single = pol.act(obs[0])
    np.testing.assert_allclose(np.asarray(single), np.asarray(expect[0]), atol=1e-5)


def test_format_1_files_still_load(tmp_path):
    model, venv = _model(DICT_OBS, BOX)
    pol = NumpyPolicy.load(export_policy(model, venv, tmp_path / "p.npz"))
    assert pol.meta["format"] == 1 and pol.extractor is None


def test_files_with_a_1_by_beams_lidar_read_one_scan(tmp_path):
    """Files written when one scan was shaped (1, beams) act on today's (beams,) scans."""
    import json

    from arena.learn.env import SocialNavEnv
    from arena.learn.policy import write_random_policy
    from tests.learn.helpers import small_cfg, small_robot

    cfg, robot = small_cfg(), small_robot(12)
    obs, _ = SocialNavEnv(cfg, robot=robot).reset(seed=0)
    assert obs["lidar"].shape == (12,)
    path = write_random_policy(tmp_path / "new.npz", cfg.learning.env, robot, rng=3)
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["meta"]))
    assert meta["obs"]["shapes"]["lidar"] == [12]
    meta["obs"]["shapes"]["lidar"] = [1, 12]  # the older layout
    for k in ("low/lidar", "high/lidar", "mean/lidar", "var/lidar"):
        if k in arrays:
            arrays[k] = arrays[k].reshape(1, 12)
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez(tmp_path / "old.npz", **arrays)
    old, new = NumpyPolicy.load(tmp_path / "old.npz"), NumpyPolicy.load(path)
    assert old.shapes["lidar"] == (12,)
    np.testing.assert_array_equal(old.logits(obs), new.logits(obs))
