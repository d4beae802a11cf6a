"""Interval estimates for benchmark tables and figures: a seeded percentile bootstrap of the mean.

Why a bootstrap and not Student's t: benchmark metrics are bounded (rates in [0, 1], counts,
times and distances >= 0) and stages often have few episodes, where ``mean ± t·s/√n`` runs far
outside the data's range (± 20 m on a 10 m path with n = 2, bars below zero). Every bootstrap
mean is a mean of resampled values, so the percentile interval always lies inside
``[min(values), max(values)]``: rates stay in [0, 1] and non-negative metrics non-negative.

Cells with fewer than :data:`MIN_N` finite values get no interval at all (a bootstrap of 2
values is as meaningless as a t interval) and are flagged ``low_n`` instead; tables and figures
mark them. The resampling uses its own ``numpy.random.Generator`` seeded with ``seed`` on every
call, so the same values always give the same interval, whatever else ran before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

#: Fewest finite values for which an interval is given; smaller cells are flagged ``low_n``.
MIN_N = 5
#: Bootstrap resamples per interval.
RESAMPLES = 2000
#: Seed of the resampling generator (fixed: same values -> same interval).
SEED = 0
#: Most resampled values drawn at once (bounds memory for large cells: 2000 x 2000 doubles).
_CHUNK = 4_000_000


@dataclass(frozen=True)
class Estimate:
    """The mean of one cell with its bootstrap interval.

    Attributes:
        n: number of finite values.
        mean: their mean (NaN if ``n == 0``).
        lower, upper: bounds of the percentile bootstrap interval of the mean (NaN when
            ``n < MIN_N``); ``lower <= mean <= upper`` and both inside the values' range.
        confidence: the interval's level, e.g. 0.95.
    """

    n: int
    mean: float
    lower: float
    upper: float
    confidence: float = 0.95

    @property
    def low_n(self) -> bool:
        """True when the cell has values but too few (< :data:`MIN_N`) for an interval."""
        return 0 < self.n < MIN_N

    @property
    def has_interval(self) -> bool:
        """True when ``lower`` and ``upper`` are finite."""
        return math.isfinite(self.lower) and math.isfinite(self.upper)


def bootstrap_mean(
    values: ArrayLike,
    *,
    confidence: float = 0.95,
    resamples: int = RESAMPLES,
    seed: int = SEED,
    min_n: int = MIN_N,
) -> Estimate:
    """Mean of the finite ``values`` and its percentile bootstrap interval.

    Draws ``resamples`` samples of size n with replacement (vectorised, in chunks of at most
    ``_CHUNK`` values), takes each one's mean and returns the ``(1 ± confidence) / 2`` quantiles
    of those means. Constant values give ``lower == mean == upper``.

    Args:
        values: shape ``(n,)``, any real dtype; NaN and ±inf are ignored.
        confidence: interval level in (0, 1).
        resamples: bootstrap resamples (>= 1).
        seed: seed of the resampling generator.
        min_n: fewest finite values for an interval (fewer: NaN bounds).

    Returns:
        The :class:`Estimate`.
    """
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}")
    if resamples < 1:
        raise ValueError(f"resamples must be >= 1, got {resamples}")
    v = np.asarray(values, dtype=np.float64).ravel()
    v = v[np.isfinite(v)]
    n = int(v.size)
    nan = float("nan")
    if n == 0:
        return Estimate(0, nan, nan, nan, confidence)
    mean = float(v.mean())
    if n < max(1, min_n):
        return Estimate(n, mean, nan, nan, confidence)
    if float(v.min()) == float(v.max()):
        return Estimate(n, mean, mean, mean, confidence)
    rng = np.random.default_rng(seed)
    per_chunk = max(1, _CHUNK // n)
    means = np.empty(resamples)
    for start in range(0, resamples, per_chunk):
        stop = min(resamples, start + per_chunk)
        means[start:stop] = v[rng.integers(0, n, size=(stop - start, n))].mean(axis=1)
    alpha = (1.0 - confidence) / 2.0
    lo, hi = np.quantile(means, [alpha, 1.0 - alpha])
    # the mean lies inside the interval for any sample that is not pathologically skewed;
    # clamp so error bars (mean - lower, upper - mean) are never negative
    return Estimate(n, mean, min(float(lo), mean), max(float(hi), mean), confidence)


__all__ = ["MIN_N", "RESAMPLES", "SEED", "Estimate", "bootstrap_mean"]
