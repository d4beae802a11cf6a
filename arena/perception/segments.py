"""Lidar scans cut into segments, each described by the features a people detector classifies.

A planar scan is cut where consecutive returns are further apart than a jump distance (or a
beam returns nothing): each run of at least ``min_points`` returns is a *segment*, a candidate
leg or body. Each segment gets the geometric features of Arras, Mozos and Burgard ("Using
boosted features for the detection of people in 2D range data", ICRA 2007), which separate legs
(small, round, convex towards the sensor) from walls and furniture (long, straight):

=================== ===========================================================================
``n``               number of returns
``width``           m, distance between the first and the last return
``std``             m, root mean square distance of the returns from their centroid
``median_dev``      m, mean distance of the returns from their median point
``linearity``       m², mean squared residual of the least-squares line
``circularity``     m², mean squared residual of the least-squares (Kåsa) circle
``radius``          m, that circle's radius (clipped to 2 m)
``boundary``        m, summed distance between consecutive returns
``boundary_std``    m, std of those distances
``curvature``       rad/m, mean turning of the polyline per metre
``range``           m, distance of the centroid from the sensor
``jump_prev``       m, gap to the previous segment's last return (``range_max`` at none)
``jump_next``       m, gap to the next segment's first return
=================== ===========================================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]

FEATURES = ("n", "width", "std", "median_dev", "linearity", "circularity", "radius", "boundary",
            "boundary_std", "curvature", "range", "jump_prev", "jump_next")
"""Feature names, the columns of :attr:`Segments.features`."""


@dataclass(frozen=True, eq=False)
class Segments:
    """The segments of one scan.

    Attributes:
        bounds: ``(k, 2)`` first and one-past-last beam index of each segment.
        centroids: ``(k, 2)`` m, in the frame of the points given (sensor or world).
        features: ``(k, len(FEATURES))`` float64.
    """

    bounds: NDArray[np.int64]
    centroids: F64
    features: F64

    def __len__(self) -> int:
        return int(self.bounds.shape[0])


def scan_points(
    ranges: ArrayLike, angles: ArrayLike, range_max: float
) -> tuple[F64, NDArray[np.bool_]]:
    """``(n, 2)`` beam points in the sensor frame (m) and which returned (``< range_max``)."""
    r = np.asarray(ranges, dtype=np.float64).reshape(-1)
    a = np.asarray(angles, dtype=np.float64).reshape(-1)
    valid = np.isfinite(r) & (r < range_max - 1e-6)
    pts = np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
    return pts, valid


def segment_scan(
    points: F64, valid: NDArray[np.bool_], *, jump: float = 0.15, min_points: int = 3,
    max_points: int = 80, origin: ArrayLike = (0.0, 0.0), range_max: float = 30.0,
) -> Segments:
    """Cut the ``(n, 2)`` beam ``points`` (of which ``valid`` returned) into segments.

    Args:
        points: the returns, in beam order (sensor or world frame).
        valid: ``(n,)`` the beam returned.
        jump: m, a larger gap between consecutive returns starts a new segment.
        min_points: fewer returns: noise, dropped.
        max_points: more returns: a wall, dropped (a person at 0.5 m fills ~40 of 720 beams).
        origin: ``(2,)`` the sensor position in the frame of ``points`` (for ``range``).
        range_max: m, ``jump_prev``/``jump_next`` of a segment without a neighbour.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    ok = np.asarray(valid, dtype=bool).reshape(-1)
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return Segments(np.zeros((0, 2), np.int64), np.zeros((0, 2)),
                        np.zeros((0, len(FEATURES))))
    q = p[idx]
    gap = np.hypot(*(q[1:] - q[:-1]).T)
    cut = (gap > jump) | (np.diff(idx) > 1)  # a beam without return also separates
    starts = np.concatenate([[0], np.flatnonzero(cut) + 1])
    ends = np.concatenate([starts[1:], [idx.size]])
    o = np.asarray(origin, dtype=np.float64).reshape(2)
    bounds, cents, feats = [], [], []
    for s, e in zip(starts.tolist(), ends.tolist(), strict=True):
        m = e - s
        if m < min_points or m > max_points:
            continue
        seg = q[s:e]
        prev = float(np.hypot(*(seg[0] - q[s - 1]))) if s > 0 else range_max
        nxt = float(np.hypot(*(seg[-1] - q[e]))) if e < idx.size else range_max
        bounds.append((int(idx[s]), int(idx[e - 1]) + 1))
        cents.append(seg.mean(axis=0))
        feats.append(_features(seg, o, prev, nxt))
    if not bounds:
        return Segments(np.zeros((0, 2), np.int64), np.zeros((0, 2)),
                        np.zeros((0, len(FEATURES))))
    return Segments(np.array(bounds, dtype=np.int64), np.array(cents), np.array(feats))


def _features(seg: F64, origin: F64, jump_prev: float, jump_next: float) -> list[float]:
    """The :data:`FEATURES` of one segment's ``(m, 2)`` returns."""
    m = seg.shape[0]
    c = seg.mean(axis=0)
    d = seg - c
    std = float(np.sqrt(np.mean(np.sum(d * d, axis=1))))
    med = np.median(seg, axis=0)
    median_dev = float(np.mean(np.hypot(*(seg - med).T)))
    width = float(np.hypot(*(seg[-1] - seg[0])))
    # line: the smallest eigenvalue of the scatter is the mean squared orthogonal residual
    cov = d.T @ d / m
    linearity = float(np.linalg.eigvalsh(cov)[0])
    # Kåsa circle: x² + y² + a x + b y + c = 0 in the least-squares sense (centred for accuracy)
    a_mat = np.column_stack([d, np.ones(m)])
    rhs = -np.sum(d * d, axis=1)
    sol, *_ = np.linalg.lstsq(a_mat, rhs, rcond=None)
    cx, cy = -sol[0] / 2, -sol[1] / 2
    r2 = cx * cx + cy * cy - sol[2]
    radius = float(np.sqrt(r2)) if r2 > 0 else 2.0
    resid = np.hypot(d[:, 0] - cx, d[:, 1] - cy) - radius
    circularity = float(np.mean(resid * resid))
    steps = np.hypot(*(seg[1:] - seg[:-1]).T)
    boundary = float(steps.sum())
    boundary_std = float(steps.std()) if steps.size else 0.0
    if m >= 3:
        v = seg[1:] - seg[:-1]
        ang = np.arctan2(v[:, 1], v[:, 0])
        turn = np.abs((np.diff(ang) + np.pi) % (2 * np.pi) - np.pi).sum()
        curvature = float(turn / max(boundary, 1e-6))
    else:
        curvature = 0.0
    return [float(m), width, std, median_dev, linearity, circularity, min(radius, 2.0), boundary,
            boundary_std, curvature, float(np.hypot(*(c - origin))), jump_prev, jump_next]
