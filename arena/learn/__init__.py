"""Reinforcement learning: Gymnasium / PettingZoo environments, observations, actions, rewards.

Importing this package registers ``arena/SocialNav-v0`` with Gymnasium when Gymnasium is
installed (the ``learn`` extra); the config and reward modules work without it, since the
experiment schema imports :mod:`arena.learn.config`.

The environments are importable from here (``from arena.learn import BatchedSocialNavEnv``);
they load on first access, so ``import arena.learn`` stays cheap and works without Gymnasium.
"""

from __future__ import annotations

import importlib
from typing import Any

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

_LAZY = {
    "SocialNavEnv": "arena.learn.env",
    "BatchedSocialNavEnv": "arena.learn.batched",
    "MultiRobotEnv": "arena.learn.multi",
}
"""Environments importable from this package, by the module that defines them."""


def __getattr__(name: str) -> Any:
    """Import an environment class of :data:`_LAZY` on first access."""
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if gymnasium is None:
        raise ImportError(f"arena.learn.{name} needs Gymnasium: pip install 'arena[learn]'")
    return getattr(importlib.import_module(module), name)


__all__ = [
    "ENV_ID",
    "REWARD_TERMS",
    "BatchedSocialNavEnv",
    "EnvConfig",
    "LearningConfig",
    "MultiRobotEnv",
    "RewardFunction",
    "RewardInput",
    "SocialNavEnv",
]
