"""Small MLP policies as ``.npz`` files, run with numpy alone (APPLR's actor, LfLH's policy).

Layout: ``w{i}``, ``b{i}`` the linear layers, ``y = x @ w.T + b`` (torch's layout), float32,
ReLU between them; ``meta`` a JSON string with at least ``format`` and ``policy`` (the planner
that reads the file) and whatever that planner needs. Every problem with a file is one
:class:`ConfigError` naming it and the planner's ``weights`` parameter.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError

FORMAT = 1
"""Version of the file layout."""
WEIGHTS_KEY = "navigation.local_planner.weights"
"""Where a bad file is named in errors (the planner's parameter)."""


def mlp_forward(weights: Sequence[NDArray[np.float32]], biases: Sequence[NDArray[np.float32]],
                x: NDArray[Any], last: Literal["linear", "tanh"] = "linear"
                ) -> NDArray[np.float64]:
    """The MLP's output ``(out,)`` (or ``(n, out)`` for ``(n, in)`` inputs) for ``x``.

    ReLU between the layers; after the last one nothing or ``tanh``.
    """
    h = np.asarray(x, dtype=np.float32)
    final = len(weights) - 1
    for i, (w, b) in enumerate(zip(weights, biases, strict=True)):
        h = h @ w.T + b
        if i < final:
            h = np.maximum(h, 0.0)
        elif last == "tanh":
            h = np.tanh(h)
    return h.astype(np.float64)


def read_mlp_file(path: str | Path, policy: str, what: str, train_command: str
                  ) -> tuple[list[NDArray[np.float32]], list[NDArray[np.float32]], dict[str, Any]]:
    """``(weights, biases, meta)`` of the ``policy`` file at ``path``.

    Args:
        path: the ``.npz`` file.
        policy: the ``meta["policy"]`` the file must carry (``"applr"``).
        what: the policy's name in messages (``"APPLR"``).
        train_command: how to make one (named when the file is missing).

    Raises:
        ConfigError: missing, unreadable, another policy's or another format's file.
    """
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"no {what} policy file {str(p)!r}: train one with `{train_command} -o "
                          "RUN` and pass weights: RUN/policy.npz", path=WEIGHTS_KEY)
    try:
        with np.load(p, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        meta = json.loads(str(arrays.pop("meta")))
    except (OSError, ValueError, KeyError) as e:
        raise ConfigError(f"{p}: not an {what} policy file ({e})", path=WEIGHTS_KEY) from None
    if not isinstance(meta, dict) or meta.get("policy") != policy \
            or meta.get("format") != FORMAT:
        got = meta if isinstance(meta, dict) else {}
        raise ConfigError(
            f"{p}: not an {what} policy file of format {FORMAT} (policy "
            f"{got.get('policy')!r}, format {got.get('format')!r})", path=WEIGHTS_KEY)
    n = sum(1 for k in arrays if k.startswith("w"))
    try:
        weights = [np.asarray(arrays[f"w{i}"], np.float32) for i in range(n)]
        biases = [np.asarray(arrays[f"b{i}"], np.float32) for i in range(n)]
    except KeyError as e:
        raise ConfigError(f"{p}: incomplete {what} policy file ({e!r})",
                          path=WEIGHTS_KEY) from None
    return weights, biases, meta


def check_layers(path: str | Path, weights: Sequence[NDArray[Any]],
                 biases: Sequence[NDArray[Any]], n_in: int, n_out: int, outputs: str) -> None:
    """Raise a one-line :class:`ConfigError` unless the layers map ``n_in`` to ``n_out``.

    ``outputs`` names the outputs in the message (``"[v, omega]"``).
    """
    dims = [n_in] + [w.shape[0] for w in weights]
    ok = len(weights) > 0 and dims[-1] == n_out and all(
        w.shape == (dims[i + 1], dims[i]) and b.shape == (dims[i + 1],)
        for i, (w, b) in enumerate(zip(weights, biases, strict=True)))
    if not ok:
        raise ConfigError(f"{path}: layer shapes {[w.shape for w in weights]} do not map "
                          f"{n_in} features to {outputs}", path=WEIGHTS_KEY)


def write_mlp_file(path: str | Path, weights: Sequence[NDArray[Any]],
                   biases: Sequence[NDArray[Any]], meta: dict[str, Any], policy: str) -> Path:
    """Write the layers and ``meta`` (plus ``format`` and ``policy``) to ``path``; the path."""
    arrays: dict[str, NDArray[Any]] = {}
    for i, (w, b) in enumerate(zip(weights, biases, strict=True)):
        arrays[f"w{i}"] = np.asarray(w, dtype=np.float32)
        arrays[f"b{i}"] = np.asarray(b, dtype=np.float32)
    arrays["meta"] = np.array(json.dumps({**meta, "format": FORMAT, "policy": policy}))
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("wb") as f:  # np.savez would append .npz to a name without it
        np.savez(f, allow_pickle=False, **arrays)
    return out
