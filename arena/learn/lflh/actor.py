"""The LfLH policy as a small ``.npz`` file, run with numpy alone.

Layout (:mod:`arena.learn.mlp_file`; written by :func:`save_actor`, read by
:meth:`LflhActor.load`):

================ ===================================================================
``w{i}``, ``b{i}`` linear layers, ``y = x @ w.T + b`` (torch's layout), float32; ReLU
                 between them, none after the last
``meta``         JSON: ``format``, ``policy`` ("lflh"), ``features``
                 (:class:`~arena.learn.lflh.features.FeatureParams`), ``laser`` (the
                 rendered scanner), ``out_scale`` (``[v m/s, ω rad/s]`` by which the raw
                 outputs are multiplied) and ``training`` (command, samples, wall time,
                 hardware)
================ ===================================================================
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.learn.lflh.features import FeatureParams
from arena.learn.mlp_file import (
    WEIGHTS_KEY,
    check_layers,
    mlp_forward,
    read_mlp_file,
    write_mlp_file,
)
from arena.sensors.spec import LidarSpec


@dataclass(frozen=True, eq=False)
class LflhActor:
    """An MLP: input ``(D,)`` (:func:`~arena.learn.lflh.features.policy_input`) → ``[v, ω]``.

    Attributes:
        weights: ``(out, in)`` float32 matrices, one per layer.
        biases: ``(out,)`` float32 vectors.
        features: how the input is built.
        laser: the scanner the training scans were rendered with.
        out_scale: ``(2,)`` scale of the raw outputs (m/s, rad/s).
        meta: the file's whole meta.
    """

    weights: Sequence[NDArray[np.float32]]
    biases: Sequence[NDArray[np.float32]]
    features: FeatureParams
    laser: LidarSpec
    out_scale: NDArray[np.float64]
    meta: dict[str, Any]

    def act(self, x: NDArray[Any]) -> NDArray[np.float64]:
        """The command ``[v m/s, ω rad/s]`` ``(2,)`` (or ``(n, 2)`` for ``(n, D)`` inputs)."""
        return mlp_forward(self.weights, self.biases, x) * self.out_scale

    @classmethod
    def load(cls, path: str | Path) -> LflhActor:
        """Read a policy file.

        Raises:
            ConfigError: missing, unreadable or not an LfLH policy file (one line, naming it).
        """
        weights, biases, meta = read_mlp_file(path, "lflh", "LfLH",
                                              "python -m arena.learn.lflh.train")
        try:
            features = FeatureParams.model_validate(meta["features"])
            laser = LidarSpec.model_validate(meta["laser"])
            scale = np.asarray(meta["out_scale"], dtype=np.float64).reshape(2)
        except (KeyError, TypeError, ValueError) as e:
            raise ConfigError(f"{path}: incomplete LfLH policy file ({e!r})",
                              path=WEIGHTS_KEY) from None
        check_layers(path, weights, biases, features.size, 2, "[v, omega]")
        return cls(weights, biases, features, laser, scale, meta)


def save_actor(
    path: str | Path,
    weights: Sequence[NDArray[Any]],
    biases: Sequence[NDArray[Any]],
    meta: dict[str, Any],
) -> Path:
    """Write a policy file (``meta`` needs ``features``, ``laser`` and ``out_scale``)."""
    return write_mlp_file(path, weights, biases, meta, "lflh")
