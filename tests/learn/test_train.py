"""arena.learn.train: PPO smoke run, checkpoints, resume, curriculum logic, CLI errors."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("stable_baselines3")
pytest.importorskip("tensorboard")

from arena.core.errors import ArenaError, ConfigError
from arena.learn.train import (
    CurriculumController,
    LinearSchedule,
    export_checkpoint,
    load_training,
    read_run,
    train,
)
from arena.learn.train_config import TrainSettings
from arena.tasks.modules.staged import Staged
from tests.learn.helpers import small_cfg, small_robot

TINY = {
    "ppo": {"batch_size": 32, "minibatch_size": 16, "n_epochs": 1,
            "net_arch": {"pi": [16], "vf": [16]}},
    "train": {"total_steps": 64, "n_envs": 2, "vec_env": "dummy", "checkpoint_every": 32,
              "eval": {"episodes": 1, "every": 32}},
}


def _settings(**train):
    data = json.loads(json.dumps(TINY))
    data["train"].update(train)
    return TrainSettings.model_validate(data)


def test_smoke_run_checkpoint_tensorboard_and_resume(tmp_path):
    cfg = small_cfg("task.obstacles={type: random, static: 0, dynamic: 1}")
    run = tmp_path / "run"
    res = train(cfg, _settings(), run, robot=small_robot(8))
    assert res.steps == 64
    man = read_run(run)
    assert man["steps_done"] == 64 and man["seed"] == cfg.seed
    assert (run / man["checkpoint"] / "model.zip").is_file()
    assert (run / man["checkpoint"] / "vecnormalize.pkl").is_file()
    assert (run / "checkpoints" / "step_32" / "model.zip").is_file()
    assert list((run / "tb").rglob("events.out.tfevents.*"))
    assert (run / "policy.npz").is_file()
    # the last checkpoint exported on its own gives the run's final policy
    exported = np.load(export_checkpoint(run / man["checkpoint"], tmp_path / "last.npz"))
    final = np.load(run / "policy.npz")
    arrays = [k for k in final.files if k != "meta"]
    assert any(k.startswith("w") for k in arrays)
    for k in arrays:
        assert np.array_equal(exported[k], final[k]), k
    assert (run / "checkpoints" / "step_32" / "policy.npz") == export_checkpoint(
        run / "checkpoints" / "step_32")
    with pytest.raises(ArenaError, match=r"no model\.zip"):
        export_checkpoint(run)
    with pytest.raises(ArenaError, match="already holds a run"):
        train(cfg, _settings(), run, robot=small_robot(8))
    bad = TrainSettings.model_validate({**TINY, "ppo": {**TINY["ppo"], "n_epochs": 2}})
    with pytest.raises(ArenaError, match=r"cannot resume: settings key 'ppo\.n_epochs'"):
        train(cfg, bad, run, resume=True, robot=small_robot(8))
    copy = tmp_path / "copy"  # a copied run resumes and logs into its own folder
    shutil.copytree(run, copy)
    shutil.rmtree(copy / "tb")
    res2 = train(cfg, _settings(total_steps=128), copy, resume=True, robot=small_robot(8))
    assert res2.steps == 128
    assert read_run(copy)["steps_done"] == 128
    assert (copy / "checkpoints" / "step_128" / "model.zip").is_file()
    assert list((copy / "tb").rglob("events.out.tfevents.*"))
    assert read_run(run)["steps_done"] == 64 and not (run / "checkpoints" / "step_128").exists()


def test_curriculum_run_applies_stage(tmp_path):
    cfg = small_cfg("task.modules=[{type: staged, curriculum: default}]")
    # the default curriculum's stages switch to barn maps: keep them (fast) and only check the
    # stage bookkeeping, with a stub evaluator that always succeeds
    seen = []
    res = train(cfg, _settings(total_steps=64), tmp_path / "run", robot=small_robot(8),
                evaluate=lambda: 1.0, on_eval=seen.append)
    assert [s.stage for s in seen] == [1, 2]
    assert res.stage == 2 and read_run(tmp_path / "run")["stage"] == 2


class _Stub:
    def __init__(self, rates):
        self.rates = list(rates)

    def __call__(self):
        return self.rates.pop(0)


def test_curriculum_controller_promotes_demotes_and_stops():
    staged = Staged(Staged.Params(curriculum="default"))
    n = staged.num_stages
    applied = []
    ctl = CurriculumController(
        staged, _Stub([0.9, 0.95, 0.7, 0.65, 0.1, 0.3]), applied.append, stop_success=0.98
    )
    states = [ctl.step() for _ in range(6)]
    assert [s.change for s in states] == [1, 1, 0, -1, -1, 0]
    assert [s.stage for s in states] == [1, 2, 2, 1, 0, 0]
    assert applied == [1, 2, 1, 0]
    assert not any(s.stop for s in states)
    staged.set_stage(n - 1)
    ctl.evaluate = _Stub([0.97, 0.98])
    assert not ctl.step().stop
    assert ctl.step().stop


def test_linear_schedule():
    s = LinearSchedule(1e-3, 1e-4)
    assert s(1.0) == pytest.approx(1e-3) and s(0.0) == pytest.approx(1e-4)


def test_load_training_reads_blocks(tmp_path):
    f = tmp_path / "exp.yaml"
    f.write_text("seed: 3\nlearning:\n  env: {max_steps: 30}\n  ppo: {n_epochs: 5}\n")
    cfg, s = load_training(f, ["learning.train.n_envs=2", "learning.ppo.gamma=0.9"])
    assert cfg.seed == 3 and cfg.learning.env.max_steps == 30
    assert s.ppo.n_epochs == 5 and s.ppo.gamma == 0.9 and s.train.n_envs == 2
    with pytest.raises(ConfigError, match=r"learning\.ppo\.bogus"):
        load_training(f, ["learning.ppo.bogus=1"])
    with pytest.raises(ConfigError, match="not a multiple of n_envs"):
        train(cfg, TrainSettings.model_validate({"ppo": {"batch_size": 33, "minibatch_size": 8},
                                                 "train": {"n_envs": 2}}), tmp_path / "r")


def test_cli_bad_config_is_one_line(tmp_path):
    f = tmp_path / "exp.yaml"
    f.write_text("learning:\n  ppo: {clip_range: -1}\n")
    res = subprocess.run(
        [sys.executable, "-m", "arena.cli", "train", str(f), "-o", str(tmp_path / "r")],
        capture_output=True, text=True, check=False,
    )
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "learning.ppo.clip_range" in lines[0], res.stderr


def test_batched_vec_env_run_with_real_evaluator(tmp_path):
    from arena.learn.policy import NumpyPolicy
    from arena.learn.sb3_vec import SB3VecEnv
    from arena.learn.train import make_vec_env

    cfg = small_cfg("task.modules=[{type: staged, curriculum: default}]",
                    "learning.env.observation.subgoal.enabled=true")
    venv = make_vec_env(cfg, 4, "batched", small_robot(8), seed=11)
    assert isinstance(venv, SB3VecEnv) and venv.num_envs == 4
    assert venv.env_method("set_stage", 1) == [1] * 4 and venv.env.get_stage() == 1
    venv.close()
    seen = []
    res = train(cfg, _settings(total_steps=64, n_envs=4, vec_env="batched"), tmp_path / "run",
                robot=small_robot(8), on_eval=seen.append)  # evaluation: SocialNavEnv
    assert res.steps == 64 and seen and 0.0 <= seen[0].success_rate <= 1.0
    man = read_run(tmp_path / "run")
    assert man["steps_done"] == 64 and man["settings"]["train"]["vec_env"] == "batched"
    pol = NumpyPolicy.load(res.policy)
    assert len(pol.meta["laser"]["angles"]) == 8


@pytest.mark.parametrize("kind", ["dummy", "subproc"])
def test_seeded_vec_envs_play_different_episodes(kind):
    """Env k of a seeded DummyVecEnv / SubprocVecEnv starts at episode 0 of seed + k."""
    from arena.learn.env import SocialNavEnv
    from arena.learn.train import make_vec_env

    cfg = small_cfg()
    venv = make_vec_env(cfg, 3, kind, small_robot(8), seed=21)
    first = venv.reset()
    venv.close()
    goals = first["goal"]
    assert len({tuple(np.round(g, 5)) for g in goals}) == 3  # not three copies of one world
    for k in range(3):
        own, _ = SocialNavEnv(cfg, robot=small_robot(8)).reset(seed=21 + k)
        np.testing.assert_array_equal(own["goal"], goals[k])


def _state(ckpt):
    from stable_baselines3 import PPO

    pol = PPO.load(ckpt / "model.zip", device="cpu").policy
    from arena.learn.train import actor_parameters

    actor = {id(p) for p in actor_parameters(pol)}
    named = dict(pol.named_parameters())
    return ({k: v.detach().clone() for k, v in named.items() if id(v) in actor},
            {k: v.detach().clone() for k, v in named.items() if id(v) not in actor})


def test_critic_warmup_freezes_the_actor_then_releases_it(tmp_path):
    cfg = small_cfg("task.obstacles={type: random, static: 0, dynamic: 1}",
                    "learning.env.action={type: continuous, normalize: true}")
    data = json.loads(json.dumps(TINY))
    data["ppo"].update(critic_warmup=64, target_kl=0.05, ent_coef=0.01)
    data["train"].update(total_steps=96)
    settings = TrainSettings.model_validate(data)
    run = tmp_path / "run"
    train(cfg, settings, run, robot=small_robot(8))
    from stable_baselines3 import PPO

    assert PPO.load(run / "checkpoints/step_96/model.zip", device="cpu").target_kl == 0.05
    a32, c32 = _state(run / "checkpoints/step_32")
    a64, c64 = _state(run / "checkpoints/step_64")
    a96, _ = _state(run / "checkpoints/step_96")
    assert "log_std" in a32 and any("action_net" in k for k in a32)
    assert any("value_net" in k for k in c32)
    # updates after the rollouts ending at steps 32 and 64 train the critic only
    for k in a32:
        assert torch_equal(a32[k], a64[k]), k
    assert any(not torch_equal(c32[k], c64[k]) for k in c32)
    # the update after step 96 trains the actor too
    assert any(not torch_equal(a64[k], a96[k]) for k in a64)


def torch_equal(a, b):
    return bool((a == b).all())


def test_multi_robot_only_settings_need_the_multi_robot_env():
    with pytest.raises(ValueError, match="respawn only applies to vec_env multi_robot"):
        TrainSettings.model_validate({"train": {"respawn": True, "vec_env": "dummy"}})
    with pytest.raises(ValueError, match="robots_per_world only applies"):
        TrainSettings.model_validate({"train": {"robots_per_world": [2], "vec_env": "dummy"}})
    ok = TrainSettings.model_validate(
        {"train": {"respawn": True, "vec_env": "multi_robot", "n_envs": 3,
                   "robots_per_world": [1, 2]}})
    assert ok.train.respawn


def test_keep_best_keeps_the_best_evaluated_checkpoint_and_resumes_it(tmp_path):
    from stable_baselines3 import PPO

    cfg = small_cfg("task.obstacles={type: random, static: 0, dynamic: 1}")
    data = json.loads(json.dumps(TINY))
    data["train"].update(total_steps=128, eval={"episodes": 1, "every": 32, "keep_best": True})
    settings = TrainSettings.model_validate(data)
    rates = iter([0.2, 0.6, 0.4, 0.6, 0.9])
    run = tmp_path / "run"
    train(cfg, settings, run, robot=small_robot(8), evaluate=lambda: next(rates))
    best = read_run(run)["best"]
    # evaluations at steps 32, 64, 96 (between rollouts): 0.2, 0.6, 0.4 -> step 64
    assert best == {"step": 64, "success_rate": 0.6, "path": "best"}
    assert (run / "best" / "vecnormalize.pkl").is_file() and (run / "best" / "policy.npz").is_file()
    kept = PPO.load(run / "best" / "model.zip", device="cpu").policy.state_dict()
    same = PPO.load(run / "checkpoints" / "step_64" / "model.zip", device="cpu").policy.state_dict()
    assert all(bool((kept[k] == same[k]).all()) for k in kept)
    # resumed from 128: an equal rate (0.6 at 160) does not replace it, a higher one (0.9 at
    # 192) does
    longer = settings.model_copy(update={"train": settings.train.model_copy(
        update={"total_steps": 224})})
    train(cfg, longer, run, resume=True, robot=small_robot(8), evaluate=lambda: next(rates))
    assert read_run(run)["best"] == {"step": 192, "success_rate": 0.9, "path": "best"}
    staged_cfg = small_cfg(
        "task.obstacles={type: random, static: 0, dynamic: 1}",
        "task.modules=[{type: staged, curriculum: default}]")
    with pytest.raises(ConfigError, match="keep_best"):
        train(staged_cfg, settings, tmp_path / "staged", robot=small_robot(8),
              evaluate=lambda: 0.5)
