"""Grid casting of :mod:`arena.sensors.lidar2d`: beams walking the occupancy grid.

Each beam walks the grid with the Amanatides–Woo cell traversal (DDA) and crosses open space by
sphere tracing on the map's distance transform (:func:`_walk`); see the package docstring
(:mod:`arena.sensors.lidar2d.model`, "Grid casting").
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

#: Tolerance (grid cells, and beam parameter in cells) under which a beam counts as passing
#: through a cell corner or as lying on a grid line. It only ever makes beams stop *earlier*
#: (it widens blocking cells by a hair), so rounding can never open a diagonal gap.
CORNER_EPS = 1e-9

# Safe-step margin in cells. The exact bound is √2 ≈ 1.41421 (two half-diagonals); the extra
# 0.0858 cells absorb float32 rounding of the distance map (< 2e-3 cells on maps up to 10⁴
# cells across) and of the beam point ``o + t·d``.
_JUMP_MARGIN = 1.5
# Jump only when it advances at least this many cells; shorter safe steps are cheaper to walk
# cell by cell with the DDA, which needs no re-initialisation.
_JUMP_MIN = 1.0


@njit(cache=True, fastmath=False)
def _blocked(distg: NDArray[np.float32], cx: int, cy: int) -> bool:
    """Whether cell ``(row cy, col cx)`` is on the map and blocking (its distance is 0)."""
    h, w = distg.shape
    if cx < 0 or cy < 0 or cx >= w or cy >= h:
        return False
    return distg[cy, cx] == 0.0


@njit(cache=True, fastmath=False)
def _origin_touches_wall(gox: float, goy: float, distg: NDArray[np.float32]) -> bool:
    """Whether grid point ``(gox, goy)`` lies in a closed blocking square (up to CORNER_EPS)."""
    cx = math.floor(gox)
    cy = math.floor(goy)
    if _blocked(distg, cx, cy):
        return True
    fx = gox - cx
    fy = goy - cy
    # The neighbour across a grid line the point (nearly) lies on also touches it.
    nx = cx - 1 if fx <= CORNER_EPS else (cx + 1 if fx >= 1.0 - CORNER_EPS else cx)
    ny = cy - 1 if fy <= CORNER_EPS else (cy + 1 if fy >= 1.0 - CORNER_EPS else cy)
    if nx != cx and _blocked(distg, nx, cy):
        return True
    if ny != cy and _blocked(distg, cx, ny):
        return True
    return nx != cx and ny != cy and _blocked(distg, nx, ny)


@njit(cache=True, fastmath=False)
def _cast_axis_line(
    g_along: float, k: int, sgn: int, t0: float, t1: float, distg: NDArray[np.float32],
    horizontal: bool,
) -> float:
    """Beam lying on a grid line: walk it checking the cells on both sides.

    Args:
        g_along: origin coordinate along the beam (grid cells): x for a horizontal line, y for a
            vertical one.
        k: the grid line's index (y = k for horizontal, x = k for vertical); the beam touches the
            rows (or columns) ``k − 1`` and ``k``.
        sgn: +1 or −1, the beam's direction along the line.
        t0: parameter (cells) where the beam enters the map.
        t1: parameter (cells) beyond which nothing counts (map exit or limit).
        distg: ``(H, W)`` distance map in cells (0 = blocking).
        horizontal: whether the line is horizontal.

    Returns:
        Parameter (cells) of the first touch, or ``inf``.
    """
    h, w = distg.shape
    n_along = w if horizontal else h
    # Start in the cell holding the entry point (it may sit on the far map edge, one off-map).
    c = math.floor(g_along + sgn * t0)
    while (c < n_along) if sgn > 0 else (c >= 0):
        # Entry parameter of cell c along the line (clamped to the map entry t0).
        tc = (c - g_along) if sgn > 0 else (g_along - (c + 1))
        tc = max(tc, t0)
        if tc > t1:
            return math.inf
        if horizontal:
            hit = _blocked(distg, c, k) or _blocked(distg, c, k - 1)
        else:
            hit = _blocked(distg, k, c) or _blocked(distg, k - 1, c)
        if hit:
            return tc
        c += sgn
    return math.inf


@njit(cache=True, fastmath=False)
def _clip_to_map(
    gox: float, goy: float, dx: float, dy: float, tlim: float, w: int, h: int
) -> tuple[float, float]:
    """Parameter interval ``[t0, t1]`` (cells) of the beam inside the closed box [0, W]×[0, H].

    ``t1`` is also capped at ``tlim``; ``t0 > t1`` means the beam misses the map (slab method).
    """
    t0 = 0.0
    t1 = tlim
    if dx > 0.0:
        t0 = max(t0, -gox / dx)
        t1 = min(t1, (w - gox) / dx)
    elif dx < 0.0:
        t0 = max(t0, (w - gox) / dx)
        t1 = min(t1, -gox / dx)
    elif gox < 0.0 or gox > w:
        return 1.0, 0.0
    if dy > 0.0:
        t0 = max(t0, -goy / dy)
        t1 = min(t1, (h - goy) / dy)
    elif dy < 0.0:
        t0 = max(t0, (h - goy) / dy)
        t1 = min(t1, -goy / dy)
    elif goy < 0.0 or goy > h:
        return 1.0, 0.0
    return t0, t1


@njit(cache=True, fastmath=False)
def _on_grid_line(g: float, d: float) -> bool:
    """Whether a beam with zero direction component ``d`` runs along the grid line near ``g``."""
    return d == 0.0 and abs(g - math.floor(g + 0.5)) <= CORNER_EPS


@njit(cache=True, fastmath=False)
def _walk(
    gox: float, goy: float, dx: float, dy: float, inv_dx: float, inv_dy: float, t: float,
    t1: float, distg: NDArray[np.float32],
) -> float:
    """Cell walk (DDA, with sphere-tracing jumps in open space) from parameter ``t`` to ``t1``.

    The beam must not lie on a grid line (see :func:`_cast_axis_line`) and ``o + t·d`` must be
    on the map, in free space reached without touching a wall (or at the map entry).

    Args:
        gox: beam origin x in grid cells (``(x − origin_x) / res``).
        goy: beam origin y in grid cells.
        dx: unit direction x (exactly 0 for a vertical beam).
        dy: unit direction y.
        inv_dx: ``1 / dx`` (``inf`` for ``dx == 0``).
        inv_dy: ``1 / dy`` (``inf`` for ``dy == 0``).
        t: start parameter (cells).
        t1: parameter (cells) beyond which hits do not matter (limit or map exit).
        distg: ``(H, W)`` float32 distance from each cell centre to the nearest blocking cell
            centre, in cells; 0 marks blocking cells.

    Returns:
        The beam parameter (cells) at which it first touches a closed blocking square, or
        ``inf`` if none does up to ``t1``.

    Why a jump never skips a wall: let ``p`` lie in (the closed square of) cell ``c`` and
    ``D = distg[c]`` be the distance from ``c``'s centre to the nearest blocking centre. Every
    point of ``c`` is within √2/2 of ``c``'s centre and every point of a blocking square is within
    √2/2 of that square's centre, so by the triangle inequality every point of every blocking
    square is at least ``D − √2`` from ``p``. The beam segment from ``p`` of length
    ``s = D − 1.5 < D − √2`` therefore stays ≥ 0.086 cells away from all blocking squares,
    including under float32 rounding of ``D`` and rounding of ``p`` (both ≪ 0.01 cells). The walk
    resumes from the cell containing the new point, so no cell the beam touches after the jump
    is missed either.
    """
    h, w = distg.shape
    sx = 1 if dx > 0.0 else -1
    sy = 1 if dy > 0.0 else -1
    # The next vertical/horizontal grid line lies at cell index + off (1 when moving up).
    off_x = 1 if dx > 0.0 else 0
    off_y = 1 if dy > 0.0 else 0

    cx = min(max(math.floor(gox + t * dx), 0), w - 1)
    cy = min(max(math.floor(goy + t * dy), 0), h - 1)
    # Boundary parameters are recomputed from the origin (not accumulated) so a face hit is
    # exact to one rounding.
    tmx = (cx + off_x - gox) * inv_dx if dx != 0.0 else math.inf
    tmy = (cy + off_y - goy) * inv_dy if dy != 0.0 else math.inf
    while True:
        d = distg[cy, cx]
        if d == 0.0:
            return t
        step = d - _JUMP_MARGIN
        if step >= _JUMP_MIN:
            t += step
            if t > t1:
                return math.inf
            cx = min(max(math.floor(gox + t * dx), 0), w - 1)
            cy = min(max(math.floor(goy + t * dy), 0), h - 1)
            tmx = (cx + off_x - gox) * inv_dx if dx != 0.0 else math.inf
            tmy = (cy + off_y - goy) * inv_dy if dy != 0.0 else math.inf
            continue
        diff = tmx - tmy
        if diff < -CORNER_EPS:
            t = tmx
            cx += sx
            tmx = (cx + off_x - gox) * inv_dx
        elif diff > CORNER_EPS:
            t = tmy
            cy += sy
            tmy = (cy + off_y - goy) * inv_dy
        else:
            # Through a corner (up to rounding): the beam touches both side cells there, so a
            # blocking one stops it — this is what closes zero-width diagonal gaps.
            t = min(tmx, tmy)
            if t > t1:
                return math.inf
            if _blocked(distg, cx + sx, cy) or _blocked(distg, cx, cy + sy):
                return t
            cx += sx
            cy += sy
            tmx = (cx + off_x - gox) * inv_dx
            tmy = (cy + off_y - goy) * inv_dy
        if t > t1 or cx < 0 or cy < 0 or cx >= w or cy >= h:
            return math.inf


@njit(cache=True, fastmath=False)
def _cast_grid(
    gox: float, goy: float, dx: float, dy: float, tlim: float, distg: NDArray[np.float32]
) -> float:
    """First touch of one beam with a blocking cell, in grid units (the scalar reference path).

    Args:
        gox: beam origin x in grid cells.
        goy: beam origin y in grid cells.
        dx: unit direction x (exactly 0 for a vertical beam).
        dy: unit direction y (exactly 0 for a horizontal beam).
        tlim: parameter (cells) beyond which hits do not matter.
        distg: ``(H, W)`` float32 distance map in cells (0 = blocking).

    Returns:
        The beam parameter (cells) of the first touch, or ``inf`` if none before ``tlim`` or
        before the beam leaves the map. :func:`_cast_grid_many` computes the same values for many
        beams at once.
    """
    h, w = distg.shape
    t0, t1 = _clip_to_map(gox, goy, dx, dy, tlim, w, h)
    if t0 > t1:
        return math.inf
    if _on_grid_line(goy, dy):
        k = math.floor(goy + 0.5)
        return _cast_axis_line(gox, k, 1 if dx > 0 else -1, t0, t1, distg, True)
    if _on_grid_line(gox, dx):
        k = math.floor(gox + 0.5)
        return _cast_axis_line(goy, k, 1 if dy > 0 else -1, t0, t1, distg, False)
    inv_dx = 1.0 / dx if dx != 0.0 else math.inf
    inv_dy = 1.0 / dy if dy != 0.0 else math.inf
    return _walk(gox, goy, dx, dy, inv_dx, inv_dy, t0, t1, distg)


@njit(cache=True, fastmath=False)
def _cast_grid_many(
    gox: float, goy: float, dx: NDArray[np.float64], dy: NDArray[np.float64],
    tlim: NDArray[np.float64], distg: NDArray[np.float32], t_out: NDArray[np.float64],
    t1s: NDArray[np.float64], active: NDArray[np.int64], pending: NDArray[np.int64],
) -> None:
    """:func:`_cast_grid` for all beams of one origin, breadth first.

    A single beam's sphere tracing is one long chain of dependent steps (look up the distance,
    jump, find the new cell, look up again), so the CPU idles on latency. Here the open-space
    jumps of all beams advance in rounds, one jump per beam per round: the steps within a round
    are independent and overlap. Beams whose safe step has become short leave the rounds and
    finish with the scalar :func:`_walk`, from exactly the state the scalar path would reach.

    Args:
        gox: origin x in grid cells.
        goy: origin y in grid cells.
        dx: ``(n,)`` unit directions x.
        dy: ``(n,)`` unit directions y.
        tlim: ``(n,)`` per-beam parameter limits (cells).
        distg: ``(H, W)`` float32 distance map in cells.
        t_out: ``(n,)`` output: hit parameter (cells) or ``inf``.
        t1s: ``(n,)`` scratch.
        active: ``(n,)`` int scratch.
        pending: ``(n,)`` int scratch.
    """
    h, w = distg.shape
    n = dx.shape[0]
    # Every beam starting on the map makes the same first jump, from the origin's cell.
    t_first = 0.0
    if 0.0 <= gox < w and 0.0 <= goy < h:
        t_first = distg[int(goy), int(gox)] - _JUMP_MARGIN
        if t_first < _JUMP_MIN:
            t_first = 0.0
    n_act = 0
    n_pend = 0
    for i in range(n):
        t_out[i] = math.inf
        t0, t1 = _clip_to_map(gox, goy, dx[i], dy[i], tlim[i], w, h)
        if t0 > t1:
            continue
        if _on_grid_line(goy, dy[i]) or _on_grid_line(gox, dx[i]):
            t_out[i] = _cast_grid(gox, goy, dx[i], dy[i], tlim[i], distg)
            continue
        t0 = max(t0, t_first)
        if t0 > t1:
            continue
        t_out[i] = t0  # current parameter while the beam is in flight
        t1s[i] = t1
        active[n_act] = i
        n_act += 1
    while n_act > 0:
        m = 0
        for k in range(n_act):
            i = active[k]
            t = t_out[i]
            cx = min(max(math.floor(gox + t * dx[i]), 0), w - 1)
            cy = min(max(math.floor(goy + t * dy[i]), 0), h - 1)
            step = distg[cy, cx] - _JUMP_MARGIN
            if step >= _JUMP_MIN:
                t += step
                if t > t1s[i]:
                    t_out[i] = math.inf
                else:
                    t_out[i] = t
                    active[m] = i
                    m += 1
            else:
                pending[n_pend] = i
                n_pend += 1
        n_act = m
    for k in range(n_pend):
        i = pending[k]
        dxi = dx[i]
        dyi = dy[i]
        inv_dx = 1.0 / dxi if dxi != 0.0 else math.inf
        inv_dy = 1.0 / dyi if dyi != 0.0 else math.inf
        t_out[i] = _walk(gox, goy, dxi, dyi, inv_dx, inv_dy, t_out[i], t1s[i], distg)


#: Bound on the error of :func:`_fast_atan2` (rad); beam windows are widened by it.
