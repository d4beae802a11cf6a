"""What a pedestrian perceives: vision cone plus personal-space awareness, vectorised.

An agent sees a point when it lies within ``vision_range`` and within ``vision_angle`` of the
agent's **heading**, or anywhere within ``1.1 · personal_space_radius`` (arena_specs §5.2).
Arena compares the world-frame bearing ``|angle(p − p_i)|`` with the vision angle, so its agents
"look" along +x whatever their heading; we measure the bearing relative to the heading instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.core.geometry import wrap_angle
from arena.crowd.neighbors import CellList
from arena.crowd.walls import WallIndex

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
