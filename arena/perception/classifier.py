"""The small classifier both people detectors score their candidates with.

A candidate (a scan segment, an image blob) is a row of ``F`` geometric features. The network
sees the standardised features and their logarithms (people-sized things differ from walls and
furniture over orders of magnitude in size and shape): one hidden layer of tanh units and a
logistic output, ``p = σ(w₂ · tanh(W₁ φ(x) + b₁) + b₂)``, ``φ(x) = standardise([x, log(1e-6 +
|x|)])``. :func:`fit_classifier` trains it with a class-balanced logistic loss and an L2 penalty
by L-BFGS from a seeded start (the same data give the same weights); inference is numpy.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

F64 = NDArray[np.float64]

HIDDEN = 16
"""Hidden units of the classifier."""

KEYS = ("mean", "scale", "w1", "b1", "w2", "b2")
"""Its arrays, as stored in a detector's ``.npz`` (under a detector's prefix)."""


def expand(features: ArrayLike) -> F64:
    """``(k, 2 F)``: the features and ``log(1e-6 + |x|)`` of each (scale-free shapes)."""
    x = np.asarray(features, dtype=np.float64)
    x = x.reshape(x.shape[0] if x.ndim else 0, -1) if x.ndim != 2 else x
    return np.concatenate([x, np.log(1e-6 + np.abs(x))], axis=1)


@dataclass(frozen=True, eq=False)
class Classifier:
    """The trained network.

    ``mean``/``scale`` ``(2F,)``, ``w1`` ``(2F, H)``, ``b1`` ``(H,)``, ``w2`` ``(H,)``, ``b2``.
    """

    mean: F64
    scale: F64
    w1: F64
    b1: F64
    w2: F64
    b2: float

    @classmethod
    def from_arrays(
        cls, arrays: Mapping[str, NDArray[np.floating]], prefix: str = ""
    ) -> Classifier:
        """Read it from a mapping (an opened ``.npz``); ``KeyError`` when a key is missing."""
        a = {k: np.asarray(arrays[prefix + k], dtype=np.float64) for k in KEYS}
        return cls(a["mean"], a["scale"], a["w1"], a["b1"], a["w2"], float(a["b2"]))

    def arrays(self, prefix: str = "") -> dict[str, F64]:
        """Its arrays under ``prefix`` (to save with ``np.savez``)."""
        return {prefix + "mean": self.mean, prefix + "scale": self.scale,
                prefix + "w1": self.w1, prefix + "b1": self.b1, prefix + "w2": self.w2,
                prefix + "b2": np.array(self.b2)}

    def scores(self, features: ArrayLike) -> F64:
        """``(k,)`` probability that each candidate ``(k, F)`` is a person."""
        x = expand(features)
        if x.shape[0] == 0:
            return np.zeros(0)
        h = np.tanh(((x - self.mean) / self.scale) @ self.w1 + self.b1)
        p: F64 = 1.0 / (1.0 + np.exp(-(h @ self.w2 + self.b2)))
        return p


def fit_classifier(
    features: ArrayLike, labels: ArrayLike, *, l2: float = 1e-4, seed: int = 0,
    hidden: int = HIDDEN,
) -> Classifier:
    """Fit the network to ``(N, F)`` features and ``(N,)`` 0/1 labels.

    Logistic loss with balanced class weights (people are a minority of the candidates) and an
    L2 penalty ``l2 · (|W₁|² + |w₂|²)``, minimised by L-BFGS from weights drawn from
    ``default_rng(seed)``.
    """
    x = expand(features)
    y = np.asarray(labels, dtype=np.float64).reshape(-1)
    mean = x.mean(axis=0)
    scale = x.std(axis=0)
    scale[scale < 1e-9] = 1.0
    z = (x - mean) / scale
    n, f = z.shape
    pos = max(y.sum(), 1.0)
    neg = max(y.size - y.sum(), 1.0)
    cw = np.where(y > 0, y.size / (2 * pos), y.size / (2 * neg)) / n
    sizes = (f * hidden, hidden, hidden, 1)

    def unpack(theta: F64) -> tuple[F64, F64, F64, float]:
        a, b, c = np.cumsum(sizes)[:3]
        return theta[:a].reshape(f, hidden), theta[a:b], theta[b:c], float(theta[c])

    def loss(theta: F64) -> tuple[float, F64]:
        w1, b1, w2, b2 = unpack(theta)
        h = np.tanh(z @ w1 + b1)
        m = h @ w2 + b2
        l_i = np.logaddexp(0.0, np.where(y > 0, -m, m))  # stable log(1 + e^(∓m))
        p = 1.0 / (1.0 + np.exp(-m))
        g = cw * (p - y)  # dL/dm
        gh = np.outer(g, w2) * (1.0 - h * h)
        grad = np.concatenate([
            (z.T @ gh + 2 * l2 * w1).ravel(), gh.sum(axis=0), h.T @ g + 2 * l2 * w2,
            [g.sum()],
        ])
        val = float(np.sum(cw * l_i) + l2 * (np.sum(w1 * w1) + w2 @ w2))
        return val, grad

    rng = np.random.default_rng(seed)
    theta0 = np.concatenate([rng.normal(0.0, 1.0 / np.sqrt(f), f * hidden), np.zeros(hidden),
                             rng.normal(0.0, 1.0 / np.sqrt(hidden), hidden), [0.0]])
    res = minimize(loss, theta0, jac=True, method="L-BFGS-B", options={"maxiter": 3000})
    w1, b1, w2, b2 = unpack(res.x)
    return Classifier(mean, scale, w1, b1, w2, b2)
