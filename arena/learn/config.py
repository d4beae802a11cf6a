"""The ``learning.env`` block: observations, actions, reward and timing of the RL environments.

One experiment YAML drives both ``arena run`` and :class:`~arena.learn.env.SocialNavEnv`::

    learning:
      env:
        observation:
          lidar: true
          goal: true
          last_action: true
          velocity: false              # measured body twist [vx, vy, ω]
          laser_stack: 1
          pedestrians: {enabled: true, k: 5, max_range: 8.0}
          semantic: {enabled: false, size: 80, roi: 20.0, channels: [pedestrian_location]}
          subgoal: {enabled: false, horizon: 5.0, replan_period: 1.0}
        action: {type: discrete, discretization: robot}
        reward: default                # a packaged file (arena/learn/data/rewards/) or a mapping
        action_period: null            # s; null = sim.dt (one simulation step per env step)
        max_steps: 500
        safety_distance: 0.5

Goal observation (arena_specs §8.1, §10.9): ``ρ = ‖g − p‖`` (m) and ``θ = wrap(atan2(g − p) − ψ)``
in ``[−π, π)`` (rad), so that a goal straight ahead has ``θ = 0``. Arena's code computes
``((atan2 − ψ + 4π) mod 2π) − π``, which is the same angle offset by π (straight ahead = ±π);
we do not reproduce that quirk.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

from arena.core.errors import ConfigError
from arena.learn.train_config import PPOConfig, TrainConfig

SemanticChannel = Literal[
    "pedestrian_location",
    "pedestrian_type",
    "pedestrian_vel_x",
    "pedestrian_vel_y",
    "pedestrian_social_state",
]
"""Feature-map channels (rosnav-rl ``PEDESTRIAN_*`` spaces, arena_specs §8.2)."""


class _Strict(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class PedestrianObsConfig(_Strict):
    """The ``k`` nearest people in the robot frame, zero-padded, with a validity mask."""

    enabled: bool = Field(False, description="add 'pedestrians' and 'pedestrians_mask'")
    k: int = Field(5, ge=1, description="number of nearest people observed")
    max_range: float = Field(8.0, gt=0, description="m; people farther away are not observed")


class SemanticObsConfig(_Strict):
    """Ego-centric pedestrian feature maps (Arena's 80 × 80 grids, ROI centred on the robot)."""

    enabled: bool = Field(False, description="add 'semantic' (channels, size, size)")
    size: int = Field(80, ge=2, description="cells per side")
    roi: float = Field(20.0, gt=0, description="m, side length of the square region")
    channels: tuple[SemanticChannel, ...] = Field(
        ("pedestrian_location", "pedestrian_type", "pedestrian_vel_x", "pedestrian_vel_y",
         "pedestrian_social_state"),
        min_length=1,
        description="feature maps, in this order",
    )


class SubgoalObsConfig(_Strict):
    """Arena's "spacial horizon" (arena_specs §8.1): the goal observation refers to a subgoal.

    At reset a global path is planned (A* on the episode's planning grid, inflated by the robot
    radius + ``navigation.inflation_margin`` as the navigation stack does); each step the
    ``goal`` observation is ``[ρ, θ]`` of :func:`~arena.learn.paths.subgoal_on_path`.
    Rewards keep using the final goal.
    """

    enabled: bool = Field(False, description="'goal' observes the subgoal, not the final goal")
    horizon: float = Field(5.0, gt=0, description="m ahead along the path (Arena: 5.0)")
    replan_period: float = Field(1.0, gt=0, description="s between global replans (Arena: 1.0)")
    max_deviation: float = Field(
        1.0, gt=0, description="m; replan at once when the robot is farther from the path"
    )


class CameraObsConfig(_Strict):
    """Images of one of the robot's ``rgbd`` cameras (the MuJoCo backend renders them)."""

    sensor: str | None = Field(
        None, pattern=r"^[A-Za-z_][A-Za-z0-9_]*$",
        description="the robot's rgbd sensor observed; null: no camera part",
    )
    channels: tuple[Literal["depth", "rgb"], ...] = Field(
        ("depth",), min_length=1,
        description="'depth': (H, W) float32 m (0: no return); 'rgb': (H, W, 3) uint8",
    )


class ObservationConfig(_Strict):
    """Which observation parts the environment returns."""

    lidar: bool = Field(
        True, description="'lidar': (beams,) ranges in m; (laser_stack, beams) if stacked"
    )
    goal: bool = Field(True, description="'goal': [ρ m, θ rad] in the robot frame")
    last_action: bool = Field(True, description="'last_action': [vx, vy, ω] last command")
    velocity: bool = Field(
        False, description="'velocity': [vx, vy, ω] measured body twist (vy = 0 for diff drive)"
    )
    laser_stack: int = Field(1, ge=1, description="number of most recent scans stacked")
    sensor: str = Field(
        "laser", pattern=r"^[A-Za-z_][A-Za-z0-9_]*$",
        description="the robot's lidar2d sensor the 'lidar' part reads",
    )
    goal_max_distance: float = Field(
        30.0, gt=0, description="m; ρ is clipped to this (Arena's GOAL space: [0, 30])"
    )
    pedestrians: PedestrianObsConfig = Field(default_factory=PedestrianObsConfig)
    semantic: SemanticObsConfig = Field(default_factory=SemanticObsConfig)
    subgoal: SubgoalObsConfig = Field(default_factory=SubgoalObsConfig)
    camera: CameraObsConfig = Field(default_factory=CameraObsConfig)
    flatten: bool = Field(False, description="one flat float32 Box instead of a Dict space")


class ActionConfig(_Strict):
    """The action space (arena_specs §8.3)."""

    type: Literal["continuous", "discrete"] = Field("discrete", description="Arena: discrete")
    discretization: Literal["robot", "custom"] = Field(
        "robot", description="robot: the preset's discrete list; custom: a linspace grid"
    )
    n_linear: int = Field(12, ge=2, description="custom grid: linear speeds (Arena Jun 2024: 12)")
    n_angular: int = Field(16, ge=2, description="custom grid: yaw rates (Arena Jun 2024: 16)")
    normalize: bool = Field(
        False, description="continuous: actions in [-1, 1] mapped linearly onto the ranges"
    )


RewardSpec = str | dict[str, dict[str, Any]]
"""A packaged reward file name (``default``) or an inline mapping ``{term: {params}}``."""


class EnvConfig(_Strict):
    """One RL environment: observation, action, reward, timing."""

    observation: ObservationConfig = Field(default_factory=ObservationConfig)
    action: ActionConfig = Field(default_factory=ActionConfig)
    reward: RewardSpec = Field(
        "default",
        description="packaged reward file (default, base_semantic, rule_13, rlca) "
        "or {term: {params}}",
    )
    action_period: float | None = Field(
        None, gt=0, description="s per env step, a multiple of sim.dt; null = sim.dt"
    )
    max_steps: int = Field(500, ge=1, description="env steps before truncation (Arena Jun 2024)")
    safety_distance: float = Field(
        0.5, ge=0, description="m beyond the robot radius; closer laser returns breach it"
    )

    @field_validator("reward", mode="before")
    @classmethod
    def _check_reward(cls, v: Any) -> Any:
        # a ConfigError passes through pydantic and keeps its key path
        from arena.learn.rewards import validate_reward_spec

        validate_reward_spec(v, path="learning.env.reward")
        return v


class LearningConfig(_Strict):
    """The ``learning`` block of an experiment."""

    env: EnvConfig = Field(default_factory=EnvConfig)
    ppo: PPOConfig = Field(default_factory=PPOConfig, description="PPO (arena train)")
    train: TrainConfig = Field(default_factory=TrainConfig, description="arena train run")


def substeps(env: EnvConfig, dt: float) -> int:
    """Simulation steps per env step; ``action_period`` must be a multiple of ``dt``."""
    if env.action_period is None:
        return 1
    k = env.action_period / dt
    if round(k) < 1 or abs(k - round(k)) > 1e-6:
        raise ConfigError(
            f"{env.action_period} s is not a positive multiple of sim.dt = {dt} s",
            path="learning.env.action_period",
        )
    return round(k)
