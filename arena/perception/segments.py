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
``depth_prev``      m, how much farther from the sensor the previous return is than the
                    segment's first one (negative: the segment is a fragment seen behind
                    something nearer, e.g. wall between two legs' shadows; ``range_max``
                    when the neighbouring beam returned nothing)
``depth_next``      m, the same on the other side
=================== ===========================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]

FEATURES = ("n", "width", "std", "median_dev", "linearity", "circularity", "radius", "boundary",
            "boundary_std", "curvature", "range", "jump_prev", "jump_next", "depth_prev",
            "depth_next")
"""Feature names, the columns of :attr:`Segments.features`."""


@dataclass(frozen=True, eq=False)
class Segments:
    """The segments of one scan.

    Attributes:
        bounds: ``(k, 2)`` first and one-past-last beam index of each segment.
        centroids: ``(k, 2)`` m, in the frame of the points given (sensor or world).
        centres: ``(k, 2)`` m, the fitted circle's centre (a leg's or body's centre; the
            centroid where the returns are too straight for a circle of radius < 2 m).
        features: ``(k, len(FEATURES))`` float64.
    """

    bounds: NDArray[np.int64]
    centroids: F64
    centres: F64
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
    points: F64, valid: NDArray[np.bool_], *, jump: float = 0.15, min_points: int = 2,
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
        return _empty()
    q = p[idx]
    gap = np.hypot(*(q[1:] - q[:-1]).T)
    cut = (gap > jump) | (np.diff(idx) > 1)  # a beam without return also separates
    starts = np.concatenate([[0], np.flatnonzero(cut) + 1])
    ends = np.concatenate([starts[1:], [idx.size]])
    o = np.asarray(origin, dtype=np.float64).reshape(2)
    size = ends - starts
    keep = (size >= min_points) & (size <= max_points)
    if not keep.any():
        return _empty()
    s0, s1 = starts[keep].astype(np.int64), ends[keep].astype(np.int64)
    k = s0.shape[0]
    feats = np.empty((k, len(FEATURES)))
    cents = np.empty((k, 2))
    centres = np.empty((k, 2))
    _segment_features(np.ascontiguousarray(q), idx.astype(np.int64), s0, s1, o[0], o[1],
                      float(range_max), feats, cents, centres)
    bounds = np.stack([idx[s0], idx[s1 - 1] + 1], axis=1).astype(np.int64)
    return Segments(bounds, cents, centres, feats)


def _empty() -> Segments:
    return Segments(np.zeros((0, 2), np.int64), np.zeros((0, 2)), np.zeros((0, 2)),
                    np.zeros((0, len(FEATURES))))


@njit(cache=True)
def _segment_features(
    q: F64, beam: NDArray[np.int64], s0: NDArray[np.int64], s1: NDArray[np.int64], ox: float,
    oy: float, range_max: float, feats: F64, cents: F64, centres: F64,
) -> None:
    """The :data:`FEATURES` of the segments ``q[s0[j]:s1[j]]`` (one compiled pass), written.

    Also each segment's centroid and its least-squares (Kåsa) circle's centre, the centroid
    where fewer than 3 returns or a radius of 2 m or more (a nearly straight run).
    """
    total = q.shape[0]
    for j in range(s0.shape[0]):
        a, e = s0[j], s1[j]
        m = e - a
        cx = 0.0
        cy = 0.0
        for i in range(a, e):
            cx += q[i, 0]
            cy += q[i, 1]
        cx /= m
        cy /= m
        sxx = 0.0
        syy = 0.0
        sxy = 0.0
        for i in range(a, e):
            dx = q[i, 0] - cx
            dy = q[i, 1] - cy
            sxx += dx * dx
            syy += dy * dy
            sxy += dx * dy
        std = math.sqrt((sxx + syy) / m)
        mx = np.median(q[a:e, 0])
        my = np.median(q[a:e, 1])
        med_dev = 0.0
        for i in range(a, e):
            med_dev += math.hypot(q[i, 0] - mx, q[i, 1] - my)
        med_dev /= m
        width = math.hypot(q[e - 1, 0] - q[a, 0], q[e - 1, 1] - q[a, 1])
        # line: the smaller eigenvalue of the scatter (mean squared orthogonal residual)
        ca, cc, cb = sxx / m, syy / m, sxy / m
        linearity = max(0.5 * (ca + cc) - math.sqrt(0.25 * (ca - cc) ** 2 + cb * cb), 0.0)
        # Kåsa circle in centred coordinates: [x y 1] [p q r]^T = -(x² + y²), normal equations
        sxxx = 0.0
        syyy = 0.0
        for i in range(a, e):
            dx = q[i, 0] - cx
            dy = q[i, 1] - cy
            r2 = dx * dx + dy * dy
            sxxx += dx * r2
            syyy += dy * r2
        # with centred data the sums of dx, dy vanish: [sxx sxy; sxy syy] [p q] = -[Σx r², Σy r²]
        det = sxx * syy - sxy * sxy
        radius = 2.0
        ux = 0.0
        uy = 0.0
        circ = 0.0
        if m >= 3 and det > 1e-12 * max(sxx * syy, 1e-300):
            pp = -(sxxx * syy - syyy * sxy) / det
            qq = -(syyy * sxx - sxxx * sxy) / det
            rr = -(sxx + syy) / m  # from the third equation: m r = -Σ r²
            ux, uy = -pp / 2, -qq / 2
            rad2 = ux * ux + uy * uy - rr
            if rad2 > 0:
                radius = math.sqrt(rad2)
        if radius < 2.0:
            for i in range(a, e):
                d = math.hypot(q[i, 0] - cx - ux, q[i, 1] - cy - uy) - radius
                circ += d * d
            circ /= m
        else:
            radius = 2.0
            ux = 0.0
            uy = 0.0
            circ = linearity  # a straight run: the line's residual stands in
        boundary = 0.0
        bsq = 0.0
        for i in range(a + 1, e):
            st = math.hypot(q[i, 0] - q[i - 1, 0], q[i, 1] - q[i - 1, 1])
            boundary += st
            bsq += st * st
        nst = m - 1
        bmean = boundary / nst if nst > 0 else 0.0
        bstd = math.sqrt(max(bsq / nst - bmean * bmean, 0.0)) if nst > 0 else 0.0
        turn = 0.0
        for i in range(a + 1, e - 1):
            a1 = math.atan2(q[i, 1] - q[i - 1, 1], q[i, 0] - q[i - 1, 0])
            a2 = math.atan2(q[i + 1, 1] - q[i, 1], q[i + 1, 0] - q[i, 0])
            dturn = (a2 - a1 + math.pi) % (2 * math.pi) - math.pi
            turn += abs(dturn)
        curvature = turn / max(boundary, 1e-6) if m >= 3 else 0.0
        prev = math.hypot(q[a, 0] - q[a - 1, 0], q[a, 1] - q[a - 1, 1]) if a > 0 else range_max
        nxt = math.hypot(q[e - 1, 0] - q[e, 0], q[e - 1, 1] - q[e, 1]) if e < total else range_max
        f = feats[j]
        f[0] = m
        f[1] = width
        f[2] = std
        f[3] = med_dev
        f[4] = linearity
        f[5] = circ
        f[6] = radius
        f[7] = boundary
        f[8] = bstd
        f[9] = curvature
        f[10] = math.hypot(cx - ox, cy - oy)
        f[11] = prev
        f[12] = nxt
        r_first = math.hypot(q[a, 0] - ox, q[a, 1] - oy)
        r_last = math.hypot(q[e - 1, 0] - ox, q[e - 1, 1] - oy)
        f[13] = (math.hypot(q[a - 1, 0] - ox, q[a - 1, 1] - oy) - r_first
                 if a > 0 and beam[a - 1] == beam[a] - 1 else range_max)
        f[14] = (math.hypot(q[e, 0] - ox, q[e, 1] - oy) - r_last
                 if e < total and beam[e] == beam[e - 1] + 1 else range_max)
        cents[j, 0] = cx
        cents[j, 1] = cy
        if m >= 3 and radius < 2.0:
            centres[j, 0] = cx + ux
            centres[j, 1] = cy + uy
        else:
            centres[j, 0] = cx
            centres[j, 1] = cy
