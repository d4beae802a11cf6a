"""Compiled polygon primitives of the contact tests (placing, distances, overlaps).

Their float operations are those of the NumPy functions of :mod:`arena.core.geometry` that the
contact tests used before (``transform_points``, ``point_segment_distance``,
``segments_intersect``, ``polygons_overlap``, ``circles_overlap_polygon``), element by element,
so that every flag stayed the same.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic
from numpy.typing import NDArray

from arena.core.geometry import point_in_polygon


@intrinsic
def fma(typingctx: object, a: types.Type, b: types.Type, c: types.Type) -> tuple[object, object]:
    """``a * b + c`` rounded once (IEEE fused multiply-add; float64 arguments)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context: object, builder: ir.IRBuilder, signature: object, args: list) -> object:
        d = ir.DoubleType()
        name = "llvm.fma.f64"
        fn = builder.module.globals.get(name)
        if fn is None:
            fn = ir.Function(builder.module, ir.FunctionType(d, [d, d, d]), name=name)
        return builder.call(fn, args)

    return sig, codegen


# -- placing a footprint ------------------------------------------------------------------------
@njit(cache=True)
def place(body: NDArray[np.float64], x: float, y: float, th: float) -> NDArray[np.float64]:
    """``(k, 2)`` m: ``body`` placed at ``(x, y, th)`` (m, rad), rounded as ``transform_points``.

    ``(c·px − s·py) + x`` and ``(s·px + c·py) + y``, in that order.
    """
    c, s = math.cos(th), math.sin(th)
    out = np.empty_like(body)
    for k in range(body.shape[0]):
        out[k, 0] = c * body[k, 0] - s * body[k, 1] + x
        out[k, 1] = s * body[k, 0] + c * body[k, 1] + y
    return out


@njit(cache=True)
def place_from_pose(
    body: NDArray[np.float64], x: float, y: float, th: float
) -> NDArray[np.float64]:
    """``body`` placed at ``(x, y, th)`` as ``x + c·px − s·py`` (the pedestrian test's order).

    The pedestrian test always rounded its placed polygon this way; kept, so that its flags
    stay those it gave.
    """
    c, s = math.cos(th), math.sin(th)
    out = np.empty_like(body)
    for k in range(body.shape[0]):
        out[k, 0] = x + c * body[k, 0] - s * body[k, 1]
        out[k, 1] = y + s * body[k, 0] + c * body[k, 1]
    return out


# -- polygons -----------------------------------------------------------------------------------
@njit(cache=True)
def segment_distance(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    """m, distance from ``(px, py)`` to the segment ``a→b`` (``point_segment_distance``'s ops).

    ``t = ((p − a)·(b − a)) / |b − a|²`` (NaN → 0, clipped to [0, 1]); a zero-length segment is
    its point ``a``.
    """
    abx, aby = bx - ax, by - ay
    denom = abx * abx + aby * aby
    dot = (px - ax) * abx + (py - ay) * aby
    if denom != 0.0:
        t = dot / denom
    elif dot > 0.0:
        t = 1.0  # +inf clipped
    else:
        t = 0.0  # 0/0 is NaN → 0; −inf clipped
    if t != t:
        t = 0.0
    t = min(max(t, 0.0), 1.0)
    dx = px - (ax + t * abx)
    dy = py - (ay + t * aby)
    return math.sqrt(dx * dx + dy * dy)


@njit(cache=True)
def circle_overlaps_polygon(cx: float, cy: float, r: float, poly: NDArray[np.float64]) -> bool:
    """Whether the circle ``(cx, cy)``, ``r`` (m) touches or lies inside ``poly`` ``(k, 2)``.

    The nearest edge within ``r`` (touching counts) or the centre inside (even-odd rule).
    """
    k = poly.shape[0]
    dmin = np.inf
    for e in range(k):
        f = (e + 1) % k
        d = segment_distance(cx, cy, poly[e, 0], poly[e, 1], poly[f, 0], poly[f, 1])
        dmin = min(dmin, d)
    return dmin <= r or point_in_polygon(cx, cy, poly)


@njit(cache=True)
def _segments_intersect(
    px: float, py: float, rx: float, ry: float, qx: float, qy: float, sx: float, sy: float
) -> bool:
    """Whether ``p → p + r`` and ``q → q + s`` cross or touch (collinear overlaps count).

    ``segments_intersect``'s tests for one pair: cross products below 1e-12 count as parallel.
    """
    qpx, qpy = qx - px, qy - py
    rxs = rx * sy - ry * sx
    qpxr = qpx * ry - qpy * rx
    if abs(rxs) >= 1e-12:
        qpxs = qpx * sy - qpy * sx
        t = qpxs / rxs
        u = qpxr / rxs
        return t >= 0 and t <= 1 and u >= 0 and u <= 1
    if abs(qpxr) >= 1e-12:
        return False  # parallel, not collinear
    rr = rx * rx + ry * ry
    if rr == 0.0:
        return False  # a point "segment": NaN overlap interval, as before
    t0 = (qpx * rx + qpy * ry) / rr
    t1 = t0 + (sx * rx + sy * ry) / rr
    return max(t0, t1) >= 0 and min(t0, t1) <= 1


@njit(cache=True)
def polygons_overlap(p: NDArray[np.float64], q: NDArray[np.float64]) -> bool:
    """Whether polygons ``(k, 2)`` and ``(m, 2)`` intersect (edges cross, or one holds one)."""
    k, m = p.shape[0], q.shape[0]
    for i in range(k):
        i1 = (i + 1) % k
        rx, ry = p[i1, 0] - p[i, 0], p[i1, 1] - p[i, 1]
        for j in range(m):
            j1 = (j + 1) % m
            sx, sy = q[j1, 0] - q[j, 0], q[j1, 1] - q[j, 1]
            if _segments_intersect(p[i, 0], p[i, 1], rx, ry, q[j, 0], q[j, 1], sx, sy):
                return True
    return point_in_polygon(p[0, 0], p[0, 1], q) or point_in_polygon(q[0, 0], q[0, 1], p)
