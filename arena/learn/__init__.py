"""Reinforcement learning: Gymnasium / PettingZoo environments, observations, actions, rewards.

Importing this package registers ``arena/SocialNav-v0`` with Gymnasium when Gymnasium is
installed (the ``learn`` extra); the config and reward modules work without it, since the
experiment schema imports :mod:`arena.learn.config`.
"""

from __future__ import annotations

from arena.learn.config import EnvConfig, LearningConfig
from arena.learn.rewards import REWARD_TERMS, RewardFunction, RewardInput

ENV_ID = "arena/SocialNav-v0"
"""The Gymnasium id of :class:`~arena.learn.env.SocialNavEnv`."""

try:
    import gymnasium
except ImportError:  # pragma: no cover - the learn extra is not installed
    gymnasium = None

if gymnasium is not None and ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="arena.learn.env:SocialNavEnv")

__all__ = ["ENV_ID", "REWARD_TERMS", "EnvConfig", "LearningConfig", "RewardFunction", "RewardInput"]
