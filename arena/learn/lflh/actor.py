"""The LfLH policy as a small ``.npz`` file, run with numpy alone.

Layout (written by :func:`save_actor`, read by :meth:`LflhActor.load`):

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

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.learn.lflh.features import FeatureParams
from arena.sensors.spec import LidarSpec

FORMAT = 1
"""Version of the file layout."""
WEIGHTS_KEY = "navigation.local_planner.weights"
"""Where a bad file is named in errors (the planner's parameter)."""


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
        h = np.asarray(x, dtype=np.float32)
        last = len(self.weights) - 1
        for i, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            h = h @ w.T + b
            if i < last:
                h = np.maximum(h, 0.0)
        return h.astype(np.float64) * self.out_scale

    @classmethod
    def load(cls, path: str | Path) -> LflhActor:
        """Read a policy file.

        Raises:
            ConfigError: missing, unreadable or not an LfLH policy file (one line, naming it).
        """
        p = Path(path)
        if not p.is_file():
            raise ConfigError(
                f"no LfLH policy file {str(p)!r}: train one with `python -m "
                "arena.learn.lflh.train -o RUN` and pass weights: RUN/policy.npz",
                path=WEIGHTS_KEY,
            )
        try:
            with np.load(p, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
            meta = json.loads(str(arrays.pop("meta")))
        except (OSError, ValueError, KeyError) as e:
            raise ConfigError(f"{p}: not an LfLH policy file ({e})", path=WEIGHTS_KEY) from None
        if meta.get("policy") != "lflh" or meta.get("format") != FORMAT:
            raise ConfigError(
                f"{p}: not an LfLH policy file of format {FORMAT} (policy "
                f"{meta.get('policy')!r}, format {meta.get('format')!r})", path=WEIGHTS_KEY,
            )
        n = sum(1 for k in arrays if k.startswith("w"))
        try:
            weights = [np.asarray(arrays[f"w{i}"], np.float32) for i in range(n)]
            biases = [np.asarray(arrays[f"b{i}"], np.float32) for i in range(n)]
            features = FeatureParams.model_validate(meta["features"])
            laser = LidarSpec.model_validate(meta["laser"])
            scale = np.asarray(meta["out_scale"], dtype=np.float64).reshape(2)
        except (KeyError, TypeError, ValueError) as e:
            raise ConfigError(f"{p}: incomplete LfLH policy file ({e!r})",
                              path=WEIGHTS_KEY) from None
        dims = [features.size] + [w.shape[0] for w in weights]
        shapes_ok = n > 0 and dims[-1] == 2 and all(
            w.shape == (dims[i + 1], dims[i]) and b.shape == (dims[i + 1],)
            for i, (w, b) in enumerate(zip(weights, biases, strict=True))
        )
        if not shapes_ok:
            raise ConfigError(
                f"{p}: layer shapes {[w.shape for w in weights]} do not map "
                f"{dims[0]} features to [v, omega]", path=WEIGHTS_KEY,
            )
        return cls(weights, biases, features, laser, scale, meta)


def save_actor(
    path: str | Path,
    weights: Sequence[NDArray[Any]],
    biases: Sequence[NDArray[Any]],
    meta: dict[str, Any],
) -> Path:
    """Write a policy file (``meta`` needs ``features``, ``laser`` and ``out_scale``)."""
    arrays: dict[str, NDArray[Any]] = {}
    for i, (w, b) in enumerate(zip(weights, biases, strict=True)):
        arrays[f"w{i}"] = np.asarray(w, dtype=np.float32)
        arrays[f"b{i}"] = np.asarray(b, dtype=np.float32)
    arrays["meta"] = np.array(json.dumps({**meta, "format": FORMAT, "policy": "lflh"}))
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("wb") as f:  # np.savez would append .npz to a name without it
        np.savez(f, allow_pickle=False, **arrays)
    return out
