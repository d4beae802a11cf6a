"""The RGB-D people detector's network, run in numpy: a small fully convolutional segmenter.

:class:`PixelNet` maps the detector's input image ``(C, h, w)`` (:func:`~arena.perception.
rgbd_detector.net_input`) to a person logit per pixel ``(h, w)``. Architecture (:data:`LAYERS`;
every convolution 3 × 3 with "same" zero padding, ReLU after each but the last)::

    x (C, h, w) ─ conv1 16 ─ a ─ conv2 32, stride 2 ─ conv3 32, dilation 2 ─ conv4 32, dilation 4
                             │                                                        │
                             └──────────── concat ─ upsample × 2 (nearest) ───────────┘
                                              │
                                           conv5 16 ─ conv6 1 × 1 ─ logit (h, w)

The dilated half-resolution layers see about 60 input pixels across (a near person's width);
the skip connection keeps the full-resolution edges. :func:`torch_pixelnet` builds the same
architecture as a torch module for training (``tools/train_rgbd_detector.py``, torch from the
``train`` extra), whose weights load here (``w1`` ``(16, C, 3, 3)`` … ``w6`` ``(1, 16, 1, 1)``,
``b1`` … ``b6``, as torch's ``Conv2d`` stores them).

A convolution here is one matrix product over the image's shifted copies (im2col), float32
throughout: about 65 MFLOP for an 80 × 60 input.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

F32 = NDArray[np.float32]

LAYERS: tuple[tuple[str, int, int], ...] = (
    ("1", 1, 1), ("2", 2, 1), ("3", 1, 2), ("4", 1, 4), ("5", 1, 1), ("6", 1, 1),
)
"""``(name, stride, dilation)`` of each convolution, in order."""

WIDTHS: dict[str, tuple[int, int] | int] = {"1": 16, "2": (16, 32), "3": (32, 32),
                                           "4": (32, 32), "5": (48, 16), "6": (16, 1)}
"""``(in, out)`` channels of each convolution (``"1"``: its output; its input is the image's)."""


def conv2d(x: F32, w: F32, b: F32, stride: int = 1, dilation: int = 1) -> F32:
    """Cross-correlation of ``x`` ``(C, H, W)`` with ``w`` ``(O, C, k, k)`` plus ``b`` ``(O,)``.

    "Same" zero padding (``dilation · (k - 1) / 2`` on each side, ``k`` odd): the output is
    ``(O, ceil(H / stride), ceil(W / stride))``, as torch's ``Conv2d(padding=…)`` gives.
    """
    o, c, k, _ = w.shape
    pad = dilation * (k - 1) // 2
    _, h, wd = x.shape
    ho, wo = (h - 1) // stride + 1, (wd - 1) // stride + 1
    if k == 1:
        cols = x[:, ::stride, ::stride].reshape(c, ho * wo)
    else:
        xp = np.pad(x, ((0, 0), (pad, pad), (pad, pad)))
        cols = np.empty((c, k, k, ho, wo), dtype=np.float32)
        for i in range(k):
            for j in range(k):
                y0, x0 = i * dilation, j * dilation
                cols[:, i, j] = xp[:, y0 : y0 + stride * (ho - 1) + 1 : stride,
                                   x0 : x0 + stride * (wo - 1) + 1 : stride]
        cols = cols.reshape(c * k * k, ho * wo)
    out: F32 = (w.reshape(o, c * k * k) @ cols).reshape(o, ho, wo)
    out += b[:, None, None]
    return out


class PixelNet:
    """The network with its weights (a mapping with ``w1`` … ``w6``, ``b1`` … ``b6``)."""

    def __init__(self, weights: Mapping[str, NDArray[np.floating]]) -> None:
        self.w = {n: np.ascontiguousarray(weights[f"w{n}"], dtype=np.float32) for n, *_ in LAYERS}
        self.b = {n: np.ascontiguousarray(weights[f"b{n}"], dtype=np.float32) for n, *_ in LAYERS}
        self.in_channels = int(self.w["1"].shape[1])

    def _conv(self, x: F32, name: str, relu: bool = True) -> F32:
        _, stride, dilation = next(layer for layer in LAYERS if layer[0] == name)
        y = conv2d(x, self.w[name], self.b[name], stride, dilation)
        return np.maximum(y, 0.0, out=y) if relu else y

    def logits(self, x: F32) -> F32:
        """``(h, w)`` person logits of the input ``(C, h, w)``."""
        x = np.asarray(x, dtype=np.float32)
        if x.ndim != 3 or x.shape[0] != self.in_channels:
            raise ValueError(f"expected a ({self.in_channels}, h, w) input, got {x.shape}")
        a = self._conv(x, "1")
        d = self._conv(self._conv(self._conv(a, "2"), "3"), "4")
        up = d.repeat(2, axis=1).repeat(2, axis=2)[:, : a.shape[1], : a.shape[2]]
        e = self._conv(np.concatenate([a, up]), "5")
        return self._conv(e, "6", relu=False)[0]


def torch_pixelnet(channels: int) -> Any:
    """The network as a ``torch.nn.Module`` for ``channels`` input channels (for training).

    Its ``convs[name]`` are the ``Conv2d`` layers of :data:`LAYERS`; ``forward`` maps
    ``(N, C, h, w)`` to ``(N, 1, h, w)`` logits exactly as :meth:`PixelNet.logits` does.
    """
    import torch
    from torch import nn

    def width(name: str) -> tuple[int, int]:
        w = WIDTHS[name]
        return (channels, w) if isinstance(w, int) else w

    class TorchPixelNet(nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.convs = nn.ModuleDict({
                n: nn.Conv2d(*width(n), kernel_size=1 if n == "6" else 3, stride=s,
                             dilation=d, padding=0 if n == "6" else d)
                for n, s, d in LAYERS
            })

        def forward(self, x: torch.Tensor) -> torch.Tensor:
            c = self.convs
            a = torch.relu(c["1"](x))
            d = torch.relu(c["4"](torch.relu(c["3"](torch.relu(c["2"](a))))))
            up = d.repeat_interleave(2, dim=2).repeat_interleave(2, dim=3)
            up = up[:, :, : a.shape[2], : a.shape[3]]
            out: torch.Tensor = c["6"](torch.relu(c["5"](torch.cat([a, up], dim=1))))
            return out

    return TorchPixelNet()
