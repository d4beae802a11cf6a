"""People from a 2-D scan: a learned segment classifier, then segments merged into people.

:class:`LidarPeopleDetector`:

1. cuts the scan into segments with their features (:mod:`arena.perception.segments`);
2. scores each segment with a small neural network on its standardised features and their
   logarithms (leg- and body-sized things differ over orders of magnitude in ``linearity`` and
   ``circularity``): one hidden layer of :data:`HIDDEN` tanh units,
   ``p = σ(w₂ · tanh(W₁ φ(x) + b₁) + b₂)`` (a linear model could not tell a leg from a short
   piece of wall seen between two legs' shadows);
3. merges the segments scoring at least ``min_score`` that lie within ``merge_radius`` of each
   other, best first (two legs of one person, the halves of a body cut by a shadow): a person
   is the score-weighted mean of their fitted circle centres, with the best score.

The weights are trained by :func:`train` on simulated scans (:mod:`.lidar_data`) with L2
regularisation and balanced classes (L-BFGS, from a seeded initialisation), and shipped in
``arena/perception/data/``; inference is numpy only. :func:`average_precision` scores
detections against the visible people.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from arena.core.errors import ConfigError
from arena.perception.segments import FEATURES, Segments, scan_points, segment_scan

F64 = NDArray[np.float64]

WEIGHTS = Path(__file__).parent / "data" / "lidar_people.npz"
HIDDEN = 16
"""Hidden units of the segment classifier."""
"""The shipped detector (``python tools/train_lidar_detector.py`` makes it)."""


def expand(features: F64) -> F64:
    """``(k, 2 F)``: the features and ``log(1e-6 + |x|)`` of each (scale-free shapes)."""
    x = np.asarray(features, dtype=np.float64).reshape(-1, len(FEATURES))
    return np.concatenate([x, np.log(1e-6 + np.abs(x))], axis=1)


class LidarPeopleDetector:
    """Detects people in planar scans (see the module docstring).

    Args:
        weights: an ``.npz`` with ``mean``, ``scale``, ``w1``, ``b1``, ``w2``, ``b2`` (default:
            the shipped one).
        min_score: segments scoring less are not people.
        merge_radius: m, segments closer than this are one person.
    """

    def __init__(
        self, weights: str | Path | None = None, *, min_score: float = 0.3,
        merge_radius: float = 0.5,
    ) -> None:
        path = Path(weights) if weights is not None else WEIGHTS
        try:
            with np.load(path) as data:
                self.mean, self.scale = data["mean"], data["scale"]
                self.w1, self.b1 = data["w1"], data["b1"]
                self.w2, self.b2 = data["w2"], float(data["b2"])
        except (OSError, KeyError, ValueError) as e:
            raise ConfigError(f"not a lidar people detector ({e})", source=str(path)) from None
        self.min_score = float(min_score)
        self.merge_radius = float(merge_radius)

    def segment_scores(self, segments: Segments) -> F64:
        """``(k,)`` probability that each segment belongs to a person."""
        if len(segments) == 0:
            return np.zeros(0)
        z = (expand(segments.features) - self.mean) / self.scale
        h = np.tanh(z @ self.w1 + self.b1)
        p: F64 = 1.0 / (1.0 + np.exp(-(h @ self.w2 + self.b2)))
        return p

    def detect(
        self, ranges: ArrayLike, angles: ArrayLike, range_max: float
    ) -> tuple[F64, F64]:
        """People in one scan: ``(k, 2)`` positions in the sensor frame (m), ``(k,)`` scores."""
        pts, valid = scan_points(ranges, angles, range_max)
        segs = segment_scan(pts, valid, range_max=range_max)
        return self.people(segs, self.segment_scores(segs))

    def people(self, segments: Segments, scores: F64) -> tuple[F64, F64]:
        """Merge scored segments into people (best first, within ``merge_radius``)."""
        keep = np.flatnonzero(scores >= self.min_score)
        if keep.size == 0:
            return np.zeros((0, 2)), np.zeros(0)
        order = keep[np.argsort(-scores[keep], kind="stable")]
        xy, s = segments.centres[order], scores[order]
        taken = np.zeros(order.size, dtype=bool)
        out_xy, out_s = [], []
        for i in range(order.size):
            if taken[i]:
                continue
            near = ~taken & (np.hypot(*(xy - xy[i]).T) <= self.merge_radius)
            taken |= near
            w = s[near]
            out_xy.append((xy[near] * w[:, None]).sum(axis=0) / w.sum())
            out_s.append(s[i])
        return np.array(out_xy), np.array(out_s)


def train(
    features: F64, labels: ArrayLike, path: str | Path, *, l2: float = 1e-4, seed: int = 0,
    hidden: int = HIDDEN,
) -> dict[str, F64]:
    """Fit the segment classifier to ``(N, F)`` features and ``(N,)`` 0/1 labels; save it.

    Logistic loss with balanced class weights (people are a minority of the segments) and an
    L2 penalty ``l2 · (|W₁|² + |w₂|²)``, minimised by L-BFGS from weights drawn from
    ``default_rng(seed)``: the same data give the same weights. Returns the saved arrays.
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
    arrays = {"mean": mean, "scale": scale, "w1": w1, "b1": b1, "w2": w2,
              "b2": np.array(b2), "features": np.array(FEATURES)}
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, **arrays)
    return arrays


def average_precision(
    detections: Sequence[tuple[F64, F64]], people: Sequence[F64],
    visible: Sequence[NDArray[np.bool_]], radius: float,
) -> tuple[float, F64, F64]:
    """AP of per-frame ``(positions, scores)`` against the visible people, within ``radius`` m.

    Detections of all frames are ranked by score; each, in turn, takes the nearest person of
    its frame not yet taken within ``radius``: a visible one makes it a true positive, a hidden
    one (the scan does not show them) is ignored, none a false positive. AP is the area under
    the precision-recall curve with precision made non-increasing (the VOC/COCO rule).

    Returns:
        ``(AP, recall (d,), precision (d,))`` over the ranked detections (without the ignored).
    """
    ranked = sorted(
        ((float(s), f, k) for f, (_, sc) in enumerate(detections) for k, s in enumerate(sc)),
        key=lambda t: -t[0],
    )
    total = int(sum(int(np.sum(v)) for v in visible))
    taken = [np.zeros(len(p), dtype=bool) for p in people]
    tp: list[float] = []
    for _, f, k in ranked:
        pos = detections[f][0][k]
        free = ~taken[f]
        if not free.any():
            tp.append(0.0)
            continue
        d = np.where(free, np.hypot(*(people[f] - pos).T), np.inf)
        j = int(np.argmin(d))
        if d[j] > radius:
            tp.append(0.0)
            continue
        taken[f][j] = True
        if visible[f][j]:
            tp.append(1.0)
        # a hidden person: neither right nor wrong
    if not tp or total == 0:
        return 0.0, np.zeros(0), np.zeros(0)
    t = np.array(tp)
    ctp = np.cumsum(t)
    precision = ctp / np.arange(1, t.size + 1)
    recall = ctp / total
    p_mono = np.maximum.accumulate(precision[::-1])[::-1]
    r_prev = np.concatenate([[0.0], recall[:-1]])
    ap = float(np.sum((recall - r_prev) * p_mono))
    return ap, recall, precision
