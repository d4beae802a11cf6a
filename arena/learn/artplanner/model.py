"""ArtPlanner's motion-cost network as a small ``.npz`` file, run with numpy alone.

Layout (:mod:`arena.learn.mlp_file`; written by :func:`save_model`, read by
:meth:`MotionCostModel.load`):

================ ===================================================================
``w{i}``, ``b{i}`` linear layers, ``y = x @ w.T + b`` (torch's layout), float32; ReLU
                 between them, none after the last
``meta``         JSON: ``format``, ``policy`` ("artplanner"), ``features``
                 (:class:`~arena.learn.artplanner.features.EdgeFeatureParams`),
                 ``stepping`` (the labelling robot,
                 :class:`~arena.learn.artplanner.stepping.SteppingParams`), ``time_scale``
                 (s/m per unit of the second output) and ``training``
================ ===================================================================

Outputs: ``[logit of feasibility, time per metre / time_scale]``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.learn.artplanner.features import EdgeFeatureParams
from arena.learn.artplanner.stepping import SteppingParams
from arena.learn.mlp_file import check_layers, mlp_forward, read_mlp_file, write_mlp_file

MODEL_KEY = "navigation.global_planner.weights"
"""Where a bad model file is named in errors."""
TRAIN_COMMAND = "python -m arena.learn.artplanner.train"
ARTPLANNER_WEIGHTS = Path(__file__).resolve().parents[1] / "data" / "policies" / "artplanner.npz"
"""The packaged motion-cost model (``arena/learn/data/policies/artplanner.npz``)."""


@dataclass(frozen=True, eq=False)
class MotionCostModel:
    """An MLP: edge height patch ``(D,)`` → feasibility probability and traversal time.

    Attributes:
        weights: ``(out, in)`` float32 matrices, one per layer.
        biases: ``(out,)`` float32 vectors.
        features: the patch layout the network was trained on.
        stepping: the robot whose stepping model made the labels.
        time_scale: s/m per unit of the time output.
        meta: the file's whole meta.
    """

    weights: Sequence[NDArray[np.float32]]
    biases: Sequence[NDArray[np.float32]]
    features: EdgeFeatureParams
    stepping: SteppingParams
    time_scale: float
    meta: dict[str, Any]

    def raw(self, x: NDArray[Any]) -> NDArray[np.float64]:
        """The network's outputs ``(n, 2)`` for inputs ``(n, D)``."""
        return mlp_forward(self.weights, self.biases, np.asarray(x, dtype=np.float32))

    def predict(self, x: NDArray[Any]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(p_feasible (n,), time per metre (n,) s/m)`` for edge inputs ``(n, D)``."""
        out = self.raw(x).reshape(-1, 2)
        p = 1.0 / (1.0 + np.exp(-np.clip(out[:, 0], -50, 50)))
        # Never faster than the robot's top speed: the output is a learned estimate.
        t = np.maximum(out[:, 1] * self.time_scale, 1.0 / self.stepping.v_max)
        return p, t

    @classmethod
    def load(cls, path: str | Path) -> MotionCostModel:
        """Read a model file.

        Raises:
            ConfigError: missing, unreadable or not an ArtPlanner model file (one line).
        """
        weights, biases, meta = read_mlp_file(path, "artplanner", "ArtPlanner motion-cost",
                                              TRAIN_COMMAND)
        try:
            features = EdgeFeatureParams.model_validate(meta["features"])
            stepping = SteppingParams.model_validate(meta["stepping"])
            time_scale = float(meta["time_scale"])
        except (KeyError, TypeError, ValueError) as e:
            raise ConfigError(f"{path}: incomplete ArtPlanner model file ({e!r})",
                              path=MODEL_KEY) from None
        check_layers(path, weights, biases, features.size, 2, "[feasible logit, time]")
        return cls(weights, biases, features, stepping, time_scale, meta)


def save_model(path: str | Path, weights: Sequence[NDArray[Any]], biases: Sequence[NDArray[Any]],
               meta: dict[str, Any]) -> Path:
    """Write a model file (``meta`` needs ``features``, ``stepping``, ``time_scale``)."""
    return write_mlp_file(path, weights, biases, meta, "artplanner")
