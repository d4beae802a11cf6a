"""The APPLR actor as a small ``.npz`` file, run with numpy alone.

Layout (written by :func:`save_actor`, read by :meth:`ApplrActor.load`):

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

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.learn.applr.space import FeatureSpec, TunedParam, parameters_from_rows

FORMAT = 1
"""Version of the file layout."""
WEIGHTS_KEY = "navigation.local_planner.weights"
"""Where a bad file is named in errors (the planner's parameter)."""


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
        h = np.asarray(x, dtype=np.float32)
        last = len(self.weights) - 1
        for i, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            h = h @ w.T + b
            h = np.tanh(h) if i == last else np.maximum(h, 0.0)
        return h.astype(np.float64)

    @classmethod
    def load(cls, path: str | Path) -> ApplrActor:
        """Read an actor file.

        Raises:
            ConfigError: missing, unreadable or not an APPLR actor file (one line, naming it).
        """
        p = Path(path)
        if not p.is_file():
            raise ConfigError(
                f"no APPLR policy file {str(p)!r}: train one with `python -m "
                "arena.learn.applr.train -o RUN` and pass weights: RUN/policy.npz",
                path=WEIGHTS_KEY,
            )
        try:
            with np.load(p, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
            meta = json.loads(str(arrays.pop("meta")))
        except (OSError, ValueError, KeyError) as e:
            raise ConfigError(f"{p}: not an APPLR policy file ({e})", path=WEIGHTS_KEY) from None
        if meta.get("policy") != "applr" or meta.get("format") != FORMAT:
            raise ConfigError(
                f"{p}: not an APPLR policy file of format {FORMAT} (policy "
                f"{meta.get('policy')!r}, format {meta.get('format')!r})", path=WEIGHTS_KEY,
            )
        n = sum(1 for k in arrays if k.startswith("w"))
        try:
            weights = [np.asarray(arrays[f"w{i}"], np.float32) for i in range(n)]
            biases = [np.asarray(arrays[f"b{i}"], np.float32) for i in range(n)]
            features = FeatureSpec.from_json(meta["features"])
            parameters = parameters_from_rows(meta["parameters"])
            period = float(meta["period"])
        except (KeyError, TypeError, ValueError) as e:
            raise ConfigError(f"{p}: incomplete APPLR policy file ({e!r})",
                              path=WEIGHTS_KEY) from None
        dims = [features.size(len(parameters))] + [w.shape[0] for w in weights]
        shapes_ok = n > 0 and all(
            w.shape == (dims[i + 1], dims[i]) and b.shape == (dims[i + 1],)
            for i, (w, b) in enumerate(zip(weights, biases, strict=True))
        ) and dims[-1] == len(parameters)
        if not shapes_ok:
            raise ConfigError(
                f"{p}: layer shapes {[w.shape for w in weights]} do not map "
                f"{dims[0]} features to {len(parameters)} parameters", path=WEIGHTS_KEY,
            )
        return cls(weights, biases, features, parameters, period, meta)


def save_actor(
    path: str | Path,
    weights: Sequence[NDArray[Any]],
    biases: Sequence[NDArray[Any]],
    meta: dict[str, Any],
) -> Path:
    """Write an actor file (``meta`` needs ``features``, ``parameters`` and ``period``)."""
    arrays: dict[str, NDArray[Any]] = {}
    for i, (w, b) in enumerate(zip(weights, biases, strict=True)):
        arrays[f"w{i}"] = np.asarray(w, dtype=np.float32)
        arrays[f"b{i}"] = np.asarray(b, dtype=np.float32)
    arrays["meta"] = np.array(json.dumps({**meta, "format": FORMAT, "policy": "applr"}))
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("wb") as f:  # np.savez would append .npz to a name without it
        np.savez(f, allow_pickle=False, **arrays)
    return out
