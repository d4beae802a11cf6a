"""Compiled contact tests: one numba function per test, shared by every caller.

A robot's footprint ``body`` is its ``(k, 2)`` convex polygon in the robot frame (m), or a
``(0, 2)`` array for a circle of ``radius`` (m). Each test first rejects with a bounding circle,
so the common "nothing near" case costs a few array look-ups.

The float operations are those of the NumPy code this module replaced
(:func:`~arena.core.geometry.transform_points`, ``point_segment_distance``,
``segments_intersect``, ``convex_polygon_overlaps_squares`` ...), element by element: on 100,000
random poses and 20,000 poses bisected onto the touching boundary every flag came out the same,
but for one robot-robot boundary case in 5,000 (the bounding-circle reject and the sweep length
use the C library's ``hypot``, Python's ``math.hypot`` may round 1 ulp apart). The
separating-axis projections are fused multiply-adds, as OpenBLAS's FMA kernels rounded the former
matrix products (plain products changed 547 of those boundary flags): now the same on every CPU.

:func:`contacts_rows` tests every robot of every world in one call (flat layout of
:mod:`arena.sim.contacts.bank`); the per-robot wrappers of :mod:`arena.sim.contacts.checks`
call the same functions one robot at a time.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from arena.sim.contacts.polygons import (
    circle_overlaps_polygon,
    fma,
    place,
    place_from_pose,
    polygons_overlap,
)

SQRT2 = math.sqrt(2.0)


# -- the grid -----------------------------------------------------------------------------------
@njit(cache=True)
def _squares_within(
    occupied: NDArray[np.bool_],
    r0: int,
    r1: int,
    c0: int,
    c1: int,
    ox: float,
    oy: float,
    res: float,
    x: float,
    y: float,
    radius: float,
) -> bool:
    """Whether a blocking cell of rows ``r0:r1``, columns ``c0:c1`` overlaps a circle.

    The cell squares (edge ``res`` m, grid origin ``(ox, oy)`` m) against the open disc of
    ``radius`` (m) about ``(x, y)`` (m): the clamped-gap test ``dx² + dy² < radius²``.
    """
    half = 0.5 * res
    r2 = radius * radius
    for row in range(r0, r1):
        cy = oy + (row + 0.5) * res
        dy = max(abs(cy - y) - half, 0.0)
        for col in range(c0, c1):
            if not occupied[row, col]:
                continue
            cx = ox + (col + 0.5) * res
            dx = max(abs(cx - x) - half, 0.0)
            if dx * dx + dy * dy < r2:
                return True
    return False


@njit(cache=True)
def _polygon_overlaps_cells(
    poly: NDArray[np.float64],
    occupied: NDArray[np.bool_],
    r0: int,
    r1: int,
    c0: int,
    c1: int,
    ox: float,
    oy: float,
    res: float,
) -> bool:
    """Separating-axis test of a convex polygon ``(k, 2)`` (m) against the window's blocking cells.

    A cell square must overlap the polygon's bounding box, then on every edge normal ``a`` its
    projection ``c·a ± half·(|a_x| + |a_y|)`` must overlap the polygon's (touching edges do not
    count). The dot products are fused as OpenBLAS's FMA kernels rounded the former
    ``poly @ normals.T`` and ``centres @ normals.T``: ``fma(p_y, a_y, p_x·a_x)`` for a matrix of
    two rows or more, ``fma(p_x, a_x, p_y·a_y)`` for a single row (its vector kernel).
    """
    m = 0
    for row in range(r0, r1):
        for col in range(c0, c1):
            if occupied[row, col]:
                m += 1
    if m == 0:
        return False
    k = poly.shape[0]
    half = 0.5 * res
    nx = np.empty(k)
    ny = np.empty(k)
    pmin = np.full(k, np.inf)
    pmax = np.full(k, -np.inf)
    extent = np.empty(k)
    for a in range(k):
        b = (a + 1) % k
        nx[a] = -(poly[b, 1] - poly[a, 1])
        ny[a] = poly[b, 0] - poly[a, 0]
        extent[a] = half * (abs(nx[a]) + abs(ny[a]))
    for v in range(k):
        for a in range(k):
            if k >= 2:
                pr = fma(poly[v, 1], ny[a], poly[v, 0] * nx[a])
            else:
                pr = fma(poly[v, 0], nx[a], poly[v, 1] * ny[a])
            pmin[a] = min(pmin[a], pr)
            pmax[a] = max(pmax[a], pr)
    xmin, xmax = poly[:, 0].min(), poly[:, 0].max()
    ymin, ymax = poly[:, 1].min(), poly[:, 1].max()
    for row in range(r0, r1):
        cy = oy + (row + 0.5) * res
        for col in range(c0, c1):
            if not occupied[row, col]:
                continue
            cx = ox + (col + 0.5) * res
            if not (
                cx - half < xmax and cx + half > xmin and cy - half < ymax and cy + half > ymin
            ):
                continue
            hit = True
            for a in range(k):
                pc = fma(cy, ny[a], cx * nx[a]) if m >= 2 else fma(cx, nx[a], cy * ny[a])
                if not (pc - extent[a] < pmax[a] and pc + extent[a] > pmin[a]):
                    hit = False
                    break
            if hit:
                return True
    return False


@njit(cache=True)
def grid_hit(
    occupied: NDArray[np.bool_],
    distance: NDArray[np.float64],
    gpar: NDArray[np.float64],
    body: NDArray[np.float64],
    radius: float,
    reach: float,
    x: float,
    y: float,
    th: float,
) -> bool:
    """Whether the footprint at ``(x, y, th)`` overlaps a blocking cell or leaves the map.

    Args:
        occupied: ``(h, w)`` bool, the grid's blocking cells.
        distance: ``(h, w)`` m, the grid's distance map (cell centre to nearest blocking centre).
        gpar: ``(7,)`` ``[origin_x, origin_y, resolution, xmin, ymin, xmax, ymax]`` (m).
        body: the footprint (module docstring).
        radius: m, its bounding radius.
        reach: m, a circle surely holding it (``Footprint.reach``).
        x: m, the pose.
        y: m.
        th: rad.
    """
    ox, oy, res = gpar[0], gpar[1], gpar[2]
    xmin, ymin, xmax, ymax = gpar[3], gpar[4], gpar[5], gpar[6]
    if not (xmin <= x < xmax and ymin <= y < ymax):
        return True
    r = radius
    is_circle = body.shape[0] == 0
    if x - r < xmin or y - r < ymin or x + r > xmax or y + r > ymax:
        # Near the border: only a real overhang counts.
        if is_circle:
            return True
        pts = place(body, x, y, th)
        if (
            pts[:, 0].min() < xmin
            or pts[:, 1].min() < ymin
            or pts[:, 0].max() > xmax
            or pts[:, 1].max() > ymax
        ):
            return True
    h, w = occupied.shape
    # clamped: a position rounding onto the far border must not index past the map
    col = min(max(int((x - ox) // res), 0), w - 1)
    row = min(max(int((y - oy) // res), 0), h - 1)
    # No blocking cell square lies nearer than EDT(centre cell) - res*sqrt2 (two half diagonals).
    if distance[row, col] - res * SQRT2 >= r:
        return False
    k = math.ceil(r / res) + 1
    r0, r1 = max(row - k, 0), min(row + k + 1, h)
    c0, c1 = max(col - k, 0), min(col + k + 1, w)
    # A circle's exact test; for a polygon, a square that misses the circle holding it misses
    # the polygon too, so the separating-axis tests run only when some square comes that near.
    near = _squares_within(occupied, r0, r1, c0, c1, ox, oy, res, x, y, reach)
    if is_circle or not near:
        return near
    poly = place(body, x, y, th)
    return _polygon_overlaps_cells(poly, occupied, r0, r1, c0, c1, ox, oy, res)


@njit(cache=True)
def swept_grid_hit(
    occupied: NDArray[np.bool_],
    distance: NDArray[np.float64],
    gpar: NDArray[np.float64],
    body: NDArray[np.float64],
    radius: float,
    reach: float,
    pose: NDArray[np.float64],
    previous: NDArray[np.float64],
    sweep: bool,
) -> bool:
    """:func:`grid_hit` at ``pose`` ``(3,)``, and with ``sweep`` along the way from ``previous``.

    The way is cut into ``k = ceil(d / spacing)`` equal parts, ``spacing = max(res, radius) / 2``,
    so that consecutive footprints overlap by at least half a cell (no tunnelling through a
    one-cell wall); the heading turns the short way. The fractions are ``np.linspace(0, 1,
    k + 1)[1:]``'s: ``i · (1 / k)``, the last exactly 1.
    """
    x, y, th = pose[0], pose[1], pose[2]
    px, py, pth = previous[0], previous[1], previous[2]
    k = 0
    if sweep:
        dist = math.hypot(x - px, y - py)
        spacing = max(gpar[2] * 0.5, radius * 0.5)
        k = math.ceil(dist / spacing)
    if k <= 1:
        return grid_hit(occupied, distance, gpar, body, radius, reach, x, y, th)
    step = 1.0 / k
    dtheta = (th - pth + math.pi) % (2 * math.pi) - math.pi
    for i in range(1, k + 1):
        s = 1.0 if i == k else i * step
        if grid_hit(
            occupied,
            distance,
            gpar,
            body,
            radius,
            reach,
            px + s * (x - px),
            py + s * (y - py),
            pth + s * dtheta,
        ):
            return True
    return False


# -- obstacles, pedestrians, robots -------------------------------------------------------------
@njit(cache=True)
def _near_circles(
    centers: NDArray[np.float64], radii: NDArray[np.float64], x: float, y: float, radius: float
) -> NDArray[np.int64]:
    """Indices (ascending) of the circles ``(k, 2)``, ``(k,)`` within ``radius`` of ``(x, y)``.

    ``flatnonzero(hypot(c - p) <= radii + radius)`` (numba's ``hypot`` is the C library's, as
    numpy's).
    """
    out = np.empty(centers.shape[0], dtype=np.int64)
    k = 0
    for j in range(centers.shape[0]):
        if math.hypot(centers[j, 0] - x, centers[j, 1] - y) <= radii[j] + radius:
            out[k] = j
            k += 1
    return out[:k]


@njit(cache=True)
def first_obstacle(
    centers: NDArray[np.float64],
    radii: NDArray[np.float64],
    vstart: NDArray[np.int64],
    verts: NDArray[np.float64],
    body: NDArray[np.float64],
    radius: float,
    x: float,
    y: float,
    th: float,
) -> int:
    """Index of the first obstacle (ascending) the footprint at ``(x, y, th)`` overlaps, or -1.

    Obstacle ``j`` has bounding circle ``centers[j]``, ``radii[j]`` (m) and polygon
    ``verts[vstart[j]:vstart[j + 1]]`` (m); the footprint's bounding circle (``radius``)
    rejects first.
    """
    if centers.shape[0] == 0:
        return -1
    near = _near_circles(centers, radii, x, y, radius)
    if near.size == 0:
        return -1
    is_circle = body.shape[0] == 0
    poly = body if is_circle else place(body, x, y, th)
    for j in near:
        ob = verts[vstart[j] : vstart[j + 1]]
        if is_circle:
            if circle_overlaps_polygon(x, y, radius, ob):
                return j
        elif polygons_overlap(poly, ob):
            return j
    return -1


@njit(cache=True)
def nearest_agent(
    body: NDArray[np.float64],
    radius: float,
    x: float,
    y: float,
    th: float,
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
) -> int:
    """Nearest pedestrian circle overlapping the footprint at ``(x, y, th)``, else -1.

    ``positions`` ``(n, 2)`` m and ``radii`` ``(n,)`` m the circles; ``radius`` the footprint's
    bounding radius (m). A circle overlaps a convex polygon when its centre is inside, or when
    it comes within its radius of an edge (touching counts); a circular footprint is its
    bounding circle (strict overlap).
    """
    n = positions.shape[0]
    if n == 0:
        return -1
    poly = place_from_pose(body, x, y, th)
    best, best_d = -1, np.inf
    k = poly.shape[0]
    for i in range(n):
        px, py, r = positions[i, 0], positions[i, 1], radii[i]
        d = math.hypot(px - x, py - y)
        if d >= r + radius:
            continue  # outside the bounding circle
        if k > 0:
            inside = True
            sign = 0.0
            near = False
            for j in range(k):
                ax, ay = poly[j, 0], poly[j, 1]
                bx, by = poly[(j + 1) % k, 0], poly[(j + 1) % k, 1]
                ex, ey = bx - ax, by - ay
                cross = ex * (py - ay) - ey * (px - ax)
                if sign == 0.0:
                    sign = 1.0 if cross >= 0 else -1.0
                elif cross * sign < 0:
                    inside = False
                ee = ex * ex + ey * ey
                t = ((px - ax) * ex + (py - ay) * ey) / ee if ee > 0 else 0.0
                t = min(max(t, 0.0), 1.0)
                if math.hypot(px - ax - t * ex, py - ay - t * ey) <= r:
                    near = True
            if not (inside or near):
                continue
        if d < best_d:
            best, best_d = i, d
    return best


@njit(cache=True)
def robots_overlap(
    body_a: NDArray[np.float64],
    r_a: float,
    xa: float,
    ya: float,
    ta: float,
    body_b: NDArray[np.float64],
    r_b: float,
    xb: float,
    yb: float,
    tb: float,
) -> bool:
    """Whether footprint ``a`` at ``(xa, ya, ta)`` and ``b`` at ``(xb, yb, tb)`` overlap.

    Bounding circles (radii ``r_a``, ``r_b`` m) reject first; two circles overlap when their
    bounding circles do.
    """
    if math.hypot(xa - xb, ya - yb) >= r_a + r_b:
        return False
    a_circle, b_circle = body_a.shape[0] == 0, body_b.shape[0] == 0
    if a_circle and b_circle:
        return True
    if a_circle:
        return circle_overlaps_polygon(xa, ya, r_a, place(body_b, xb, yb, tb))
    if b_circle:
        return circle_overlaps_polygon(xb, yb, r_b, place(body_a, xa, ya, ta))
    return polygons_overlap(place(body_a, xa, ya, ta), place(body_b, xb, yb, tb))


# -- every robot of every world -----------------------------------------------------------------
@njit(cache=True)
def _contacts_row(
    i: int,
    rows_i: bool,
    poses: NDArray[np.float64],
    previous: NDArray[np.float64],
    sweep: bool,
    row_world: NDArray[np.int64],
    robot_off: NDArray[np.int64],
    g_off: NDArray[np.int64],
    g_shape: NDArray[np.int64],
    g_par: NDArray[np.float64],
    occ: NDArray[np.bool_],
    dist: NDArray[np.float64],
    o_off: NDArray[np.int64],
    o_c: NDArray[np.float64],
    o_r: NDArray[np.float64],
    o_vs: NDArray[np.int64],
    o_v: NDArray[np.float64],
    fp_r: NDArray[np.float64],
    fp_reach: NDArray[np.float64],
    fp_vs: NDArray[np.int64],
    fp_v: NDArray[np.float64],
    ag_off: NDArray[np.int64],
    ag_pos: NDArray[np.float64],
    ag_r: NDArray[np.float64],
    wall: NDArray[np.bool_],
    obstacle: NDArray[np.int64],
    agent: NDArray[np.int64],
    robot: NDArray[np.int64],
) -> None:
    """All four tests of global robot row ``i``, on its own world's slices only.

    With ``rows_i`` false it only writes "no contact" (``False``, ``-1``) into row ``i``.
    """
    robot[i] = -1
    if not rows_i:
        wall[i] = False
        obstacle[i] = -1
        agent[i] = -1
        return
    w = row_world[i]
    h, wd = g_shape[w, 0], g_shape[w, 1]
    start = g_off[w]
    occupied = occ[start : start + h * wd].reshape((h, wd))
    distance = dist[start : start + h * wd].reshape((h, wd))
    body = fp_v[fp_vs[i] : fp_vs[i + 1]]
    r = fp_r[i]
    x, y, th = poses[i, 0], poses[i, 1], poses[i, 2]
    wall[i] = swept_grid_hit(
        occupied, distance, g_par[w], body, r, fp_reach[i], poses[i], previous[i], sweep
    )
    o0, o1 = o_off[w], o_off[w + 1]
    obstacle[i] = first_obstacle(o_c[o0:o1], o_r[o0:o1], o_vs[o0 : o1 + 1], o_v, body, r, x, y, th)
    a0, a1 = ag_off[w], ag_off[w + 1]
    agent[i] = nearest_agent(body, r, x, y, th, ag_pos[a0:a1], ag_r[a0:a1])
    first = robot_off[w]
    for j in range(first, robot_off[w + 1]):
        if j != i and robots_overlap(
            body, r, x, y, th, fp_v[fp_vs[j] : fp_vs[j + 1]], fp_r[j], poses[j, 0], poses[j, 1],
            poses[j, 2],
        ):
            robot[i] = j - first
            break


@njit(cache=True)
def _rows_serial(
    rows: NDArray[np.bool_], poses, previous, sweep, row_world, robot_off, g_off, g_shape, g_par,
    occ, dist, o_off, o_c, o_r, o_vs, o_v, fp_r, fp_reach, fp_vs, fp_v, ag_off, ag_pos, ag_r,
    wall, obstacle, agent, robot,
) -> None:  # fmt: skip
    """:func:`_contacts_row` for each row (tested where ``rows[i]``), one after the other."""
    for i in range(rows.shape[0]):
        _contacts_row(
            i, rows[i], poses, previous, sweep, row_world, robot_off, g_off, g_shape, g_par,
            occ, dist, o_off, o_c, o_r, o_vs, o_v, fp_r, fp_reach, fp_vs, fp_v, ag_off, ag_pos,
            ag_r, wall, obstacle, agent, robot,
        )  # fmt: skip


@njit(cache=True, parallel=True)
def _rows_parallel(
    rows: NDArray[np.bool_], poses, previous, sweep, row_world, robot_off, g_off, g_shape, g_par,
    occ, dist, o_off, o_c, o_r, o_vs, o_v, fp_r, fp_reach, fp_vs, fp_v, ag_off, ag_pos, ag_r,
    wall, obstacle, agent, robot,
) -> None:  # fmt: skip
    """:func:`_rows_serial` over numba's threads (each row writes only its own outputs)."""
    for i in prange(rows.shape[0]):
        _contacts_row(
            i, rows[i], poses, previous, sweep, row_world, robot_off, g_off, g_shape, g_par,
            occ, dist, o_off, o_c, o_r, o_vs, o_v, fp_r, fp_reach, fp_vs, fp_v, ag_off, ag_pos,
            ag_r, wall, obstacle, agent, robot,
        )  # fmt: skip


def contacts_rows(parallel: bool) -> Callable[..., None]:
    """The rows kernel: :func:`_rows_parallel` (numba's threads) or :func:`_rows_serial`.

    Both give the same flags. Their arguments are built by
    :class:`~arena.sim.contacts.bank.ContactBank`; every row of the four outputs is written.
    """
    return _rows_parallel if parallel else _rows_serial
