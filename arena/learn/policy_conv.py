"""Conv feature extractors of exported policies: their ``.npz`` entries and numpy forward.

:func:`export_extractor` (needs torch) turns an SB3 extractor of :mod:`arena.learn.extractors`
into arrays and a ``meta["extractor"]`` entry; :func:`numpy_extractor` reads them back as a
callable ``parts → (B, D)`` features that equals the torch forward (float64 arithmetic on the
float32 weights). :mod:`arena.learn.policy` writes and reads the rest of the file.

============================ ===============================================================
``rlca_conv``                 ``fx/conv{i}/w`` ``(out, in, kernel)``, ``fx/conv{i}/b``: Conv1d
                              layers over the scan (ReLU after each); ``fx/fc/w``, ``fx/fc/b``
                              its fully connected layer (ReLU). Meta: ``scan_key``,
                              ``strides``, ``other_keys``.
``drlvo_cnn``                 ``fx/scan{i}/w|b`` Conv1d over the pooled scans, ``fx/map{i}/w|b``
                              Conv2d ``(out, in, k, k)`` over the pedestrian map, ``fx/fc/w|b``.
                              Meta: the extractor config (keys, clip, bins, strides) and
                              ``other_keys``.
============================ ===============================================================
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError

Features = Callable[[Mapping[str, NDArray[np.float64]]], NDArray[np.float64]]
"""Normalised observation parts (per key ``(B, *shape)``) → ``(B, D)`` features."""


def to_numpy(t: Any) -> NDArray[np.float32]:
    """A torch tensor (or parameter) as a float32 array."""
    return np.asarray(t.detach().cpu().numpy(), dtype=np.float32)


def conv1d(
    x: NDArray[np.float64], w: NDArray[np.float64], b: NDArray[np.float64], stride: int
) -> NDArray[np.float64]:
    """Torch's ``Conv1d`` (no padding, no dilation) in numpy.

    Args:
        x: ``(B, C, L)`` input.
        w: ``(O, C, K)`` weights.
        b: ``(O,)`` bias.
        stride: step between windows.

    Returns:
        ``(B, O, (L − K) // stride + 1)``.
    """
    k = w.shape[2]
    win = np.lib.stride_tricks.sliding_window_view(x, k, axis=2)[:, :, ::stride, :]
    out = np.einsum("bclk,ock->bol", win, w, optimize=True) + b[None, :, None]
    return np.asarray(out, dtype=np.float64)


def conv2d(
    x: NDArray[np.float64], w: NDArray[np.float64], b: NDArray[np.float64], stride: int
) -> NDArray[np.float64]:
    """Torch's ``Conv2d`` (square kernel, no padding, no dilation) in numpy.

    Args:
        x: ``(B, C, H, W)`` input.
        w: ``(O, C, K, K)`` weights.
        b: ``(O,)`` bias.
        stride: step between windows along both axes.

    Returns:
        ``(B, O, (H − K) // stride + 1, (W − K) // stride + 1)``.
    """
    k = w.shape[2]
    win = np.lib.stride_tricks.sliding_window_view(x, (k, k), axis=(2, 3))
    win = win[:, :, ::stride, ::stride]
    out = np.einsum("bchwij,ocij->bohw", win, w, optimize=True) + b[None, :, None, None]
    return np.asarray(out, dtype=np.float64)


def pool_scans(x: NDArray[np.float64], clip: float, bins: int) -> NDArray[np.float64]:
    """``(B, stack, beams)`` ranges (m) → ``(B, 2·stack, bins)`` pooled scans in ``[0, 1]``.

    Ranges are clipped to ``clip`` and divided by it; each scan's beams are split into ``bins``
    equal runs, giving first the minimum of each run (the nearest obstacle, DRL-VO's min
    pooling) for every scan, then the mean. The torch twin used in training is
    :func:`arena.learn.extractors.pool_scans_torch`.
    """
    b, stack, beams = x.shape
    y = (np.clip(x, 0.0, clip) / clip).reshape(b, stack, bins, beams // bins)
    return np.concatenate([y.min(axis=3), y.mean(axis=3)], axis=1)


def _relu(x: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.maximum(x, 0.0)


def export_extractor(extractor: Any) -> tuple[dict[str, NDArray[Any]], dict[str, Any]]:
    """The arrays and meta entry of a conv extractor (needs torch).

    Raises:
        TypeError: ``extractor`` is not one of the conv extractors.
    """
    import torch.nn as nn

    from arena.learn.extractors import DrlvoExtractor, RLCAConvExtractor

    arrays: dict[str, NDArray[Any]] = {}
    if isinstance(extractor, RLCAConvExtractor):
        convs = [m for m in extractor.convs if isinstance(m, nn.Conv1d)]
        for i, conv in enumerate(convs):
            arrays[f"fx/conv{i}/w"] = to_numpy(conv.weight)
            arrays[f"fx/conv{i}/b"] = to_numpy(conv.bias)
        fc = extractor.fc[1]
        meta: dict[str, Any] = {
            "type": "rlca_conv",
            "scan_key": extractor.scan_key,
            "strides": [int(c.stride[0]) for c in convs],
            "other_keys": list(extractor.other_keys),
        }
    elif isinstance(extractor, DrlvoExtractor):
        for name, seq in (("scan", extractor.scan_convs), ("map", extractor.map_convs)):
            layers = [m for m in seq if isinstance(m, nn.Conv1d | nn.Conv2d)]
            for i, layer in enumerate(layers):
                arrays[f"fx/{name}{i}/w"] = to_numpy(layer.weight)
                arrays[f"fx/{name}{i}/b"] = to_numpy(layer.bias)
        fc = extractor.fc[0]
        meta = {
            "type": "drlvo_cnn",
            "config": extractor.config.model_dump(),
            "other_keys": list(extractor.other_keys),
        }
    else:
        raise TypeError(f"{type(extractor).__name__} is not a conv extractor")
    arrays["fx/fc/w"] = to_numpy(fc.weight)
    arrays["fx/fc/b"] = to_numpy(fc.bias)
    return arrays, meta


def _layers(
    arrays: Mapping[str, NDArray[Any]], prefix: str, strides: list[int]
) -> list[tuple[NDArray[np.float64], NDArray[np.float64], int]]:
    return [
        (arrays[f"fx/{prefix}{i}/w"].astype(np.float64),
         arrays[f"fx/{prefix}{i}/b"].astype(np.float64), int(s))
        for i, s in enumerate(strides)
    ]


def numpy_extractor(
    meta: Mapping[str, Any], arrays: Mapping[str, NDArray[Any]], source: str
) -> Features:
    """The numpy forward of the extractor ``meta`` describes (``meta["extractor"]``).

    Raises:
        ConfigError: an unknown extractor type.
    """
    kind = meta.get("type")
    fc_w = arrays["fx/fc/w"].astype(np.float64)
    fc_b = arrays["fx/fc/b"].astype(np.float64)
    other = list(meta["other_keys"])

    def rest(parts: Mapping[str, NDArray[np.float64]]) -> list[NDArray[np.float64]]:
        return [parts[k].reshape(parts[k].shape[0], -1) for k in other]

    if kind == "rlca_conv":
        convs = _layers(arrays, "conv", list(meta["strides"]))
        scan_key = str(meta["scan_key"])

        def rlca(parts: Mapping[str, NDArray[np.float64]]) -> NDArray[np.float64]:
            x = parts[scan_key]  # (B, stack, beams): channels × length
            if x.ndim == 2:  # one scan (B, beams): one channel
                x = x[:, None, :]
            for w, b, stride in convs:
                x = _relu(conv1d(x, w, b, stride))
            scan = _relu(x.reshape(x.shape[0], -1) @ fc_w.T + fc_b)
            return np.concatenate([scan, *rest(parts)], axis=1)

        return rlca
    if kind == "drlvo_cnn":
        cfg = meta["config"]
        scan_convs = _layers(arrays, "scan", list(cfg["scan_strides"]))
        map_convs = _layers(arrays, "map", list(cfg["map_strides"]))

        def drlvo(parts: Mapping[str, NDArray[np.float64]]) -> NDArray[np.float64]:
            x = pool_scans(parts[cfg["scan_key"]], float(cfg["scan_clip"]), int(cfg["scan_bins"]))
            for w, b, stride in scan_convs:
                x = _relu(conv1d(x, w, b, stride))
            m = parts[cfg["map_key"]]
            for w, b, stride in map_convs:
                m = _relu(conv2d(m, w, b, stride))
            n = x.shape[0]
            both = np.concatenate([x.reshape(n, -1), m.reshape(n, -1)], axis=1)
            return np.concatenate([_relu(both @ fc_w.T + fc_b), *rest(parts)], axis=1)

        return drlvo
    raise ConfigError(f"unknown feature extractor {kind!r}", source=source)
