"""PPO training of ``arena/SocialNav-v0`` with Stable-Baselines3 (arena_specs §8).

:func:`train` runs (or resumes) one training run into a run folder::

    RUN/run.json                     config, settings, seed, steps done, curriculum stage,
                                     latest checkpoint, throughput
    RUN/checkpoints/step_<N>/        model.zip + vecnormalize.pkl, every checkpoint_every steps
    RUN/tb/PPO_1/                    TensorBoard events (SB3's scalars + eval/success_rate,
                                     curriculum/stage)
    RUN/policy.npz                   the final actor for numpy inference (arena.learn.policy)
    RUN/best/                        eval.keep_best: model, statistics and policy.npz of the
                                     best evaluated checkpoint (run.json["best"]: step, rate)

Training uses ``n_envs`` :class:`~arena.learn.env.SocialNavEnv` instances seeded ``seed + k``
(``DummyVecEnv`` or ``SubprocVecEnv``; ``batched``: one batched simulator; ``multi_robot``:
:class:`~arena.learn.multi_vec.MultiRobotVecEnv`, one slot per robot of ``robots_per_world``
worlds, so several robots share one world and the policy's parameters) under SB3's
``VecNormalize`` (observations normalised,
rewards not, clip 30; Arena's setting). ``MultiInputPolicy`` serves Dict observations,
``MlpPolicy`` flat ones; ``learning.ppo.extractor`` picks the feature extractor
(:mod:`arena.learn.extractors`, e.g. Long et al.'s ``rlca_conv`` scan encoder).

Curriculum: when ``task.modules`` has a ``staged`` module, a separate evaluation env runs
``eval.episodes`` deterministic episodes every ``eval.every`` env steps; the module's
:meth:`~arena.tasks.modules.staged.Staged.report` (its curriculum's thresholds, Arena 0.90 /
0.65) promotes or demotes, and the new stage is applied to every training env. Training stops
at the last stage once the success rate reaches ``curriculum.stop_success`` (Arena: 0.98).

Best checkpoint: with ``eval.keep_best`` (and no ``staged`` module) the same deterministic
evaluation runs every ``eval.every`` steps, between rollouts, and the model with the highest
success rate so far is kept in ``RUN/best``; a resumed run keeps comparing with the recorded
best. PPO can make a warm-started policy worse (``rlca``: 100 % → 65 % on validation
episodes within 230 k steps), so the last checkpoint is not always the one to ship.

Resume: ``resume=True`` loads the latest checkpoint of the run folder and continues to
``total_steps`` with the recorded config and settings; only ``total_steps`` may differ. The
training envs are reseeded ``seed + steps_done + k`` (their episode streams continue from new
seeds), so a resumed run is not bit-identical to an uninterrupted one.

Settings come from ``learning.ppo`` / ``learning.train`` (:mod:`arena.learn.train_config`).
The run folder and configs are :mod:`arena.learn.train_run`, the environments
:mod:`arena.learn.train_envs`, evaluation, curriculum and callbacks
:mod:`arena.learn.train_callbacks`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from arena import __version__
from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError, ConfigError
from arena.learn.train_callbacks import (
    CurriculumController,
    CurriculumState,
    Evaluator,
    LinearSchedule,
    TrainerState,
    actor_parameters,
    callback_classes,
)
from arena.learn.train_config import TrainSettings
from arena.learn.train_envs import make_env_fn, make_vec_env, staged_spec
from arena.learn.train_run import (
    BEST,
    CHECKPOINTS,
    MANIFEST,
    TRAIN_CONFIGS_DIR,
    check_resume,
    load_training,
    packaged_training_configs,
    read_run,
    require_sb3,
    resolve_training_config,
    settings_of,
    write_json,
)
from arena.robots.model import RobotModel

# The training API, from here and the modules it is split into (run folder, envs, callbacks).
__all__ = [
    "BEST",
    "CHECKPOINTS",
    "MANIFEST",
    "TRAIN_CONFIGS_DIR",
    "CurriculumController",
    "CurriculumState",
    "Evaluator",
    "LinearSchedule",
    "TrainResult",
    "actor_parameters",
    "check_resume",
    "export_checkpoint",
    "load_training",
    "make_env_fn",
    "make_vec_env",
    "packaged_training_configs",
    "read_run",
    "require_sb3",
    "resolve_training_config",
    "settings_of",
    "staged_spec",
    "summary",
    "train",
]


@dataclass
class TrainResult:
    """Outcome of :func:`train`."""

    run_dir: Path
    steps: int
    stage: int | None
    steps_per_second: float
    policy: Path
    last_success: float | None


def _check_settings(s: TrainSettings) -> int:
    """``n_steps`` per env; one-line errors for inconsistent settings."""
    n_envs, batch = s.train.n_envs, s.ppo.batch_size
    if batch % n_envs:
        raise ConfigError(
            f"batch_size {batch} is not a multiple of n_envs {n_envs} "
            "(each env collects batch_size / n_envs steps)",
            path="learning.ppo.batch_size",
        )
    if s.ppo.minibatch_size > batch:
        raise ConfigError(
            f"minibatch_size {s.ppo.minibatch_size} exceeds batch_size {batch}",
            path="learning.ppo.minibatch_size",
        )
    return batch // n_envs


def train(
    cfg: ExperimentConfig,
    settings: TrainSettings,
    run_dir: str | Path,
    *,
    resume: bool = False,
    robot: RobotModel | None = None,
    progress: bool = False,
    evaluate: Callable[[], float] | None = None,
    on_eval: Callable[[CurriculumState], None] | None = None,
) -> TrainResult:
    """Train (or resume) PPO into ``run_dir``; see the module docstring.

    Args:
        cfg: the experiment (``learning.env`` configures the env).
        settings: PPO and run settings.
        run_dir: the run folder (must not hold a run unless ``resume``).
        resume: continue the run in ``run_dir`` from its latest checkpoint.
        robot: a robot model replacing ``cfg.robot`` (tests: fewer beams). Not recorded.
        progress: show a rich progress bar.
        evaluate: replaces the evaluation env (tests); returns a success rate.
        on_eval: called after each curriculum evaluation.

    Raises:
        ArenaError: torch/SB3 missing, a bad config, a run folder mismatch.
    """
    require_sb3()
    import torch.nn as nn
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from arena.learn.actions import ActionDecoder
    from arena.learn.extractors import policy_kwargs_for
    from arena.learn.policy import export_policy
    from arena.robots.presets import load_robot
    from arena.tasks.base import build_mode

    run = Path(run_dir)
    manifest_path = run / MANIFEST
    n_steps = _check_settings(settings)
    ppo, tr = settings.ppo, settings.train
    seed = tr.seed if tr.seed is not None else cfg.seed
    done = 0
    manifest: dict[str, Any]
    if resume:
        manifest = check_resume(run, cfg, settings)
        done = int(manifest["steps_done"])
        if manifest.get("checkpoint") is None:
            raise ArenaError(f"{manifest_path}: the run has no checkpoint to resume from")
    else:
        if manifest_path.exists():
            raise ArenaError(f"{manifest_path}: {run} already holds a run; resume it instead")
        manifest = {
            "kind": "train",
            "config": cfg.model_dump(mode="json"),
            "settings": settings.model_dump(mode="json"),
            "seed": seed,
            "steps_done": 0,
            "stage": None,
            "checkpoint": None,
            "created": datetime.now(UTC).isoformat(timespec="seconds"),
            "arena_version": __version__,
        }

    staged_cfg = staged_spec(cfg) if tr.curriculum.enabled else None
    staged = build_mode("modules", staged_cfg) if staged_cfg is not None else None
    if staged is not None and manifest.get("stage") is not None:
        staged.set_stage(int(manifest["stage"]))

    venv = make_vec_env(cfg, tr.n_envs, tr.vec_env, robot, seed=seed,
                        robots_per_world=tr.robots_per_world, respawn=tr.respawn,
                        prefetch=tr.prefetch_episodes)
    nc = ppo.normalize
    try:
        if resume:
            ckpt = run / manifest["checkpoint"]
            venv = VecNormalize.load(str(ckpt / "vecnormalize.pkl"), venv)
            venv.training = True
            model = PPO.load(ckpt / "model.zip", env=venv, device=tr.device)
            # model.zip stores the folder it logged to; a copied or moved run logs here
            model.tensorboard_log = str(run / "tb") if tr.tensorboard else None
            venv.seed(seed + done)
        else:
            venv = VecNormalize(
                venv, norm_obs=nc.norm_obs, norm_reward=nc.norm_reward, clip_obs=nc.clip_obs,
                clip_reward=nc.clip_reward, gamma=ppo.gamma, norm_obs_keys=nc.keys,
            )
            lr: Any = (
                LinearSchedule(ppo.lr_schedule.initial, ppo.lr_schedule.final)
                if ppo.lr_schedule.enabled else ppo.learning_rate
            )
            import gymnasium as gym

            policy = (
                "MultiInputPolicy" if isinstance(venv.observation_space, gym.spaces.Dict)
                else "MlpPolicy"
            )
            model = PPO(
                policy, venv, learning_rate=lr, n_steps=n_steps,
                batch_size=ppo.minibatch_size, n_epochs=ppo.n_epochs, gamma=ppo.gamma,
                gae_lambda=ppo.gae_lambda, clip_range=ppo.clip_range, ent_coef=ppo.ent_coef,
                vf_coef=ppo.vf_coef, max_grad_norm=ppo.max_grad_norm, target_kl=ppo.target_kl,
                policy_kwargs={
                    "net_arch": {"pi": list(ppo.net_arch.pi), "vf": list(ppo.net_arch.vf)},
                    "activation_fn": {"relu": nn.ReLU, "tanh": nn.Tanh}[ppo.activation],
                    "share_features_extractor": ppo.share_features_extractor,
                    **policy_kwargs_for(ppo.extractor),
                },
                tensorboard_log=str(run / "tb") if tr.tensorboard else None,
                seed=seed, device=tr.device, verbose=0,
            )
        run.mkdir(parents=True, exist_ok=True)

        t = TrainerState()
        t.every_ckpt, t.every_eval = tr.checkpoint_every, tr.eval.every
        t.last_checkpoint = t.last_eval = done
        t.stage = staged.stage if staged is not None else None
        t.on_eval = on_eval
        evaluator: Evaluator | None = None
        if staged is not None:
            if evaluate is None:
                evaluator = Evaluator(cfg, tr.eval.episodes, seed + tr.eval.seed_offset, robot)
                evaluator.model, evaluator.train_env = model, venv
                evaluator.set_stage(staged.stage)
                evaluate = evaluator

            def apply(stage: int) -> None:
                venv.env_method("set_stage", stage)
                if evaluator is not None:
                    evaluator.set_stage(stage)

            t.controller = CurriculumController(
                staged, evaluate, apply, tr.curriculum.stop_success
            )
        wall = {"t": time.perf_counter(), "steps": done}
        rob = robot if robot is not None else load_robot(cfg.robot)

        def export(path: Path) -> Path:
            return export_policy(
                model, venv if nc.norm_obs else None, path,
                decoder=ActionDecoder(cfg.learning.env.action, rob),
                observation=cfg.learning.env.observation.model_dump(mode="json"),
                laser=rob.lidar(cfg.learning.env.observation.sensor),
            )

        def checkpoint() -> None:
            steps = int(model.num_timesteps)
            name = f"{CHECKPOINTS}/step_{steps}"
            (run / name).mkdir(parents=True, exist_ok=True)
            model.save(run / name / "model.zip")
            venv.save(str(run / name / "vecnormalize.pkl"))
            dt = time.perf_counter() - wall["t"]
            manifest.update(
                steps_done=steps, checkpoint=name, stage=t.stage,
                last_success_rate=t.last_success,
                steps_per_second=(steps - wall["steps"]) / dt if dt > 0 else None,
                updated=datetime.now(UTC).isoformat(timespec="seconds"),
            )
            write_json(manifest_path, manifest)
            t.last_checkpoint = steps

        t.checkpoint = checkpoint
        if tr.eval.keep_best:
            if staged is not None:
                raise ConfigError(
                    "eval.keep_best compares success rates across the run; with a staged "
                    "curriculum they belong to different stages", path="learning.train.eval",
                )
            if evaluate is None:
                evaluator = Evaluator(cfg, tr.eval.episodes, seed + tr.eval.seed_offset, robot)
                evaluator.model, evaluator.train_env = model, venv
                evaluate = evaluator
            judge = evaluate

            def keep_best() -> None:
                rate = float(judge())
                t.last_success = rate
                if rate <= float((manifest.get("best") or {}).get("success_rate", -1.0)):
                    return
                (run / BEST).mkdir(parents=True, exist_ok=True)
                model.save(run / BEST / "model.zip")
                venv.save(str(run / BEST / "vecnormalize.pkl"))
                export(run / BEST / "policy.npz")
                manifest["best"] = {
                    "step": int(model.num_timesteps), "success_rate": rate, "path": BEST,
                }
                write_json(manifest_path, manifest)

            t.keep_best = keep_best
        write_json(manifest_path, manifest)
        cbs = callback_classes()
        callbacks: list[Any] = [cbs["eval"](t), cbs["checkpoint"](t)]
        if ppo.critic_warmup > 0:
            callbacks.append(cbs["critic_warmup"](ppo.critic_warmup))
        if progress:
            callbacks.append(cbs["progress"](tr.total_steps, done))
        remaining = max(tr.total_steps - done, 0)
        start = time.perf_counter()
        if remaining > 0:
            model.learn(remaining, callback=callbacks, reset_num_timesteps=False,
                        tb_log_name="PPO")
        elapsed = time.perf_counter() - start
        steps = int(model.num_timesteps)
        if remaining > 0 or manifest.get("checkpoint") is None:
            checkpoint()  # the final model, after the last update
        rate = (steps - done) / elapsed if elapsed > 0 else 0.0
        manifest["steps_per_second"] = rate
        write_json(manifest_path, manifest)
        policy_path = export(run / "policy.npz")
        if evaluator is not None:
            evaluator.close()
    finally:
        venv.close()
    return TrainResult(run, steps, t.stage, rate, policy_path, t.last_success)


def export_checkpoint(checkpoint: str | Path, out: str | Path | None = None) -> Path:
    """Write the numpy policy of one checkpoint of a run (``RUN/checkpoints/step_N``).

    Training keeps its best policy in some checkpoint, not always the last one; this writes
    that checkpoint's actor exactly as the end of :func:`train` writes ``RUN/policy.npz``.

    Args:
        checkpoint: a checkpoint folder (``model.zip`` + ``vecnormalize.pkl``) inside a run.
        out: output file; default ``<checkpoint>/policy.npz``.

    Raises:
        ArenaError: not a checkpoint of a run, or torch/SB3 missing.
    """
    require_sb3()
    import pickle

    from stable_baselines3 import PPO

    from arena.learn.actions import ActionDecoder
    from arena.learn.policy import export_policy
    from arena.robots.presets import load_robot

    ckpt = Path(checkpoint)
    if not (ckpt / "model.zip").is_file():
        raise ArenaError(f"{ckpt}: no model.zip; give a checkpoint folder RUN/checkpoints/step_N")
    manifest = read_run(ckpt.parent.parent)
    cfg = ExperimentConfig.model_validate(manifest["config"])
    settings = TrainSettings.model_validate(manifest["settings"])
    vecnorm = None
    if settings.ppo.normalize.norm_obs:
        with open(ckpt / "vecnormalize.pkl", "rb") as f:  # statistics only, no env needed
            vecnorm = pickle.load(f)
    model = PPO.load(ckpt / "model.zip", device="cpu")
    rob = load_robot(cfg.robot)
    return export_policy(
        model, vecnorm, Path(out) if out is not None else ckpt / "policy.npz",
        decoder=ActionDecoder(cfg.learning.env.action, rob),
        observation=cfg.learning.env.observation.model_dump(mode="json"),
        laser=rob.lidar(cfg.learning.env.observation.sensor),
    )


def summary(result: TrainResult) -> str:
    """One line describing a finished run."""
    stage = "" if result.stage is None else f", stage {result.stage}"
    succ = "" if result.last_success is None else f", eval success {result.last_success:.0%}"
    return (f"{result.steps} steps ({result.steps_per_second:.0f} env steps/s){stage}{succ}; "
            f"policy {result.policy}")


__all__ = [
    "CurriculumController",
    "CurriculumState",
    "Evaluator",
    "LinearSchedule",
    "TrainResult",
    "check_resume",
    "export_checkpoint",
    "load_training",
    "make_vec_env",
    "read_run",
    "require_sb3",
    "settings_of",
    "summary",
    "train",
]
