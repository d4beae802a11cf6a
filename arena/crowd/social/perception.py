"""What a pedestrian perceives: vision cone plus personal-space awareness.

An agent sees a point when it lies within ``vision_range`` and within ``vision_angle`` of the
agent's **heading**, or anywhere within ``1.1 · personal_space_radius`` (arena_specs §5.2).
Arena compares the world-frame bearing ``|angle(p − p_i)|`` with the vision angle, so its agents
"look" along +x whatever their heading; we measure the bearing relative to the heading instead.

The queries come twice: vectorised over many agents (:func:`sees`, :func:`nearest_seen_agents`
and the others), the reference, and compiled for one agent (:func:`sees_one`,
:func:`nearest_seen_agent` and the others), which the statechart's kernels call. The compiled
ones give the same answers bit for bit: they scan the same cell lists in the same order (so ties
in distance go the same way as numpy's stable sort) and do the same arithmetic. One catch:
numpy's ``arctan2`` is a SIMD routine that may differ from libm's ``atan2`` (which numba calls)
in the last bit, so a bearing within ``_CONE_MARGIN`` of the cone's edge, the only place where
that bit can change the answer, is decided again with numpy's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, objmode
from numpy.typing import NDArray

from arena.core.geometry import wrap_angle
from arena.crowd.neighbors import _MAX_CELLS, CellList, _build, _scan
from arena.crowd.walls import WallIndex, _closest_on_segment

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

NEAR_FACTOR = 1.1
"""Anything within this many personal-space radii is perceived in every direction (Arena)."""


@dataclass(frozen=True, eq=False)
class Vision:
    """Per-agent perception parameters.

    Attributes:
        range: ``(n,)`` m, vision range.
        half_angle: ``(n,)`` rad, half-angle of the vision cone around the heading.
        near: ``(n,)`` m, all-around perception radius (``1.1 · personal_space_radius``).
    """

    range: FloatArray
    half_angle: FloatArray
    near: FloatArray

    @property
    def reach(self) -> float:
        """The farthest any agent perceives (m); 0 for an empty crowd."""
        if self.range.shape[0] == 0:
            return 0.0
        return float(max(self.range.max(), self.near.max()))


def sees(
    vision: Vision,
    idx: IntArray,
    positions: FloatArray,
    headings: FloatArray,
    targets: FloatArray,
) -> tuple[BoolArray, FloatArray]:
    """Whether agents ``idx`` see the matching ``targets`` (one target per row).

    Args:
        vision: per-agent perception parameters (indexed by ``idx``).
        idx: ``(m,)`` agent indices.
        positions: ``(n, 2)`` agent positions (m).
        headings: ``(n,)`` agent headings (rad).
        targets: ``(m, 2)`` points (m).

    Returns:
        ``(seen, dist)``: ``(m,)`` bool and ``(m,)`` distances (m).
    """
    d = targets - positions[idx]
    dist = np.hypot(d[:, 0], d[:, 1])
    bearing = wrap_angle(np.arctan2(d[:, 1], d[:, 0]) - headings[idx])
    cone = (dist < vision.range[idx]) & (np.abs(bearing) < vision.half_angle[idx])
    return cone | (dist < vision.near[idx]), dist


def _first_per_query(q: IntArray, dist: FloatArray) -> tuple[IntArray, IntArray]:
    """Rows of the nearest candidate per query: ``(queries, rows)``, queries ascending."""
    order = np.lexsort((dist, q))
    uq, first = np.unique(q[order], return_index=True)
    return uq, order[first]


def nearest_seen_agents(
    vision: Vision,
    positions: FloatArray,
    headings: FloatArray,
    query: IntArray,
    cells: CellList | None = None,
) -> IntArray:
    """For each agent in ``query``, the nearest other agent it sees, or -1.

    Args:
        vision: perception parameters of all ``n`` agents.
        positions: ``(n, 2)`` m.
        headings: ``(n,)`` rad.
        query: ``(q,)`` agent indices to look for.
        cells: a cell list over ``positions`` with cell size ≥ ``vision.reach`` (built if None).

    Returns:
        ``(q,)`` agent indices (-1: sees nobody).
    """
    out = np.full(query.shape[0], -1, dtype=np.int64)
    reach = vision.reach
    if query.shape[0] == 0 or positions.shape[0] < 2 or reach <= 0.0:
        return out
    if cells is None:
        cells = CellList(positions, reach)
    nb = cells.query(positions[query], reach)
    qrow, j = nb.pairs()
    i = query[qrow]
    keep = j != i
    qrow, i, j = qrow[keep], i[keep], j[keep]
    seen, dist = sees(vision, i, positions, headings, positions[j])
    if not seen.any():
        return out
    uq, rows = _first_per_query(qrow[seen], dist[seen])
    out[uq] = j[seen][rows]
    return out


def nearest_seen_robots(
    vision: Vision,
    positions: FloatArray,
    headings: FloatArray,
    query: IntArray,
    robot_positions: FloatArray,
) -> IntArray:
    """For each agent in ``query``, the nearest robot it sees, or -1 (dense: robots are few)."""
    q, r = query.shape[0], robot_positions.shape[0]
    out = np.full(q, -1, dtype=np.int64)
    if q == 0 or r == 0:
        return out
    i = np.repeat(query, r)
    k = np.tile(np.arange(r, dtype=np.int64), q)
    seen, dist = sees(vision, i, positions, headings, robot_positions[k])
    dist = np.where(seen, dist, math.inf).reshape(q, r)
    best = np.argmin(dist, axis=1)
    found = np.isfinite(dist[np.arange(q), best])
    out[found] = best[found]
    return out


def nearest_seen_wall_points(
    vision: Vision,
    positions: FloatArray,
    headings: FloatArray,
    query: IntArray,
    index: WallIndex | None,
) -> tuple[BoolArray, FloatArray]:
    """For each agent in ``query``, the nearest segment point it sees.

    Each indexed segment piece within reach offers its closest point to the agent; the nearest
    of those that is seen wins.

    Returns:
        ``(found, points)``: ``(q,)`` bool and ``(q, 2)`` points (m; the agent's own position
        where nothing is seen).
    """
    q = query.shape[0]
    found = np.zeros(q, dtype=bool)
    points = positions[query].copy() if q else np.zeros((0, 2))
    reach = vision.reach
    if q == 0 or index is None or len(index) == 0 or reach <= 0.0:
        return found, points
    p = positions[query]
    nb = index.query(p, reach)
    qrow, piece = nb.pairs()
    if qrow.shape[0] == 0:
        return found, points
    a, b = index.a[piece], index.b[piece]
    e = b - a
    ee = np.einsum("ij,ij->i", e, e)
    t = np.einsum("ij,ij->i", p[qrow] - a, e) / np.where(ee > 0.0, ee, 1.0)
    c = a + np.clip(t, 0.0, 1.0)[:, None] * e
    seen, dist = sees(vision, query[qrow], positions, headings, c)
    if not seen.any():
        return found, points
    uq, rows = _first_per_query(qrow[seen], dist[seen])
    found[uq] = True
    points[uq] = c[seen][rows]
    return found, points


# -- compiled, one agent at a time (the statechart's kernels) -------------------------------------
# Transcriptions of the functions above for one querying agent, bit-identical to them (tested
# against them; see the module docstring); no fastmath.
_CONE_MARGIN = 1e-9
"""rad; far beyond the last-bit spread of two atan2 implementations (~1e-15 rad)."""


@njit(cache=True, inline="always")
def clip01(x: float) -> float:
    """``np.clip(x, 0.0, 1.0)``, signed zeros and NaN included."""
    if math.isnan(x):
        return x
    x = x if x > 0.0 else 0.0
    return x if x < 1.0 else 1.0


@njit(cache=True, inline="always")
def _wrap(a: float) -> float:
    """:func:`arena.core.geometry.wrap_angle` of one angle (numba's float % is Python's)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True)
def _numpy_atan2(y: float, x: float) -> float:
    """``np.arctan2(y, x)`` computed by numpy itself (its SIMD loop, not libm)."""
    with objmode(r="float64"):
        r = float(np.arctan2(y, x))
    return r


@njit(cache=True, inline="always")
def _in_cone(dx: float, dy: float, heading: float, half_angle: float) -> bool:
    """``|wrap(arctan2(dy, dx) − heading)| < half_angle`` with numpy's arctan2."""
    b = abs(_wrap(math.atan2(dy, dx) - heading))
    if abs(b - half_angle) <= _CONE_MARGIN:  # rare: only here can the last bit matter
        b = abs(_wrap(_numpy_atan2(dy, dx) - heading))
    return b < half_angle


@njit(cache=True, inline="always")
def sees_one(vision, positions, headings, i, tx, ty):  # type: ignore[no-untyped-def]
    """:func:`sees` for agent ``i`` and the point ``(tx, ty)`` (m).

    ``vision`` is ``(range, half_angle, near)``, :class:`Vision`'s arrays. Returns
    ``(seen, dist)`` (dist in m).
    """
    vis_range, half_angle, near = vision
    dx = tx - positions[i, 0]
    dy = ty - positions[i, 1]
    dist = math.hypot(dx, dy)
    if dist < near[i]:
        return True, dist
    seen = dist < vis_range[i] and _in_cone(dx, dy, headings[i], half_angle[i])
    return seen, dist


# The same grid, hence the same candidate order, as arena.crowd.neighbors' CellList.
@njit(cache=True)
def cell_grid(points, cell_size):  # type: ignore[no-untyped-def]
    """:class:`~arena.crowd.neighbors.CellList` over ``(m, 2)`` points, as plain values.

    Returns ``(ox, oy, cell, nx, ny, order, starts)``; ``points`` must be non-empty.
    """
    lox, loy = points[0, 0], points[0, 1]
    hix, hiy = lox, loy
    for k in range(1, points.shape[0]):
        lox = min(lox, points[k, 0])
        loy = min(loy, points[k, 1])
        hix = max(hix, points[k, 0])
        hiy = max(hiy, points[k, 1])
    cell = max(cell_size, 1e-6)
    nx = math.floor((hix - lox) / cell) + 1
    ny = math.floor((hiy - loy) / cell) + 1
    while nx * ny > _MAX_CELLS:
        cell *= 2.0
        nx = math.floor((hix - lox) / cell) + 1
        ny = math.floor((hiy - loy) / cell) + 1
    order, starts = _build(points, lox, loy, cell, nx, ny)
    return lox, loy, cell, nx, ny, order, starts


@njit(cache=True)
def candidates(points, grid, x, y, radius, out):  # type: ignore[no-untyped-def]
    """Indices of ``points`` strictly within ``radius`` of ``(x, y)`` into ``out``; the count.

    The order is :meth:`CellList.query`'s (every point, in index order, for an infinite radius).
    """
    if not math.isfinite(radius):
        for j in range(points.shape[0]):
            out[j] = j
        return points.shape[0]
    ox, oy, cell, nx, ny, order, starts = grid
    rings = max(1, math.ceil(radius / cell))
    return _scan(points, order, starts, ox, oy, cell, nx, ny, x, y, radius, rings, -1, out, 0, True)


@njit(cache=True)
def nearest_seen_agent(  # type: ignore[no-untyped-def]
    vision, positions, headings, grid, reach, i, buf
):
    """:func:`nearest_seen_agents` for agent ``i`` (-1: none), compiled.

    ``grid``: :func:`cell_grid` over ``positions`` with cell ≥ ``reach`` (m, the vision
    reach); ``buf``: ``(n,)`` int scratch.
    """
    m = candidates(positions, grid, positions[i, 0], positions[i, 1], reach, buf)
    best, best_d = -1, math.inf
    for k in range(m):
        j = buf[k]
        if j == i:
            continue
        seen, dist = sees_one(vision, positions, headings, i, positions[j, 0], positions[j, 1])
        if seen and (best < 0 or dist < best_d):  # first of equals, as a stable sort
            best, best_d = j, dist
    return best


@njit(cache=True)
def nearest_seen_robot(vision, positions, headings, robot_pos, i):  # type: ignore[no-untyped-def]
    """:func:`nearest_seen_robots` for agent ``i`` and ``(r, 2)`` robots (-1: none), compiled."""
    best, best_d = -1, math.inf
    for k in range(robot_pos.shape[0]):
        seen, dist = sees_one(vision, positions, headings, i, robot_pos[k, 0], robot_pos[k, 1])
        if seen and dist < best_d:
            best, best_d = k, dist
    return best


@njit(cache=True)
def nearest_seen_wall_point(  # type: ignore[no-untyped-def]
    vision, positions, headings, index, reach, i, buf
):
    """:func:`nearest_seen_wall_points` for agent ``i``, compiled.

    ``index`` is :func:`wall_index_arrays`' tuple, ``buf`` a ``(pieces,)`` int scratch.
    Returns ``(found, x, y)`` (m).
    """
    a, b, mids, half, grid = index
    px, py = positions[i, 0], positions[i, 1]
    m = candidates(mids, grid, px, py, reach + half, buf)
    r2 = reach * reach
    found, best_d, bx, by = False, math.inf, px, py
    for k in range(m):
        j = buf[k]
        ax, ay = a[j, 0], a[j, 1]
        # WallIndex.query's filter, then the closest point as perception computes it
        fx, fy = _closest_on_segment(px, py, ax, ay, b[j, 0], b[j, 1])
        if not (fx - px) ** 2 + (fy - py) ** 2 < r2:
            continue
        ex, ey = b[j, 0] - ax, b[j, 1] - ay
        ee = ex * ex + ey * ey
        t = clip01(((px - ax) * ex + (py - ay) * ey) / (ee if ee > 0.0 else 1.0))
        cx, cy = ax + t * ex, ay + t * ey
        seen, dist = sees_one(vision, positions, headings, i, cx, cy)
        if seen and (not found or dist < best_d):
            found, best_d, bx, by = True, dist, cx, cy
    return found, bx, by


WallArrays = tuple[
    FloatArray, FloatArray, FloatArray, float,
    tuple[float, float, float, int, int, IntArray, IntArray],
]
"""A wall index as the kernels read it (see :func:`wall_index_arrays`)."""


def wall_index_arrays(index: WallIndex | None) -> WallArrays:
    """A :class:`~arena.crowd.walls.WallIndex` as the tuple the kernels read (``None``: empty).

    ``(a, b, mids, half, (ox, oy, cell, nx, ny, order, starts))``: piece ends ``(p, 2)``, the
    cell list's points (piece midpoints) and grid.
    """
    if index is None or len(index) == 0:
        empty = np.zeros((0, 2))
        none = np.zeros(0, dtype=np.int64)
        return empty, empty, empty, 0.0, (0.0, 0.0, 1.0, 0, 0, none, none)
    c = index._cells
    grid = (float(c.origin[0]), float(c.origin[1]), float(c.cell), int(c.shape[0]),
            int(c.shape[1]), c.order, c.starts)
    return index.a, index.b, c.points, float(index.half), grid
