"""Stable-Baselines3 feature extractors selected by ``learning.ppo.extractor`` (needs torch).

:class:`RLCAConvExtractor` is the scan encoder of Long et al. 2018 ("Towards Optimally
Decentralized Multi-Robot Collision Avoidance via Deep Reinforcement Learning", Fig. 3): the
stacked laser scans ``(stack, beams)`` are read as a 1-D signal over the beams with the stack as
input channels, through ``Conv1d(32, 5, stride 2) → ReLU → Conv1d(32, 3, stride 2) → ReLU →
Linear(256) → ReLU``; the other observation parts (goal, velocity, ...) are flattened and
appended. SB3's ``net_arch`` then adds the paper's 128-unit layer before the action and value
heads. :mod:`arena.learn.policy` exports it for numpy inference.
"""

from __future__ import annotations

import math
from typing import Any

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from arena.core.errors import ConfigError
from arena.learn.train_config import ExtractorConfig, RLCAConvExtractorConfig


class RLCAConvExtractor(BaseFeaturesExtractor):
    """Conv1d scan encoder + flattened remaining parts (Long et al. 2018).

    Output ``(B, fc + Σ other sizes)``: the scan features first, then each other key of the Dict
    space flattened in the space's key order (:attr:`other_keys`).

    Args:
        observation_space: a Dict space holding ``scan_key`` with shape ``(stack, beams)``
            (or ``(beams,)``: one channel).
        scan_key, filters, kernels, strides, fc: see
            :class:`~arena.learn.train_config.RLCAConvExtractorConfig`.
    """

    def __init__(
        self,
        observation_space: spaces.Dict,
        scan_key: str = "lidar",
        filters: tuple[int, ...] = (32, 32),
        kernels: tuple[int, ...] = (5, 3),
        strides: tuple[int, ...] = (2, 2),
        fc: int = 256,
    ) -> None:
        if (not isinstance(observation_space, spaces.Dict)
                or scan_key not in observation_space.spaces):
            raise ConfigError(
                f"the rlca_conv extractor needs a Dict observation with {scan_key!r} "
                "(observation.flatten: false, observation.lidar: true)",
                path="learning.ppo.extractor",
            )
        scan_shape = tuple(int(v) for v in observation_space[scan_key].shape or ())
        if len(scan_shape) not in (1, 2):
            raise ConfigError(
                f"observation {scan_key!r} has shape {scan_shape}; expected (beams,) or "
                "(stack, beams)",
                path="learning.ppo.extractor",
            )
        stack, beams = scan_shape if len(scan_shape) == 2 else (1, scan_shape[0])
        layers: list[nn.Module] = []
        channels, length = stack, beams
        for f, k, s in zip(filters, kernels, strides, strict=True):
            if length < k:
                raise ConfigError(
                    f"{beams} beams are too few for the conv layers (kernel {k} on {length})",
                    path="learning.ppo.extractor",
                )
            layers += [nn.Conv1d(channels, int(f), int(k), stride=int(s)), nn.ReLU()]
            channels, length = int(f), (length - int(k)) // int(s) + 1
        self.other_keys = [k for k in observation_space.spaces if k != scan_key]
        other = sum(math.prod(observation_space[k].shape or ()) for k in self.other_keys)
        super().__init__(observation_space, features_dim=int(fc) + other)
        self.scan_key = scan_key
        self.convs = nn.Sequential(*layers)
        self.fc = nn.Sequential(nn.Flatten(), nn.Linear(channels * length, int(fc)), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """``(B, features_dim)`` features of a batch of (normalised) observations."""
        x = observations[self.scan_key]
        if x.dim() == 2:  # one scan (B, beams): one channel
            x = x.unsqueeze(1)
        scan = self.fc(self.convs(x))
        rest = [observations[k].flatten(1) for k in self.other_keys]
        return torch.cat([scan, *rest], dim=1)


def policy_kwargs_for(extractor: ExtractorConfig) -> dict[str, Any]:
    """SB3 ``policy_kwargs`` entries selecting ``extractor`` (empty for ``flatten``)."""
    if isinstance(extractor, RLCAConvExtractorConfig):
        return {
            "features_extractor_class": RLCAConvExtractor,
            "features_extractor_kwargs": {
                "scan_key": extractor.scan_key,
                "filters": tuple(extractor.filters),
                "kernels": tuple(extractor.kernels),
                "strides": tuple(extractor.strides),
                "fc": extractor.fc,
            },
        }
    return {}
