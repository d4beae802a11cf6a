"""The APPLR actor as a small ``.npz`` file, run with numpy alone.

Layout (:mod:`arena.learn.mlp_file`; written by :func:`save_actor`, read by
:meth:`ApplrActor.load`):

================ ===================================================================
``w{i}``, ``b{i}`` linear layers, ``y = x @ w.T + b`` (torch's layout), float32; ReLU
                 between them, ``tanh`` after the last (TD3's actor: actions in [-1, 1])
``meta``         JSON: ``format``, ``policy`` ("applr"), ``features``
                 (:meth:`FeatureSpec.to_json`), ``parameters`` (the ranges,
                 :func:`~arena.learn.applr.space.parameter_ranges`), ``period`` (s) and
                 ``training`` (command, steps, wall time, hardware)
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
from arena.learn.applr.space import FeatureSpec, TunedParam, parameters_from_rows
from arena.learn.mlp_file import (
    WEIGHTS_KEY,
    check_layers,
    mlp_forward,
    read_mlp_file,
    write_mlp_file,
)


@dataclass(frozen=True, eq=False)
class ApplrActor:
    """A deterministic TD3 actor: observation ``(D,)`` → action ``(k,)`` in ``[-1, 1]``.

    Attributes:
        weights: ``(out, in)`` float32 matrices, one per layer.
        biases: ``(out,)`` float32 vectors.
        features: how the observation is built.
        parameters: the tuned parameters and their ranges, in action order.
        period: s between two parameter choices the policy was trained with.
        meta: the file's whole meta.
    """

    weights: Sequence[NDArray[np.float32]]
    biases: Sequence[NDArray[np.float32]]
    features: FeatureSpec
    parameters: tuple[TunedParam, ...]
    period: float
    meta: dict[str, Any]

    def act(self, x: NDArray[Any]) -> NDArray[np.float64]:
        """The action ``(k,)`` (or ``(n, k)`` for ``(n, D)`` inputs) for observations ``x``."""
        return mlp_forward(self.weights, self.biases, x, last="tanh")

    @classmethod
    def load(cls, path: str | Path) -> ApplrActor:
        """Read an actor file.

        Raises:
            ConfigError: missing, unreadable or not an APPLR actor file (one line, naming it).
        """
        weights, biases, meta = read_mlp_file(path, "applr", "APPLR",
                                              "python -m arena.learn.applr.train")
        try:
            features = FeatureSpec.from_json(meta["features"])
            parameters = parameters_from_rows(meta["parameters"])
            period = float(meta["period"])
        except (KeyError, TypeError, ValueError) as e:
            raise ConfigError(f"{path}: incomplete APPLR policy file ({e!r})",
                              path=WEIGHTS_KEY) from None
        check_layers(path, weights, biases, features.size(len(parameters)), len(parameters),
                     f"{len(parameters)} parameters")
        return cls(weights, biases, features, parameters, period, meta)


def save_actor(
    path: str | Path,
    weights: Sequence[NDArray[Any]],
    biases: Sequence[NDArray[Any]],
    meta: dict[str, Any],
) -> Path:
    """Write an actor file (``meta`` needs ``features``, ``parameters`` and ``period``)."""
    return write_mlp_file(path, weights, biases, meta, "applr")
