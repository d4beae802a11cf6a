"""People from a 2-D scan: a learned segment classifier, then segments merged into people.

:class:`LidarPeopleDetector`:

1. cuts the scan into segments with their features (:mod:`arena.perception.segments`);
2. scores each segment with the small network of :mod:`arena.perception.classifier` on its
   features and their logarithms (leg- and body-sized things differ over orders of magnitude in
   ``linearity`` and ``circularity``; a linear model could not tell a leg from a short piece of
   wall seen between two legs' shadows);
3. merges the segments scoring at least ``min_score`` that lie within ``merge_radius`` of each
   other, best first (two legs of one person, the halves of a body cut by a shadow): a person
   is the score-weighted mean of their fitted circle centres, with the best score.

The weights are trained by :func:`train` on simulated scans (:mod:`.lidar_data`) with L2
regularisation and balanced classes (L-BFGS, from a seeded initialisation), and shipped in
``arena/perception/data/``; inference is numpy only.
:func:`~arena.perception.scoring.average_precision` scores detections against the visible people.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import ConfigError
from arena.perception.classifier import HIDDEN, Classifier, fit_classifier
from arena.perception.segments import FEATURES, Segments, scan_points, segment_scan

F64 = NDArray[np.float64]

WEIGHTS = Path(__file__).parent / "data" / "lidar_people.npz"
"""The shipped detector (``python tools/train_lidar_detector.py`` makes it)."""


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
                self.classifier = Classifier.from_arrays(data)
        except (OSError, KeyError, ValueError) as e:
            raise ConfigError(f"not a lidar people detector ({e})", source=str(path)) from None
        self.min_score = float(min_score)
        self.merge_radius = float(merge_radius)

    def segment_scores(self, segments: Segments) -> F64:
        """``(k,)`` probability that each segment belongs to a person."""
        return self.classifier.scores(segments.features.reshape(-1, len(FEATURES)))

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

    See :func:`~arena.perception.classifier.fit_classifier`. Returns the saved arrays.
    """
    clf = fit_classifier(np.asarray(features, dtype=np.float64).reshape(-1, len(FEATURES)),
                         labels, l2=l2, seed=seed, hidden=hidden)
    arrays = {**clf.arrays(), "features": np.array(FEATURES)}
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, **arrays)
    return arrays
