"""The ``learning.ppo`` and ``learning.train`` blocks: PPO hyper-parameters and the training run.

Pydantic only (no torch), so that the experiment schema can import it. Defaults follow Arena's
training config (arena_specs §8.5; the June 2024 values where March and June differ)::

    learning:
      ppo:
        batch_size: 20480        # total rollout per update; n_steps per env = batch_size / n_envs
        minibatch_size: 512      # SB3 batch_size (Arena: m_batch_size)
        n_epochs: 3
        learning_rate: 3.0e-4    # used when lr_schedule.enabled is false
        lr_schedule: {enabled: true, initial: 1.0e-3, final: 1.0e-4}   # linear over the run
        gamma: 0.99
        gae_lambda: 0.95
        clip_range: 0.25
        ent_coef: 0.005
        vf_coef: 0.22
        max_grad_norm: 0.5
        net_arch: {pi: [64, 64], vf: [64, 64]}
        activation: relu
        extractor: {type: flatten}          # or {type: rlca_conv, filters: [32, 32], ...}
        share_features_extractor: true
        normalize: {norm_obs: true, norm_reward: false, clip_obs: 30.0, clip_reward: 20.0}
      train:
        total_steps: 4000000
        n_envs: 4
        vec_env: subproc           # dummy | subproc | batched | multi_robot
        robots_per_world: null     # multi_robot: robots of each world, summing to n_envs
        checkpoint_every: 100000
        eval: {episodes: 40, every: 20000}
        curriculum: {enabled: true, stop_success: 0.98}
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.core.rng import Seed


class _Strict(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class LRSchedule(_Strict):
    """Linear learning-rate schedule over the whole run (Arena's ``lr_schedule``)."""

    enabled: bool = Field(True, description="linear initial → final; false: learning_rate")
    initial: float = Field(1e-3, gt=0, description="learning rate at step 0")
    final: float = Field(1e-4, gt=0, description="learning rate at total_steps")


class NetArch(_Strict):
    """Hidden layers of the policy (``pi``) and value (``vf``) MLPs after the feature extractor."""

    pi: list[int] = Field([64, 64], description="policy MLP widths")
    vf: list[int] = Field([64, 64], description="value MLP widths")

    @model_validator(mode="after")
    def _positive(self) -> NetArch:
        if any(w < 1 for w in (*self.pi, *self.vf)):
            raise ValueError("layer widths must be >= 1")
        return self


class FlattenExtractorConfig(_Strict):
    """SB3's default: every observation part flattened and concatenated (an MLP policy)."""

    type: Literal["flatten"] = "flatten"


class RLCAConvExtractorConfig(_Strict):
    """Long et al. 2018's scan encoder (:class:`arena.learn.extractors.RLCAConvExtractor`).

    The ``scan_key`` part ``(stack, beams)`` goes through ``Conv1d`` layers (the stack as input
    channels, ReLU after each) and one fully connected layer (ReLU); the other parts are
    flattened and appended, in the observation's key order. Defaults are the paper's: 32
    filters of kernel 5 stride 2, 32 of kernel 3 stride 2, FC 256.
    """

    type: Literal["rlca_conv"] = "rlca_conv"
    scan_key: str = Field("lidar", description="the (stack, beams) observation part")
    filters: list[int] = Field([32, 32], min_length=1, description="output channels per conv")
    kernels: list[int] = Field([5, 3], min_length=1, description="kernel size per conv (beams)")
    strides: list[int] = Field([2, 2], min_length=1, description="stride per conv (beams)")
    fc: int = Field(256, ge=1, description="width of the fully connected layer after the convs")

    @model_validator(mode="after")
    def _layers(self) -> RLCAConvExtractorConfig:
        if not len(self.filters) == len(self.kernels) == len(self.strides):
            raise ValueError("filters, kernels and strides must have one entry per conv layer")
        if any(v < 1 for v in (*self.filters, *self.kernels, *self.strides)):
            raise ValueError("filters, kernels and strides must be >= 1")
        return self


class DrlvoExtractorConfig(_Strict):
    """DRL-VO's encoder as TRAIL uses it (:class:`arena.learn.extractors.DrlvoExtractor`).

    Two branches: the stacked scans ``scan_key`` ``(stack, beams)``, clipped to ``scan_clip``
    and scaled to ``[0, 1]``, min- and average-pooled per scan into ``scan_bins`` bins and read
    as ``2 · stack`` channels of a 1-D signal through ``Conv1d`` layers (``scan_filters``,
    ``scan_kernels``, ``scan_strides``); the pedestrian kinematic map ``map_key``
    ``(channels, size, size)`` through ``Conv2d`` layers (``map_filters`` ...). Both flattened,
    one fully connected layer (ReLU) of width ``fc``, then the other parts appended.
    """

    type: Literal["drlvo_cnn"] = "drlvo_cnn"
    scan_key: str = Field("lidar", description="the (stack, beams) observation part")
    map_key: str = Field("semantic", description="the (channels, size, size) pedestrian map")
    scan_clip: float = Field(10.0, gt=0, description="m; ranges beyond read as this")
    scan_bins: int = Field(80, ge=1, description="pooled bins per scan (beams % bins == 0)")
    scan_filters: list[int] = Field([32, 32], min_length=1)
    scan_kernels: list[int] = Field([5, 3], min_length=1)
    scan_strides: list[int] = Field([2, 2], min_length=1)
    map_filters: list[int] = Field([16, 16], min_length=1)
    map_kernels: list[int] = Field([5, 3], min_length=1)
    map_strides: list[int] = Field([2, 2], min_length=1)
    fc: int = Field(256, ge=1, description="width of the fully connected layer")

    @model_validator(mode="after")
    def _layers(self) -> DrlvoExtractorConfig:
        for name in ("scan", "map"):
            f, k, s = (getattr(self, f"{name}_{x}") for x in ("filters", "kernels", "strides"))
            if not len(f) == len(k) == len(s):
                raise ValueError(f"{name}_filters, {name}_kernels and {name}_strides must have "
                                 "one entry per conv layer")
            if any(v < 1 for v in (*f, *k, *s)):
                raise ValueError(f"{name} filters, kernels and strides must be >= 1")
        return self


ExtractorConfig = Annotated[
    FlattenExtractorConfig | RLCAConvExtractorConfig | DrlvoExtractorConfig,
    Field(discriminator="type"),
]
"""The policy's feature extractor, picked by ``type``."""


class NormalizeConfig(_Strict):
    """SB3 ``VecNormalize`` (arena_specs §8.2: obs normalised, rewards not, clip 30)."""

    norm_obs: bool = Field(True, description="running mean/var normalisation of observations")
    norm_reward: bool = Field(False, description="normalise rewards by the return's std")
    clip_obs: float = Field(30.0, gt=0, description="clip normalised observations to ±this")
    clip_reward: float = Field(20.0, gt=0, description="clip normalised rewards to ±this")
    keys: list[str] | None = Field(
        None, description="Dict observations: the parts to normalise (None: all)"
    )


class PPOConfig(_Strict):
    """Stable-Baselines3 PPO (arena_specs §8.5, Arena's ``rl_agent.ppo``)."""

    batch_size: int = Field(
        20480, ge=1, description="env steps per update over all envs (n_steps = this / n_envs)"
    )
    minibatch_size: int = Field(512, ge=1, description="SB3 minibatch (Arena: m_batch_size)")
    n_epochs: int = Field(3, ge=1, description="passes over each rollout")
    learning_rate: float = Field(3e-4, gt=0, description="constant rate without lr_schedule")
    lr_schedule: LRSchedule = Field(default_factory=LRSchedule)
    gamma: float = Field(0.99, gt=0, le=1, description="discount")
    gae_lambda: float = Field(0.95, ge=0, le=1, description="GAE λ")
    clip_range: float = Field(0.25, gt=0, description="PPO ratio clip")
    ent_coef: float = Field(0.005, ge=0, description="entropy bonus weight")
    vf_coef: float = Field(0.22, ge=0, description="value loss weight")
    max_grad_norm: float = Field(0.5, gt=0, description="gradient clipping")
    target_kl: float | None = Field(
        None, gt=0,
        description="stop an update's epochs early once the approximate KL between the old "
        "and new policy exceeds 1.5 x this (SB3); null: always run n_epochs",
    )
    critic_warmup: int = Field(
        0, ge=0,
        description="env steps (counted from the run's step 0) during which only the critic "
        "learns: the actor's parameters (its extractor, MLP, mean and log-std) stay frozen, so "
        "a warm-started actor meets advantages from a fitted critic",
    )
    net_arch: NetArch = Field(default_factory=NetArch)
    activation: Literal["relu", "tanh"] = Field("relu", description="hidden-layer activation")
    extractor: ExtractorConfig = Field(
        default_factory=FlattenExtractorConfig,
        description="feature extractor before the MLPs: flatten (default), rlca_conv, drlvo_cnn",
    )
    share_features_extractor: bool = Field(
        True, description="actor and critic share the extractor (false: one each, Long et al.)"
    )
    normalize: NormalizeConfig = Field(default_factory=NormalizeConfig)


class EvalConfig(_Strict):
    """Periodic evaluation (deterministic policy, separate env) driving the curriculum."""

    episodes: int = Field(40, ge=1, description="episodes per evaluation (Arena: 40-50)")
    every: int = Field(20000, ge=1, description="env steps (all envs together) between evals")
    seed_offset: int = Field(
        10000, ge=0, description="the eval env's seed is the run's seed + this"
    )
    keep_best: bool = Field(
        False,
        description="without a staged curriculum: evaluate every `every` steps anyway and keep "
        "the checkpoint with the highest success rate in RUN/best (model, statistics, "
        "policy.npz); a warm-started policy may get worse under PPO",
    )


class CurriculumTrainConfig(_Strict):
    """Stage changes of ``task.modules`` ``staged`` from the evaluation success rate."""

    enabled: bool = Field(True, description="only acts when the task has a staged module")
    stop_success: float | None = Field(
        0.98, ge=0, le=1, description="stop training at the last stage at this success; null: never"
    )


class TrainConfig(_Strict):
    """One training run: length, parallel envs, checkpoints, evaluation, curriculum."""

    total_steps: int = Field(4_000_000, ge=1, description="env steps (Arena Jun 2024: 4e6)")
    n_envs: int = Field(4, ge=1, description="parallel training envs (Arena Jun 2024: 4)")
    vec_env: Literal["dummy", "subproc", "batched", "multi_robot"] = Field(
        "subproc",
        description="SB3 vector env; one env always runs in-process; batched: "
        "BatchedSocialNavEnv (all envs as worlds of one engine; evaluation stays on SocialNavEnv); "
        "multi_robot: MultiRobotVecEnv, one slot per robot of robots_per_world worlds",
    )
    robots_per_world: list[int] | None = Field(
        None,
        description="multi_robot: robots in each world (one entry per world), summing to n_envs",
    )
    respawn: bool = Field(
        False,
        description="multi_robot: a robot that arrives, collides or reaches max_steps gets a "
        "new start and goal in its running world (Long et al.); false: the first robot to "
        "finish ends its world's episode for all",
    )
    prefetch_episodes: int = Field(
        1,
        ge=0,
        description="batched: episodes per world drawn ahead by a helper process, overlapping "
        "the simulation (same episodes either way); 0: drawn in the training process",
    )
    seed: Seed | None = Field(None, description="run seed; null: the experiment's seed")
    checkpoint_every: int = Field(100_000, ge=1, description="env steps between checkpoints")
    tensorboard: bool = Field(True, description="write TensorBoard logs to RUN/tb")
    device: Literal["auto", "cpu", "cuda"] = Field("cpu", description="torch device")
    eval: EvalConfig = Field(default_factory=EvalConfig)
    curriculum: CurriculumTrainConfig = Field(default_factory=CurriculumTrainConfig)

    @model_validator(mode="after")
    def _robots(self) -> TrainConfig:
        rpw = self.robots_per_world
        if self.vec_env == "multi_robot":
            if rpw is None:
                raise ValueError("vec_env multi_robot needs robots_per_world, e.g. [2, 3, 4]")
            if any(r < 1 for r in rpw) or not rpw:
                raise ValueError("robots_per_world entries must be >= 1")
            if sum(rpw) != self.n_envs:
                raise ValueError(
                    f"robots_per_world {rpw} has {sum(rpw)} robots; n_envs is {self.n_envs} "
                    "(one PPO slot per robot)"
                )
        elif rpw is not None:
            raise ValueError("robots_per_world only applies to vec_env multi_robot")
        if self.respawn and self.vec_env != "multi_robot":
            raise ValueError("respawn only applies to vec_env multi_robot")
        return self


class TrainSettings(_Strict):
    """``learning.ppo`` + ``learning.train`` together (what a run folder records)."""

    ppo: PPOConfig = Field(default_factory=PPOConfig)
    train: TrainConfig = Field(default_factory=TrainConfig)
