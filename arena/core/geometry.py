"""Vectorised planar geometry helpers. Points are ``(n, 2)`` arrays, poses ``(n, 3)``.

Polygons are ``(k, 2)`` vertex arrays in order (either orientation), implicitly closed.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def wrap_angle(a: ArrayLike) -> FloatArray:
    """Wrap angles (any shape) to ``[-pi, pi)``."""
    return (np.asarray(a, dtype=np.float64) + np.pi) % (2.0 * np.pi) - np.pi


def rotation_matrix(theta: float) -> FloatArray:
    """The 2×2 rotation matrix for ``theta`` (rad)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def transform_points(points: ArrayLike, pose: ArrayLike) -> FloatArray:
    """Map body-frame points ``(k, 2)`` to the world with ``pose = [x, y, theta]``.

    ``pose`` may also be ``(n, 3)``; the result is then ``(n, k, 2)``.
    """
    p = np.asarray(points, dtype=np.float64)
    q = np.asarray(pose, dtype=np.float64)
    c, s = np.cos(q[..., 2]), np.sin(q[..., 2])
    x = c[..., None] * p[:, 0] - s[..., None] * p[:, 1] + q[..., 0, None]
    y = s[..., None] * p[:, 0] + c[..., None] * p[:, 1] + q[..., 1, None]
    return np.stack([x, y], axis=-1)


def to_body_frame(points: ArrayLike, pose: ArrayLike) -> FloatArray:
    """Inverse of :func:`transform_points` for one pose: world points ``(k, 2)`` → body frame."""
    q = np.asarray(pose, dtype=np.float64)
    p = np.asarray(points, dtype=np.float64) - q[:2]
    c, s = np.cos(q[2]), np.sin(q[2])
    return np.stack([c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1]], axis=-1)


def rectangle(length: float, width: float, center: tuple[float, float] = (0.0, 0.0)) -> FloatArray:
    """Counter-clockwise rectangle ``(4, 2)``: ``length`` along x, ``width`` along y (m)."""
    hx, hy = length / 2.0, width / 2.0
    cx, cy = center
    return np.array(
        [[cx - hx, cy - hy], [cx + hx, cy - hy], [cx + hx, cy + hy], [cx - hx, cy + hy]]
    )


def regular_polygon(radius: float, sides: int = 16) -> FloatArray:
    """Counter-clockwise regular polygon inscribed in a circle of ``radius`` (m)."""
    t = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    return np.stack([radius * np.cos(t), radius * np.sin(t)], axis=-1)


def segment_lengths(points: ArrayLike) -> FloatArray:
    """``(k−1,)`` m, the 2-D lengths of the segments of the polyline ``points``.

    ``points``: ``(k, ≥2)`` m (columns x, y, anything after them, e.g. a heading, is ignored);
    empty for ``k < 2``. ``np.hypot`` per segment, so every path length in Arena rounds alike.
    """
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 2:
        return np.zeros(0)
    d = np.diff(p[:, :2], axis=0)
    return np.asarray(np.hypot(d[:, 0], d[:, 1]), dtype=np.float64)


def polyline_length(points: ArrayLike) -> float:
    """m, the 2-D length of the polyline ``points`` ``(k, ≥2)`` (0 for ``k < 2``).

    The sum of :func:`segment_lengths`: the length of a planned path, a driven trajectory or a
    band.
    """
    return float(np.sum(segment_lengths(points)))


def polygon_area(polygon: ArrayLike) -> float:
    """Signed area (m²): positive for counter-clockwise vertex order."""
    p = np.asarray(polygon, dtype=np.float64)
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def polygon_edges(polygon: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Edge start and end points, each ``(k, 2)``."""
    a = np.asarray(polygon, dtype=np.float64)
    return a, np.roll(a, -1, axis=0)


def bounding_radius(polygon: ArrayLike) -> float:
    """Largest distance of a vertex from the origin (m): the circumscribed radius about (0, 0)."""
    return float(np.max(np.linalg.norm(np.asarray(polygon, dtype=np.float64), axis=1)))


def points_in_polygon(points: ArrayLike, polygon: ArrayLike) -> NDArray[np.bool_]:
    """Even-odd rule test for ``(n, 2)`` points against one polygon → ``(n,)`` bool."""
    p = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 2))
    poly = np.ascontiguousarray(np.asarray(polygon, dtype=np.float64))
    inside: NDArray[np.bool_] = _points_in_polygon(p, poly.reshape(-1, 2))
    return inside


@njit(cache=True)
def _points_in_polygon(p: FloatArray, poly: FloatArray) -> NDArray[np.bool_]:
    """:func:`point_in_polygon` for each point ``(n, 2)`` → ``(n,)`` bool.

    The compiled loop replaced a vectorised version with the same float operations (so the same
    answers), without its ``(n, k)`` temporaries (rasterising one footprint made a dozen).
    """
    n = p.shape[0]
    inside = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        inside[i] = point_in_polygon(p[i, 0], p[i, 1], poly)
    return inside


@njit(cache=True)
def point_in_polygon(px: float, py: float, poly: FloatArray) -> bool:
    """Even-odd test of the point ``(px, py)`` (m) against the polygon ``(k, 2)`` (m), compiled.

    Counts the edges ``a→b`` that a ray from the point towards +x crosses: an edge counts when
    it straddles ``py`` and its ``x`` there, ``a_x + (py - a_y)(b_x - a_x) / (b_y - a_y)``, lies
    right of the point. The one implementation: :func:`points_in_polygon` and the contact
    kernels (:mod:`arena.sim.contacts.kernels`) call it.
    """
    k = poly.shape[0]
    count = 0
    for e in range(k):
        ax = poly[e, 0]
        ay = poly[e, 1]
        bx = poly[(e + 1) % k, 0]
        by = poly[(e + 1) % k, 1]
        if (ay > py) != (by > py) and px < ax + (py - ay) * (bx - ax) / (by - ay):
            count += 1
    return count % 2 == 1


def point_segment_distance(points: ArrayLike, a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Distances from ``(n, 2)`` points to ``(m, 2)`` segments ``a→b`` → ``(n, m)`` in metres."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 1, 2)
    a = np.asarray(a, dtype=np.float64).reshape(1, -1, 2)
    b = np.asarray(b, dtype=np.float64).reshape(1, -1, 2)
    ab = b - a
    denom = np.einsum("...i,...i->...", ab, ab)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.einsum("...i,...i->...", p - a, ab) / denom
    t = np.clip(np.nan_to_num(t, nan=0.0), 0.0, 1.0)
    closest = a + t[..., None] * ab
    dist: FloatArray = np.linalg.norm(p - closest, axis=-1)
    return dist


def segments_intersect(
    a1: ArrayLike, b1: ArrayLike, a2: ArrayLike, b2: ArrayLike
) -> NDArray[np.bool_]:
    """Pairwise proper-or-touching intersection of segments ``(n, 2)`` × ``(m, 2)`` → ``(n, m)``."""
    p = np.asarray(a1, dtype=np.float64).reshape(-1, 1, 2)
    r = np.asarray(b1, dtype=np.float64).reshape(-1, 1, 2) - p
    q = np.asarray(a2, dtype=np.float64).reshape(1, -1, 2)
    s = np.asarray(b2, dtype=np.float64).reshape(1, -1, 2) - q
    qp = q - p
    rxs = r[..., 0] * s[..., 1] - r[..., 1] * s[..., 0]
    qpxr = qp[..., 0] * r[..., 1] - qp[..., 1] * r[..., 0]
    qpxs = qp[..., 0] * s[..., 1] - qp[..., 1] * s[..., 0]
    parallel = np.abs(rxs) < 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        t = qpxs / rxs
        u = qpxr / rxs
    hit = ~parallel & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    # Collinear overlapping segments count as intersecting.
    collinear = parallel & (np.abs(qpxr) < 1e-12)
    if np.any(collinear):
        rr = np.einsum("...i,...i->...", r, r)
        with np.errstate(divide="ignore", invalid="ignore"):
            t0 = np.einsum("...i,...i->...", qp, r) / rr
            t1 = t0 + np.einsum("...i,...i->...", s, r) / rr
        lo, hi = np.minimum(t0, t1), np.maximum(t0, t1)
        hit |= collinear & (hi >= 0) & (lo <= 1)
    return hit


def circles_overlap_polygon(
    centers: ArrayLike, radii: ArrayLike, polygon: ArrayLike
) -> NDArray[np.bool_]:
    """Whether each circle ``(n,)`` touches or lies inside one polygon → ``(n,)`` bool."""
    c = np.asarray(centers, dtype=np.float64).reshape(-1, 2)
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    a, b = polygon_edges(polygon)
    near_edge = np.min(point_segment_distance(c, a, b), axis=1) <= r
    hit: NDArray[np.bool_] = near_edge | points_in_polygon(c, polygon)
    return hit


def polygons_overlap(p: ArrayLike, q: ArrayLike) -> bool:
    """Whether two polygons intersect (edges cross, or one contains the other)."""
    pa, pb = polygon_edges(p)
    qa, qb = polygon_edges(q)
    if np.any(segments_intersect(pa, pb, qa, qb)):
        return True
    return bool(points_in_polygon(pa[:1], q)[0] or points_in_polygon(qa[:1], p)[0])


def convex_hull(points: ArrayLike) -> FloatArray:
    """Counter-clockwise convex hull ``(h, 2)`` of ``(n, 2)`` points (Andrew's monotone chain)."""
    p = np.unique(np.asarray(points, dtype=np.float64).reshape(-1, 2), axis=0)
    if len(p) <= 2:
        return p

    def half(pts: FloatArray) -> list[FloatArray]:
        out: list[FloatArray] = []
        for q in pts:
            while len(out) >= 2:
                o, a = out[-2], out[-1]
                if (a[0] - o[0]) * (q[1] - o[1]) - (a[1] - o[1]) * (q[0] - o[0]) > 0:
                    break
                out.pop()
            out.append(q)
        return out

    lower, upper = half(p), half(p[::-1])
    return np.array(lower[:-1] + upper[:-1])


def convex_polygon_overlaps_squares(
    polygon: ArrayLike, centers: ArrayLike, half_size: float
) -> NDArray[np.bool_]:
    """Separating-axis test of one convex polygon against axis-aligned squares.

    Args:
        polygon: ``(k, 2)`` convex polygon (world frame).
        centers: ``(m, 2)`` square centres.
        half_size: half the square's edge length (m).

    Returns:
        ``(m,)`` bool, True where the interiors overlap (touching edges do not count).
    """
    poly = np.asarray(polygon, dtype=np.float64)
    c = np.asarray(centers, dtype=np.float64).reshape(-1, 2)
    edges = np.roll(poly, -1, axis=0) - poly
    normals = np.stack([-edges[:, 1], edges[:, 0]], axis=1)  # (k, 2)
    # The projections stay numpy matrix products: BLAS may fuse their multiply-adds, and the
    # answers must not change; the comparisons run in one pass without (m, k) temporaries.
    proj_poly = poly @ normals.T  # (k_vertices, k_axes)
    proj_c = c @ normals.T  # (m, k_axes)
    xmax, xmin = poly[:, 0].max(), poly[:, 0].min()
    box = (xmin, xmax, poly[:, 1].min(), poly[:, 1].max())
    result: NDArray[np.bool_] = _squares_overlap(
        c, float(half_size), box, normals, proj_poly.min(axis=0), proj_poly.max(axis=0), proj_c
    )
    return result


@njit(cache=True)
def _squares_overlap(
    c: FloatArray,
    half_size: float,
    box: tuple[float, float, float, float],
    normals: FloatArray,
    pmin: FloatArray,
    pmax: FloatArray,
    proj_c: FloatArray,
) -> NDArray[np.bool_]:
    """The tests of :func:`convex_polygon_overlaps_squares` on given projections.

    Each square must overlap the polygon's bounding box ``(xmin, xmax, ymin, ymax)``, then on
    every edge normal ``a`` its projection ``proj_c ± half_size · (|n_x| + |n_y|)`` must
    overlap the polygon's ``[pmin, pmax]``.
    """
    xmin, xmax, ymin, ymax = box
    k = normals.shape[0]
    m = c.shape[0]
    ok = np.zeros(m, dtype=np.bool_)
    extent = np.empty(k)
    for a in range(k):
        extent[a] = half_size * (abs(normals[a, 0]) + abs(normals[a, 1]))
    for i in range(m):
        cx = c[i, 0]
        cy = c[i, 1]
        if not (
            cx - half_size < xmax
            and cx + half_size > xmin
            and cy - half_size < ymax
            and cy + half_size > ymin
        ):
            continue
        hit = True
        for a in range(k):
            if not (proj_c[i, a] - extent[a] < pmax[a] and proj_c[i, a] + extent[a] > pmin[a]):
                hit = False
                break
        ok[i] = hit
    return ok
