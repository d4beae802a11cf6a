"""Small, fast experiment configs for the RL environment tests."""

from __future__ import annotations

from arena.config.loader import load_config
from arena.config.schema import ExperimentConfig
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot

BASE = (
    "map={type: empty, width: 8, height: 8, resolution: 0.1}",
    "task.obstacles={type: random, static: 0, dynamic: 3}",
    "task.robots.min_goal_distance=3.0",
    "learning.env.max_steps=40",
)


def small_cfg(*overrides: str) -> ExperimentConfig:
    """An 8 × 8 m empty room, three people, 40 steps per episode."""
    return load_config(None, [*BASE, *overrides])


def small_robot(beams: int = 24) -> RobotModel:
    """The Jackal with ``beams`` laser beams (fast ray casting)."""
    jackal = load_robot("jackal")
    return jackal.model_copy(update={"laser": jackal.laser.model_copy(update={"num_beams": beams})})
