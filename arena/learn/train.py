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
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from arena import __version__
from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError, ConfigError
from arena.learn.train_config import TrainSettings
from arena.robots.model import RobotModel

MANIFEST = "run.json"
CHECKPOINTS = "checkpoints"
BEST = "best"  # eval.keep_best: the best evaluated checkpoint
INSTALL_HINT = "pip install torch==2.13.0, then pip install 'arena[train]'"


def require_sb3() -> None:
    """Raise a one-line :class:`ArenaError` when torch or Stable-Baselines3 is missing."""
    for mod in ("torch", "stable_baselines3", "gymnasium"):
        try:
            __import__(mod)
        except ImportError:
            raise ArenaError(
                f"training needs {mod}, which is not installed: {INSTALL_HINT}"
            ) from None


# -- settings -----------------------------------------------------------------------------------
def settings_of(cfg: ExperimentConfig) -> TrainSettings:
    """The training settings (``learning.ppo`` and ``learning.train``) of a loaded experiment."""
    return TrainSettings(ppo=cfg.learning.ppo, train=cfg.learning.train)


def load_training(
    path: str | Path | None, overrides: Sequence[str] = ()
) -> tuple[ExperimentConfig, TrainSettings]:
    """Load an experiment and its ``learning.ppo`` / ``learning.train`` settings.

    Raises:
        ConfigError: a bad experiment or training block, naming file/override and key path.
    """
    from arena.config.loader import load_config

    cfg = load_config(resolve_training_config(path), overrides)
    return cfg, settings_of(cfg)


#: The packaged training configs (``arena train rosnav_rl``).
TRAIN_CONFIGS_DIR = Path(__file__).resolve().parent / "data" / "train"


def packaged_training_configs() -> list[str]:
    """Names of the packaged training configs (``rlca``, ``rosnav_rl``, ``value_policy``)."""
    return sorted(p.stem for p in TRAIN_CONFIGS_DIR.glob("*.yaml"))


def resolve_training_config(path: str | Path | None) -> str | Path | None:
    """A YAML path as given, or a packaged config's name turned into its file.

    ``rosnav_rl`` (no such file here, no ``.yaml`` suffix, no folder) names
    ``arena/learn/data/train/rosnav_rl.yaml``, so the command works from any folder.

    Raises:
        ConfigError: a bare name that is neither a file nor a packaged config (with a close
            match and the packaged names).
    """
    if path is None or Path(path).exists():
        return path
    text = str(path)
    if Path(text).suffix or "/" in text or os.sep in text:
        return path  # a file path: load_config reports it missing
    packaged = TRAIN_CONFIGS_DIR / f"{text}.yaml"
    if packaged.is_file():
        return packaged
    import difflib

    known = packaged_training_configs()
    close = difflib.get_close_matches(text, known, n=1, cutoff=0.5)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ConfigError(
        f"no such file or packaged training config {text!r}; {hint}packaged: {', '.join(known)}"
    )


# -- run folder ---------------------------------------------------------------------------------
def _write_json(path: Path, data: Any) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(data, f, indent=1)
    os.replace(tmp, path)


def read_run(run_dir: str | Path) -> dict[str, Any]:
    """Read ``RUN/run.json``.

    Raises:
        ArenaError: not a training run folder, or an unreadable manifest.
    """
    path = Path(run_dir) / MANIFEST
    if not path.is_file():
        raise ArenaError(f"{path}: no run manifest; {run_dir} is not a training run folder")
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise ArenaError(f"{path}: unreadable run manifest ({e})") from None
    if not isinstance(data, dict) or data.get("kind") != "train":
        raise ArenaError(f"{path}: not a training run manifest")
    return data


def _first_difference(a: Any, b: Any, prefix: str = "") -> str | None:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b), key=str):
            d = _first_difference(a.get(k), b.get(k), f"{prefix}.{k}" if prefix else str(k))
            if d is not None:
                return d
        return None
    return None if a == b else prefix


def _current(schema: Any, stored: Any) -> Any:
    """A stored config re-read through today's ``schema``, or as stored if it no longer validates.

    Fields added since get their defaults, so a run made before a new option existed still
    resumes; an invalid one is compared as stored (the comparison names the first difference).
    """
    try:
        return json.loads(json.dumps(schema.model_validate(stored).model_dump(mode="json")))
    except ValueError:
        return json.loads(json.dumps(stored))


def check_resume(run_dir: Path, cfg: ExperimentConfig, settings: TrainSettings) -> dict[str, Any]:
    """The run's manifest, if ``cfg``/``settings`` match it (``total_steps`` may differ).

    Raises:
        ArenaError: naming the manifest and the first key that differs.
    """
    data = read_run(run_dir)
    want_settings = settings.model_dump(mode="json")
    have_settings = _current(TrainSettings, data["settings"])
    want_settings["train"].pop("total_steps")
    have_settings["train"].pop("total_steps", None)
    for what, have, want in (
        ("config", _current(ExperimentConfig, data["config"]), cfg.model_dump(mode="json")),
        ("settings", have_settings, want_settings),
    ):
        diff = _first_difference(have, json.loads(json.dumps(want)))
        if diff is not None:
            raise ArenaError(
                f"{run_dir / MANIFEST}: cannot resume: {what} key {diff!r} differs from the run's"
            )
    return data


# -- environments -------------------------------------------------------------------------------
def staged_spec(cfg: ExperimentConfig) -> dict[str, Any] | None:
    """The ``staged`` entry of ``task.modules``, if any."""
    for m in cfg.task.modules:
        if isinstance(m, dict) and m.get("type") == "staged":
            return m
    return None


def _stage_env_class() -> type:
    import gymnasium as gym

    from arena.tasks.modules.staged import Staged

    class StagedEnv(gym.Wrapper):  # type: ignore[misc,unused-ignore]
        """Lets the trainer set the curriculum stage of a wrapped :class:`SocialNavEnv`."""

        def __init__(self, env: Any) -> None:
            super().__init__(env)
            self._stage: int | None = None

        def _modules(self) -> list[Staged]:
            driver: Any = self.env.unwrapped.driver
            return [m for m in driver.generator.modules
                    if isinstance(m, Staged)]

        def set_stage(self, index: int) -> int:
            """Move every staged module to ``index`` (clamped); return the stage."""
            self._stage = int(index)
            stages = [m.set_stage(index) for m in self._modules()]
            return stages[0] if stages else -1

        def get_stage(self) -> int:
            """The current stage (-1 without a staged module)."""
            mods = self._modules()
            return mods[0].stage if mods else -1

        def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> Any:
            if seed is not None and self._stage is not None:
                # a seeded reset rebuilds the task generator (back at its start stage)
                self.env.reset(seed=seed)
                self.set_stage(self._stage)
                opts = {"episode": 0, **(options or {})}
                obs, info = self.env.reset(options=opts)
            else:
                obs, info = self.env.reset(seed=seed, options=options)
            return obs, info

        def step(self, action: Any) -> Any:
            obs, reward, terminated, truncated, info = self.env.step(action)
            return obs, reward, terminated, truncated, info

    return StagedEnv


def make_env_fn(cfg: ExperimentConfig, robot: RobotModel | None = None) -> Callable[[], Any]:
    """A thunk building ``Monitor(StagedEnv(SocialNavEnv(cfg, robot)))``."""

    def thunk() -> Any:
        from stable_baselines3.common.monitor import Monitor

        from arena.learn.env import SocialNavEnv

        return Monitor(_stage_env_class()(SocialNavEnv(cfg, robot=robot)))

    return thunk


def make_vec_env(
    cfg: ExperimentConfig,
    n_envs: int,
    kind: str = "dummy",
    robot: RobotModel | None = None,
    seed: int | None = None,
    robots_per_world: Sequence[int] | None = None,
    respawn: bool = False,
    prefetch: int = 0,
) -> Any:
    """``n_envs`` environments in SB3's ``DummyVecEnv`` or ``SubprocVecEnv``.

    ``kind="batched"``: one :class:`~arena.learn.sb3_vec.SB3VecEnv` over a
    :class:`~arena.learn.batched.BatchedSocialNavEnv` of ``n_envs`` worlds (seeded with
    ``seed`` at its next reset when given; ``prefetch`` episodes per world drawn ahead in a
    helper process). ``kind="multi_robot"``: a
    :class:`~arena.learn.multi_vec.MultiRobotVecEnv` with ``robots_per_world`` (summing to
    ``n_envs``; default: one world of ``n_envs`` robots) and ``respawn``.
    """
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    if kind == "multi_robot":
        from arena.learn.multi_vec import MultiRobotVecEnv

        rpw = list(robots_per_world) if robots_per_world is not None else [n_envs]
        if sum(rpw) != n_envs:
            raise ConfigError(f"robots_per_world {rpw} does not sum to n_envs {n_envs}",
                              path="learning.train.robots_per_world")
        mvenv = MultiRobotVecEnv(cfg, rpw, robot=robot, respawn=respawn)
        if seed is not None:
            mvenv.seed(int(seed))
        return mvenv

    if kind == "batched":
        from arena.learn.sb3_vec import SB3VecEnv

        venv = SB3VecEnv(cfg, num_envs=n_envs, robot=robot, prefetch=prefetch)
        if seed is not None:
            venv.seed(int(seed))
        return venv

    fns = [make_env_fn(cfg, robot) for _ in range(n_envs)]
    if kind == "subproc" and n_envs > 1:
        return SubprocVecEnv(fns)
    return DummyVecEnv(fns)


# -- evaluation and curriculum ------------------------------------------------------------------
class Evaluator:
    """Success rate of the deterministic policy over ``episodes`` episodes of a separate env.

    The episodes are the same at every call (the env is reseeded with ``seed``) unless the
    curriculum stage changed.
    """

    def __init__(
        self, cfg: ExperimentConfig, episodes: int, seed: int, robot: RobotModel | None = None
    ) -> None:
        from stable_baselines3.common.vec_env import VecNormalize

        self.episodes = int(episodes)
        self.seed = int(seed)
        self.venv = VecNormalize(
            make_vec_env(cfg, 1, "dummy", robot), training=False, norm_reward=False
        )
        self.model: Any = None
        self.train_env: Any = None

    def set_stage(self, stage: int) -> None:
        """Apply a curriculum stage to the evaluation env."""
        self.venv.env_method("set_stage", stage)

    def __call__(self) -> float:
        """Run the evaluation; return the success rate (0-1)."""
        from stable_baselines3.common.vec_env import sync_envs_normalization

        assert self.model is not None
        if self.train_env is not None:
            sync_envs_normalization(self.train_env, self.venv)
        self.venv.seed(self.seed)
        obs: Any = self.venv.reset()
        done_eps = successes = 0
        while done_eps < self.episodes:
            action, _ = self.model.predict(obs, deterministic=True)
            obs, _, dones, infos = self.venv.step(action)
            if dones[0]:
                done_eps += 1
                successes += infos[0].get("outcome") == "success"
        return successes / self.episodes

    def close(self) -> None:
        """Close the evaluation env."""
        self.venv.close()


@dataclass
class CurriculumState:
    """What the curriculum controller decided at one evaluation."""

    success_rate: float
    stage: int
    change: int
    stop: bool


class CurriculumController:
    """Arena's training callback logic around a ``staged`` module (no SB3 needed).

    Args:
        staged: the module (its ``report`` holds the thresholds; its stage is the truth).
        evaluate: returns the success rate (0-1) of an evaluation.
        apply: called with the new stage after a promotion or demotion.
        stop_success: at the last stage, stop at this success rate (``None``: never).
    """

    def __init__(
        self,
        staged: Any,
        evaluate: Callable[[], float],
        apply: Callable[[int], None],
        stop_success: float | None = 0.98,
    ) -> None:
        self.staged = staged
        self.evaluate = evaluate
        self.apply = apply
        self.stop_success = stop_success

    def step(self) -> CurriculumState:
        """Evaluate, promote/demote, apply; say whether training should stop."""
        rate = float(self.evaluate())
        change = self.staged.report(rate)
        if change:
            self.apply(self.staged.stage)
        stop = (
            change == 0 and self.staged.is_last and self.stop_success is not None
            and rate >= self.stop_success
        )
        return CurriculumState(rate, self.staged.stage, change, stop)


# -- SB3 pieces ---------------------------------------------------------------------------------
class LinearSchedule:
    """SB3 learning-rate schedule: ``initial`` at the start, ``final`` at ``total_steps``."""

    def __init__(self, initial: float, final: float) -> None:
        self.initial, self.final = float(initial), float(final)

    def __call__(self, progress_remaining: float) -> float:
        """The rate at ``progress_remaining`` (1 at the start, 0 at the end)."""
        return self.final + (self.initial - self.final) * float(progress_remaining)


def actor_parameters(policy: Any) -> list[Any]:
    """The parameters that shape an SB3 ``ActorCriticPolicy``'s action distribution.

    Its feature extractor (the actor's own one, or the shared one, which then stays frozen for
    the critic too), the actor MLP, the action mean layer and the log-std. Critic warm-up
    (``learning.ppo.critic_warmup``) freezes exactly these.
    """
    extractor = (policy.features_extractor if policy.share_features_extractor
                 else policy.pi_features_extractor)
    params = [*extractor.parameters(), *policy.mlp_extractor.policy_net.parameters(),
              *policy.action_net.parameters()]
    log_std = getattr(policy, "log_std", None)  # a Gaussian policy's; none for discrete actions
    if log_std is not None:
        params.append(log_std)
    return params


def _callbacks() -> dict[str, type]:
    """SB3 callback classes (defined lazily: SB3 is optional)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class CheckpointCallback(BaseCallback):
        def __init__(self, trainer: _Trainer) -> None:
            super().__init__()
            self.trainer = trainer

        def _on_rollout_start(self) -> None:
            # between rollouts, after the previous update: the saved model has learnt from
            # every step it counts (inside a rollout the last update would be missing)
            t = self.trainer
            if t.keep_best is not None and self.num_timesteps - t.last_eval >= t.every_eval:
                t.last_eval = self.num_timesteps
                t.keep_best()
                self.logger.record("eval/success_rate", t.last_success)
            if self.num_timesteps - t.last_checkpoint >= t.every_ckpt:
                t.checkpoint()

        def _on_step(self) -> bool:
            return True

    class CriticWarmupCallback(BaseCallback):
        """Freeze the actor for the updates of rollouts ending by step ``until``."""

        def __init__(self, until: int) -> None:
            super().__init__()
            self.until = until

        def _on_rollout_end(self) -> None:
            # called after collecting, before the update that learns from this rollout
            frozen = self.num_timesteps <= self.until
            for p in actor_parameters(self.model.policy):
                p.requires_grad_(not frozen)
            self.logger.record("train/critic_warmup", int(frozen))

        def _on_step(self) -> bool:
            return True

    class EvalCurriculumCallback(BaseCallback):
        def __init__(self, trainer: _Trainer) -> None:
            super().__init__()
            self.trainer = trainer

        def _on_training_start(self) -> None:
            t = self.trainer
            if t.stage is not None:
                self.training_env.env_method("set_stage", t.stage)
            self.logger.record("curriculum/stage", -1 if t.stage is None else t.stage)

        def _on_step(self) -> bool:
            t = self.trainer
            if t.controller is None or self.num_timesteps - t.last_eval < t.every_eval:
                return True
            t.last_eval = self.num_timesteps
            st = t.controller.step()
            t.stage = st.stage
            t.last_success = st.success_rate
            self.logger.record("eval/success_rate", st.success_rate)
            self.logger.record("curriculum/stage", st.stage)
            if t.on_eval is not None:
                t.on_eval(st)
            return not st.stop

    class RichProgressCallback(BaseCallback):
        def __init__(self, total: int, start: int) -> None:
            super().__init__()
            self.total, self.start = total, start
            self.progress: Any = None

        def _on_training_start(self) -> None:
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self.progress = Progress(
                TextColumn("[bold]train"), BarColumn(), MofNCompleteColumn(),
                TextColumn("{task.fields[info]}"), TimeElapsedColumn(), TimeRemainingColumn(),
            )
            self.progress.start()
            self.task = self.progress.add_task("train", total=self.total, completed=self.start,
                                               info="")

        def _on_step(self) -> bool:
            if self.n_calls % 16 == 0:
                self.progress.update(self.task, completed=min(self.num_timesteps, self.total))
            return True

        def _on_training_end(self) -> None:
            self.progress.update(self.task, completed=min(self.num_timesteps, self.total))
            self.progress.stop()

    return {
        "checkpoint": CheckpointCallback,
        "critic_warmup": CriticWarmupCallback,
        "eval": EvalCurriculumCallback,
        "progress": RichProgressCallback,
    }


@dataclass
class TrainResult:
    """Outcome of :func:`train`."""

    run_dir: Path
    steps: int
    stage: int | None
    steps_per_second: float
    policy: Path
    last_success: float | None


class _Trainer:
    """State shared by the callbacks of one :func:`train` call."""

    def __init__(self) -> None:
        self.last_checkpoint = 0
        self.last_eval = 0
        self.every_ckpt = 1
        self.every_eval = 1
        self.stage: int | None = None
        self.controller: CurriculumController | None = None
        self.on_eval: Callable[[CurriculumState], None] | None = None
        self.last_success: float | None = None
        self.checkpoint: Callable[[], None] = lambda: None
        # eval.keep_best: evaluate and keep the best checkpoint (no curriculum)
        self.keep_best: Callable[[], None] | None = None


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
                clip_reward=nc.clip_reward, gamma=ppo.gamma,
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

        t = _Trainer()
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
                laser=rob.laser,
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
            _write_json(manifest_path, manifest)
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
                _write_json(manifest_path, manifest)

            t.keep_best = keep_best
        _write_json(manifest_path, manifest)
        cbs = _callbacks()
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
        _write_json(manifest_path, manifest)
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
        observation=cfg.learning.env.observation.model_dump(mode="json"), laser=rob.laser,
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
