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
from arena.learn.train_config import (
    DrlvoExtractorConfig,
    ExtractorConfig,
    RLCAConvExtractorConfig,
)


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
        convs, channels, length = _conv_stack(
            nn.Conv1d, stack, beams, list(filters), list(kernels), list(strides),
            f"scan of {beams} beams",
        )
        self.other_keys = [k for k in observation_space.spaces if k != scan_key]
        other = sum(math.prod(observation_space[k].shape or ()) for k in self.other_keys)
        super().__init__(observation_space, features_dim=int(fc) + other)
        self.scan_key = scan_key
        self.convs = convs
        self.fc = nn.Sequential(nn.Flatten(), nn.Linear(channels * length, int(fc)), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """``(B, features_dim)`` features of a batch of (normalised) observations."""
        x = observations[self.scan_key]
        if x.dim() == 2:  # one scan (B, beams): one channel
            x = x.unsqueeze(1)
        scan = self.fc(self.convs(x))
        rest = [observations[k].flatten(1) for k in self.other_keys]
        return torch.cat([scan, *rest], dim=1)


def pool_scans_torch(x: torch.Tensor, clip: float, bins: int) -> torch.Tensor:
    """``(B, stack, beams)`` ranges → ``(B, 2·stack, bins)``: min-pooled then mean-pooled scans.

    Ranges are clipped to ``clip`` (m) and divided by it; :func:`arena.learn.policy_conv.
    pool_scans` is the same in numpy.
    """
    b, stack, beams = x.shape
    x = (x.clamp(0.0, clip) / clip).reshape(b, stack, bins, beams // bins)
    return torch.cat([x.amin(dim=3), x.mean(dim=3)], dim=1)


def _conv_stack(
    conv: type[nn.Conv1d] | type[nn.Conv2d], channels: int, size: int,
    filters: list[int], kernels: list[int], strides: list[int], what: str,
) -> tuple[nn.Sequential, int, int]:
    """Conv layers (ReLU after each); returns them, the output channels and side length."""
    layers: list[nn.Module] = []
    for f, k, s in zip(filters, kernels, strides, strict=True):
        if size < k:
            raise ConfigError(
                f"the {what} is too small for the conv layers (kernel {k} on {size})",
                path="learning.ppo.extractor",
            )
        layers += [conv(channels, int(f), int(k), stride=int(s)), nn.ReLU()]
        channels, size = int(f), (size - int(k)) // int(s) + 1
    return nn.Sequential(*layers), channels, size


class DrlvoExtractor(BaseFeaturesExtractor):
    """DRL-VO's encoder (Xie & Dames 2023) as TRAIL uses it: pooled scans + pedestrian map.

    Output ``(B, fc + Σ other sizes)``: the two conv branches flattened (scans first) through
    one fully connected layer (ReLU), then each other key of the Dict space flattened in the
    space's key order (:attr:`other_keys`). The branches are described in
    :class:`~arena.learn.train_config.DrlvoExtractorConfig`.
    """

    def __init__(
        self,
        observation_space: spaces.Dict,
        config: dict[str, Any],
    ) -> None:
        cfg = DrlvoExtractorConfig(**config)
        for key in (cfg.scan_key, cfg.map_key):
            if (not isinstance(observation_space, spaces.Dict)
                    or key not in observation_space.spaces):
                raise ConfigError(
                    f"the drlvo_cnn extractor needs a Dict observation with {key!r} "
                    "(observation.flatten: false, lidar with laser_stack, semantic enabled)",
                    path="learning.ppo.extractor",
                )
        scan_shape = tuple(int(v) for v in observation_space[cfg.scan_key].shape or ())
        map_shape = tuple(int(v) for v in observation_space[cfg.map_key].shape or ())
        if len(scan_shape) != 2 or scan_shape[1] % cfg.scan_bins:
            raise ConfigError(
                f"observation {cfg.scan_key!r} has shape {scan_shape}; expected (stack, beams) "
                f"with beams a multiple of scan_bins {cfg.scan_bins} (laser_stack > 1)",
                path="learning.ppo.extractor",
            )
        if len(map_shape) != 3 or map_shape[1] != map_shape[2]:
            raise ConfigError(
                f"observation {cfg.map_key!r} has shape {map_shape}; expected (channels, size, "
                "size)", path="learning.ppo.extractor",
            )
        scan, sc, sl = _conv_stack(nn.Conv1d, 2 * scan_shape[0], cfg.scan_bins,
                                   cfg.scan_filters, cfg.scan_kernels, cfg.scan_strides,
                                   "pooled scan")
        ped, mc, ml = _conv_stack(nn.Conv2d, map_shape[0], map_shape[1], cfg.map_filters,
                                  cfg.map_kernels, cfg.map_strides, "pedestrian map")
        self.other_keys = [k for k in observation_space.spaces
                           if k not in (cfg.scan_key, cfg.map_key)]
        other = sum(math.prod(observation_space[k].shape or ()) for k in self.other_keys)
        super().__init__(observation_space, features_dim=cfg.fc + other)
        self.config = cfg
        self.scan_convs = scan
        self.map_convs = ped
        self.fc = nn.Sequential(nn.Linear(sc * sl + mc * ml * ml, cfg.fc), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """``(B, features_dim)`` features of a batch of observations."""
        cfg = self.config
        scan = pool_scans_torch(observations[cfg.scan_key], cfg.scan_clip, cfg.scan_bins)
        a = self.scan_convs(scan).flatten(1)
        b = self.map_convs(observations[cfg.map_key]).flatten(1)
        rest = [observations[k].flatten(1) for k in self.other_keys]
        return torch.cat([self.fc(torch.cat([a, b], dim=1)), *rest], dim=1)


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
    if isinstance(extractor, DrlvoExtractorConfig):
        return {
            "features_extractor_class": DrlvoExtractor,
            "features_extractor_kwargs": {"config": extractor.model_dump()},
        }
    return {}
