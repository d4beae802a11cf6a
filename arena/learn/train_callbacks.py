"""Evaluation, curriculum and SB3 callbacks of a training run (:func:`arena.learn.train.train`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from arena.config.schema import ExperimentConfig
from arena.learn.train_envs import make_vec_env
from arena.robots.model import RobotModel


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
            # the parts normalised (learning.ppo.normalize.keys) follow the training env's
            keys = getattr(self.train_env, "norm_obs_keys", None)
            if keys is not None:
                self.venv.norm_obs_keys = list(keys)
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


def callback_classes() -> dict[str, type]:
    """SB3 callback classes (defined lazily: SB3 is optional)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class CheckpointCallback(BaseCallback):
        def __init__(self, trainer: TrainerState) -> None:
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
        def __init__(self, trainer: TrainerState) -> None:
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


class TrainerState:
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
