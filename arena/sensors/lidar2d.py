"""Fast vectorised 2-D lidar: exact grid casting plus analytic circles and segments.

A :class:`Lidar2D` is built once per :class:`~arena.sensors.spec.LidarSpec`, bound to the static
world of an episode (:meth:`Lidar2D.bind`) and then asked for scans of one robot
(:meth:`Lidar2D.scan`) or of several robots sharing the spec (:meth:`Lidar2D.scan_many`). All the
work happens in numba kernels; Python only validates inputs and draws the noise.

What a beam hits
----------------
A beam is the half-line ``o + t·d`` (``t ≥ 0``, metres) from the sensor origin
``o = pose ⊕ spec.mount``. Its range is the smallest ``t`` at which it touches

* a **blocking grid cell**, taken as a *closed* square in grid coordinates
  ``g = (p − grid.origin) / resolution``. A beam that touches a blocking cell, even only along an
  edge or at a single corner point, stops there. Hence two diagonally touching blocking cells
  stop a beam that passes exactly through their shared corner (no leak through zero-width
  gaps), a beam grazing a wall's convex corner stops at that corner, and a beam running exactly
  along a grid line stops where it first touches a blocking cell on either side of the line.
  "Exactly" is decided with a tolerance of :data:`CORNER_EPS` cells so that rounding in the beam
  direction cannot open a gap. Beam directions within 1e-12 of an axis are snapped onto it.
  Off the map there are no walls: beams leave the map and may still hit circles and segments.
* a **circle** (pedestrians, circular robots), taken as a solid disc: the nearest root of
  ``|o + t·d − c| = r``. A sensor origin inside or on a circle therefore hits it at ``t = 0``
  with *every* beam, which reports ``range_min`` (the sensor is covered).
* a **segment** (static obstacle edges from :meth:`bind`, dynamic ones per scan such as other
  robots' footprints), taken as a thin wall visible from both sides. An origin lying exactly on
  a segment hits it at ``t = 0`` with every beam.

Ranges are then clipped: no hit before ``range_max`` reports ``range_max``; a hit nearer than
``range_min`` reports ``range_min``. A sensor origin that touches a blocking cell (inside it or
on its boundary) reports ``range_min`` on every beam.

Grid casting
------------
Each beam walks the grid with the Amanatides–Woo cell traversal (DDA), so the reported hit is the
exact parameter at which the beam enters its first blocking cell (no sampling error). Open space
is crossed with sphere tracing on the map's Euclidean distance transform: from a point inside
cell ``c`` no blocking square is closer than ``distance[c] − √2·res`` (see :func:`_walk`),
so the beam jumps that far (less a safety margin) whenever the jump is worth it.

Wall faces
----------
Most maps have few walls: the boundary of their blocking cells merges into a few hundred
axis-aligned *faces* (:func:`wall_faces`; small_office: 88). For such a map each beam is instead
intersected with the faces that look toward the sensor and lie in the beam's angular window
(the way obstacle segments are cast), which is several times cheaper than walking the grid. A
beam starting outside the blocking squares first touches their union on its boundary, so the
first front face it meets (closed at its ends, widened by :data:`CORNER_EPS`) is where the walk
would stop; the hit parameter is computed with the walk's formula
(``(line − origin) · (1 / d)``), so both paths give the same ranges. Maps whose faces outnumber
:data:`FACES_PER_BEAM` per beam (noisy scanned maps) keep the grid walk.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import SimulationError
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import GridMemo
from arena.sensors.spec import LidarSpec

FloatArray = NDArray[np.float64]

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
# Directions closer than this to an axis are snapped onto it (1e-12 rad ≈ 3e-11 m at 30 m), so
# that beams meant to be axis-aligned (yaw 90° gives cos = 6e-17) traverse the grid exactly.
_AXIS_SNAP = 1e-12
_TWO_PI = 2.0 * math.pi
#: A map's walls are cast as faces (:func:`wall_faces`) while it has at most this many faces per
#: beam; beyond that the per-face set-up costs more than walking the grid.
FACES_PER_BEAM = 2.0


# ------------------------------------------------------------------------------------------------
# numba kernels
# ------------------------------------------------------------------------------------------------
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
ATAN_ERR = 1e-5


@njit(cache=True, fastmath=False)
def _fast_atan2(y: float, x: float) -> float:
    """``atan2(y, x)`` to within :data:`ATAN_ERR` (max error 1.8e-6 rad), a few times faster.

    Only used to choose candidate beams, never for a range: a near-minimax odd polynomial of
    degree 11 for ``atan`` on [0, 1], then octant symmetry.
    """
    ax = abs(x)
    ay = abs(y)
    mx = max(ax, ay)
    if mx == 0.0:
        return 0.0
    a = min(ax, ay) / mx
    s = a * a
    r = -0.01174029132  # Horner scheme in s = a²
    r = r * s + 0.05272228881
    r = r * s - 0.1165246652
    r = r * s + 0.1935984833
    r = r * s - 0.3326377265
    r = (r * s + 0.9999784356) * a
    if ay > ax:
        r = 0.5 * math.pi - r
    if x < 0.0:
        r = math.pi - r
    return -r if y < 0.0 else r


@njit(cache=True, fastmath=False)
def _beam_window(
    phi: float, width: float, a0: float, inc: float, n: int
) -> tuple[int, int, int, int]:
    """Beam indices whose direction may lie in the arc ``[phi, phi + width]`` (rad).

    Beam ``i`` points at ``a0 + i·inc``. The arc is taken modulo 2π, so it may wrap past the
    first beam; the result is two inclusive index ranges ``[i0, i1]`` and ``[j0, j1]`` (possibly
    empty), widened by :data:`ATAN_ERR` and then by one beam each side, so that approximate
    angles and rounding can only add candidates, never drop them.
    """
    if inc <= 0.0 or width >= math.pi:
        return 0, n - 1, 1, 0
    phi -= ATAN_ERR
    width += 2.0 * ATAN_ERR
    rel = phi - a0
    rel -= _TWO_PI * math.floor(rel / _TWO_PI)
    i0 = max(math.floor(rel / inc) - 1, 0)
    i1 = min(math.ceil((rel + width) / inc) + 1, n - 1)
    j0 = max(math.floor((rel - _TWO_PI) / inc) - 1, 0)
    j1 = min(math.ceil((rel + width - _TWO_PI) / inc) + 1, n - 1)
    return i0, i1, j0, j1


@njit(cache=True, fastmath=False)
def _circle_hit(
    best: NDArray[np.float64], i: int, dx: NDArray[np.float64], dy: NDArray[np.float64],
    ccx: float, ccy: float, c2: float,
) -> None:
    """Lower ``best[i]`` to beam ``i``'s hit on a circle seen from outside.

    ``(ccx, ccy)`` is the centre relative to the origin and ``c2 = |c|² − r² > 0``. The near root
    ``b − √(b² − c2)`` is evaluated as ``c2 / (b + √(b² − c2))`` to avoid cancellation.
    """
    b = dx[i] * ccx + dy[i] * ccy
    if b <= 0.0:
        return
    disc = b * b - c2
    if disc < 0.0:
        return
    t = c2 / (b + math.sqrt(disc))
    if t < best[i]:
        best[i] = t


@njit(cache=True, fastmath=False)
def _segment_hit(
    best: NDArray[np.float64], i: int, dx: NDArray[np.float64], dy: NDArray[np.float64],
    ax: float, ay: float, ex: float, ey: float,
) -> None:
    """Lower ``best[i]`` to beam ``i``'s hit on the segment ``a + u·e``, ``u ∈ [0, 1]``.

    ``a`` is relative to the origin. Solving ``t·d − u·e = a`` by cross products gives
    ``t = (a × e)/(d × e)`` and ``u = (a × d)/(d × e)``; the range tests are done on the
    numerators (sign-normalised) so that only actual hits pay for a division. A collinear beam
    hits the nearer end (or ``t = 0`` when the origin lies on the segment).
    """
    ddx = dx[i]
    ddy = dy[i]
    den = ddx * ey - ddy * ex
    if den != 0.0:
        num_t = ax * ey - ay * ex
        num_u = ax * ddy - ay * ddx
        if den < 0.0:
            den, num_t, num_u = -den, -num_t, -num_u
        if num_t >= 0.0 and 0.0 <= num_u <= den:
            t = num_t / den
            if t < best[i]:
                best[i] = t
        return
    if ax * ddy - ay * ddx != 0.0:
        return  # parallel, not collinear
    ta = ax * ddx + ay * ddy
    tb = (ax + ex) * ddx + (ay + ey) * ddy
    if ta < 0.0 and tb < 0.0:
        return
    t = 0.0 if (ta < 0.0 or tb < 0.0) else min(ta, tb)
    if t < best[i]:
        best[i] = t


@njit(cache=True, fastmath=False)
def _segments_into(
    best: NDArray[np.float64], dx: NDArray[np.float64], dy: NDArray[np.float64],
    ox: float, oy: float, a0: float, inc: float, range_max: float,
    seg_a: NDArray[np.float64], seg_b: NDArray[np.float64], owner: NDArray[np.int64],
    robot: int,
) -> None:
    """Lower ``best`` with the hits on every segment (skipping those owned by ``robot``)."""
    n = best.shape[0]
    # Polygon edges chain (b of one edge is a of the next): reuse that end's direction.
    prev_bx = math.nan
    prev_by = math.nan
    prev_phi = 0.0
    for k in range(seg_a.shape[0]):
        if robot >= 0 and owner[k] == robot:
            continue
        ax = seg_a[k, 0] - ox
        ay = seg_a[k, 1] - oy
        bx = seg_b[k, 0] - ox
        by = seg_b[k, 1] - oy
        ex = bx - ax
        ey = by - ay
        # Bounding-circle prune: the segment lies within half its length of its midpoint.
        mx = 0.5 * (ax + bx)
        my = 0.5 * (ay + by)
        if math.sqrt(mx * mx + my * my) - 0.5 * math.sqrt(ex * ex + ey * ey) > range_max:
            continue
        if ax * by - ay * bx == 0.0 and ax * bx + ay * by <= 0.0:
            best[:] = 0.0  # the origin lies on the segment: every beam starts on it
            continue
        # Beams that can hit it lie in the (< π) arc swept from one end's direction to the other.
        if seg_a[k, 0] == prev_bx and seg_a[k, 1] == prev_by:
            phi_a = prev_phi
        else:
            phi_a = _fast_atan2(ay, ax)
        phi_b = _fast_atan2(by, bx)
        prev_bx = seg_b[k, 0]
        prev_by = seg_b[k, 1]
        prev_phi = phi_b
        dphi = phi_b - phi_a
        dphi -= _TWO_PI * math.floor((dphi + math.pi) / _TWO_PI)  # to [−π, π)
        if abs(dphi) > math.pi - 1e-3:
            # The origin (nearly) lies on the segment: which way it sweeps is ill-conditioned
            # (and the approximate angles could pick the wrong side), so test every beam.
            i0, i1, j0, j1 = 0, n - 1, 1, 0
        elif dphi >= 0.0:
            i0, i1, j0, j1 = _beam_window(phi_a, dphi, a0, inc, n)
        else:
            i0, i1, j0, j1 = _beam_window(phi_a + dphi, -dphi, a0, inc, n)
        for i in range(i0, i1 + 1):
            _segment_hit(best, i, dx, dy, ax, ay, ex, ey)
        for i in range(j0, j1 + 1):
            _segment_hit(best, i, dx, dy, ax, ay, ex, ey)


@njit(cache=True, fastmath=False)
def _cast_faces(
    gox: float, goy: float, dx: NDArray[np.float64], dy: NDArray[np.float64],
    tlim: NDArray[np.float64], faces: NDArray[np.float64], w: int, h: int, a0: float,
    inc: float, t_out: NDArray[np.float64], inv_dx: NDArray[np.float64],
    inv_dy: NDArray[np.float64],
) -> None:
    """First touch of every beam with a wall face, in grid units (see "Wall faces" above).

    The same values as :func:`_cast_grid_many` (``inf`` for no touch), from the faces instead of
    the distance map: each face that looks toward the origin and lies within ``max(tlim)`` is
    intersected with the beams of its angular window.

    Args:
        gox: origin x in grid cells; must not touch a blocking square.
        goy: origin y in grid cells.
        dx: ``(n,)`` unit directions x.
        dy: ``(n,)`` unit directions y.
        tlim: ``(n,)`` per-beam parameter limits (cells); only their maximum culls faces.
        faces: ``(F, 4)`` rows ``[kind, line, lo, hi]`` of :func:`wall_faces`.
        w: map width (cells).
        h: map height (cells).
        a0: direction of beam 0 (rad, world frame).
        inc: angle between beams (rad; 0: test every beam).
        t_out: ``(n,)`` output: hit parameter (cells) or ``inf``.
        inv_dx: ``(n,)`` scratch (``1 / dx``).
        inv_dy: ``(n,)`` scratch (``1 / dy``).
    """
    n = dx.shape[0]
    tmax = 0.0
    for i in range(n):
        t_out[i] = math.inf
        if tlim[i] > tmax:
            tmax = tlim[i]
        # The grid walk's boundary formula is (line − origin) · (1 / d): the same floats here.
        # A beam parallel to a face gets ±inf (or NaN on the face's line), which never hits;
        # the faces across the ends catch a beam running along a face.
        inv_dx[i] = 1.0 / dx[i] if dx[i] != 0.0 else math.inf
        inv_dy[i] = 1.0 / dy[i] if dy[i] != 0.0 else math.inf
    for f in range(faces.shape[0]):
        kind = faces[f, 0]
        line = faces[f, 1]
        lo = faces[f, 2]
        hi = faces[f, 3]
        vertical = kind < 1.5
        # rel: the face line relative to the origin across it; along: the origin along it
        if vertical:
            rel = line - gox
            along = goy
        else:
            rel = line - goy
            along = gox
        # A face is seen from one side only: kinds 0 and 2 from below the line, 1 and 3 above.
        if rel < 0.0 if (kind == 0.0 or kind == 2.0) else rel > 0.0:
            continue
        gap = lo - along if along < lo else (along - hi if along > hi else 0.0)
        if rel * rel + gap * gap > tmax * tmax:
            continue
        if vertical:
            phi_a = _fast_atan2(lo - along, rel)
            phi_b = _fast_atan2(hi - along, rel)
        else:
            phi_a = _fast_atan2(rel, lo - along)
            phi_b = _fast_atan2(rel, hi - along)
        dphi = phi_b - phi_a
        dphi -= _TWO_PI * math.floor((dphi + math.pi) / _TWO_PI)  # to [−π, π)
        if abs(dphi) > math.pi - 1e-3:
            i0, i1, j0, j1 = 0, n - 1, 1, 0  # edge-on through the origin: test every beam
        elif dphi >= 0.0:
            i0, i1, j0, j1 = _beam_window(phi_a, dphi, a0, inc, n)
        else:
            i0, i1, j0, j1 = _beam_window(phi_a + dphi, -dphi, a0, inc, n)
        inv_across = inv_dx if vertical else inv_dy
        d_along = dy if vertical else dx
        # A beam from off the map that touches a wall on the map's edge does so where it enters
        # the map, which the walk computes by division (_clip_to_map): do the same there.
        if line == (0.0 if (kind == 0.0 or kind == 2.0) else (w if vertical else h)):
            d_across = dx if vertical else dy
            for i in range(n):
                if i0 <= i <= i1 or j0 <= i <= j1:
                    _face_hit(t_out, i, rel / d_across[i] if d_across[i] != 0.0 else math.inf,
                              along, d_along, lo, hi)
            continue
        for i in range(i0, i1 + 1):
            _face_hit(t_out, i, rel * inv_across[i], along, d_along, lo, hi)
        for i in range(j0, j1 + 1):
            _face_hit(t_out, i, rel * inv_across[i], along, d_along, lo, hi)


@njit(cache=True, fastmath=False, inline="always")
def _face_hit(
    t_out: NDArray[np.float64], i: int, t: float, along: float, d_along: NDArray[np.float64],
    lo: float, hi: float,
) -> None:
    """Lower ``t_out[i]`` to ``t`` if beam ``i`` meets the face's line at ``t`` within the face.

    The face is closed and widened by :data:`CORNER_EPS` at both ends; one branch so that the
    compiler can keep the loop tight (``t`` may be ±inf or NaN for a parallel beam: no hit).
    """
    u = along + t * d_along[i]
    if t >= 0.0 and t < t_out[i] and u >= lo - CORNER_EPS and u <= hi + CORNER_EPS:
        t_out[i] = t


@njit(cache=True, fastmath=False)
def _scan_kernel(
    poses: NDArray[np.float64], mount: NDArray[np.float64],
    cos_a: NDArray[np.float64], sin_a: NDArray[np.float64], angle_min: float, inc: float,
    range_min: float, range_max: float,
    distg: NDArray[np.float32], res: float, gx0: float, gy0: float,
    circ_xy: NDArray[np.float64], circ_r: NDArray[np.float64], circ_owner: NDArray[np.int64],
    stat_a: NDArray[np.float64], stat_b: NDArray[np.float64], stat_owner: NDArray[np.int64],
    dyn_a: NDArray[np.float64], dyn_b: NDArray[np.float64], dyn_owner: NDArray[np.int64],
    use_owner: bool, faces: NDArray[np.float64], use_faces: bool, out: NDArray[np.float64],
) -> None:
    """Fill ``out`` with the clipped ranges (m) of every robot; see the module docstring.

    Per robot: sensor pose, origin checks, circles and segments (each testing only the beams
    in its angular window), then the grid limited to the nearest hit so far, then clipping.

    Args:
        poses: ``(r, 3)`` robot poses ``[x m, y m, yaw rad]``.
        mount: ``(3,)`` sensor pose in the robot frame.
        cos_a: ``(n,)`` cosines of the beam angles in the sensor frame.
        sin_a: ``(n,)`` sines of the beam angles.
        angle_min: first beam angle (rad, sensor frame).
        inc: angle between beams (rad); 0 disables angular windows (every beam is tested).
        range_min: m.
        range_max: m.
        distg: ``(H, W)`` float32 distance map in cells (0 = blocking).
        res: cell size (m).
        gx0: grid origin x (m).
        gy0: grid origin y (m).
        circ_xy: ``(m, 2)`` circle centres (m).
        circ_r: ``(m,)`` circle radii (m).
        circ_owner: ``(m,)`` robot owning each circle (read only if ``use_owner``).
        stat_a: ``(s, 2)`` static segment starts (m).
        stat_b: ``(s, 2)`` static segment ends (m).
        stat_owner: unused placeholder (static segments belong to nobody).
        dyn_a: ``(k, 2)`` dynamic segment starts (m).
        dyn_b: ``(k, 2)`` dynamic segment ends (m).
        dyn_owner: ``(k,)`` robot owning each dynamic segment (read only if ``use_owner``).
        use_owner: robot ``i`` ignores the circles and dynamic segments owned by ``i``.
        faces: ``(F, 4)`` the map's :func:`wall_faces` (read only if ``use_faces``).
        use_faces: cast the walls as faces instead of walking the grid.
        out: ``(r, n)`` output ranges (m).
    """
    n = cos_a.shape[0]
    dx = np.empty(n)
    dy = np.empty(n)
    tlim = np.empty(n)
    tg = np.empty(n)
    t1s = np.empty(n)
    t2s = np.empty(n)
    active = np.empty(n, dtype=np.int64)
    pending = np.empty(n, dtype=np.int64)
    inv_res = 1.0 / res
    for r in range(poses.shape[0]):
        best = out[r]
        robot = r if use_owner else -1
        # Sensor origin and heading in the world (pose ⊕ mount).
        c = math.cos(poses[r, 2])
        s = math.sin(poses[r, 2])
        ox = poses[r, 0] + c * mount[0] - s * mount[1]
        oy = poses[r, 1] + s * mount[0] + c * mount[1]
        yaw = poses[r, 2] + mount[2]
        if not (math.isfinite(ox) and math.isfinite(oy) and math.isfinite(yaw)):
            # A NaN beam parameter would never pass the exit tests: refuse instead of hanging.
            raise ValueError("Lidar2D: robot poses must be finite")
        cy_ = math.cos(yaw)
        sy_ = math.sin(yaw)
        for i in range(n):
            # Rotating precomputed beam directions is cheaper than n sin/cos per scan.
            ddx = cy_ * cos_a[i] - sy_ * sin_a[i]
            ddy = sy_ * cos_a[i] + cy_ * sin_a[i]
            if abs(ddx) < _AXIS_SNAP:
                ddx, ddy = 0.0, (1.0 if ddy > 0.0 else -1.0)
            elif abs(ddy) < _AXIS_SNAP:
                ddx, ddy = (1.0 if ddx > 0.0 else -1.0), 0.0
            dx[i] = ddx
            dy[i] = ddy
            best[i] = range_max
        a0 = yaw + angle_min

        gox = (ox - gx0) * inv_res
        goy = (oy - gy0) * inv_res
        if _origin_touches_wall(gox, goy, distg):
            best[:] = range_min
            continue

        # -- circles: solid discs, only the beams in each disc's angular window are tested --
        covered = False
        for k in range(circ_xy.shape[0]):
            if robot >= 0 and circ_owner[k] == robot:
                continue
            ccx = circ_xy[k, 0] - ox
            ccy = circ_xy[k, 1] - oy
            rad = circ_r[k]
            d2 = ccx * ccx + ccy * ccy
            c2 = d2 - rad * rad
            if c2 <= 0.0:
                covered = True  # origin inside or on the disc: every beam hits it at t = 0
                break
            dist = math.sqrt(d2)
            if dist - rad > range_max:
                continue
            half = math.asin(min(rad / dist, 1.0))
            i0, i1, j0, j1 = _beam_window(_fast_atan2(ccy, ccx) - half, 2.0 * half, a0, inc, n)
            for i in range(i0, i1 + 1):
                _circle_hit(best, i, dx, dy, ccx, ccy, c2)
            for i in range(j0, j1 + 1):
                _circle_hit(best, i, dx, dy, ccx, ccy, c2)
        if covered:
            best[:] = range_min
            continue

        # -- segments: static obstacle edges, then dynamic ones --
        _segments_into(best, dx, dy, ox, oy, a0, inc, range_max, stat_a, stat_b, stat_owner, -1)
        _segments_into(best, dx, dy, ox, oy, a0, inc, range_max, dyn_a, dyn_b, dyn_owner, robot)

        # -- grid, limited to the nearest hit found so far --
        for i in range(n):
            tlim[i] = best[i] * inv_res
        if use_faces:
            _cast_faces(
                gox, goy, dx, dy, tlim, faces, distg.shape[1], distg.shape[0], a0, inc, tg,
                t1s, t2s,
            )
        else:
            _cast_grid_many(gox, goy, dx, dy, tlim, distg, tg, t1s, active, pending)
        for i in range(n):
            if tg[i] * res < best[i]:
                best[i] = tg[i] * res
            if best[i] < range_min:
                best[i] = range_min
            elif best[i] > range_max:
                best[i] = range_max


@njit(cache=True, fastmath=False)
def _add_noise(
    out: NDArray[np.float64], z: NDArray[np.float64], sigma: float, range_min: float,
    range_max: float,
) -> None:
    """Add ``sigma·z`` to the hits in ``out`` (not to max-range returns) and clip, in place."""
    flat = out.reshape(-1)
    zf = z.reshape(-1)
    for i in range(flat.shape[0]):
        r = flat[i]
        if r < range_max:
            flat[i] = min(max(r + sigma * zf[i], range_min), range_max)


# ------------------------------------------------------------------------------------------------
# Python API
# ------------------------------------------------------------------------------------------------
# Shared empty inputs. They stay writeable on purpose: numba compiles a separate specialisation
# for read-only arrays, so every array handed to the kernel is writeable (the kernel never
# writes any input).
_EMPTY_PTS = np.zeros((0, 2))
_EMPTY_R = np.zeros(0)
_EMPTY_OWNER = np.zeros(0, dtype=np.int64)


def _c_array(x: ArrayLike, dtype: type) -> NDArray:
    """C-contiguous, writeable array of ``dtype``: a view of ``x`` when possible, else a copy."""
    a = np.ascontiguousarray(x, dtype=dtype)
    return a if a.flags.writeable else a.copy()


def _points(x: ArrayLike | None, name: str) -> FloatArray:
    """``(k, 2)`` float64 C array (a view where possible, never modified)."""
    if x is None:
        return _EMPTY_PTS
    a = _c_array(x, np.float64)
    if a.size == 0:
        return _EMPTY_PTS
    if a.ndim != 2 or a.shape[1] != 2:
        raise ValueError(f"{name} must have shape (k, 2), got {a.shape}")
    return a


def _owners(x: ArrayLike | None, k: int, name: str) -> NDArray[np.int64]:
    """``(k,)`` int64 owner indices (``-1`` = nobody) or the all-nobody default."""
    if x is None:
        return np.full(k, -1, dtype=np.int64) if k else _EMPTY_OWNER
    a = _c_array(x, np.int64)
    if a.shape != (k,):
        raise ValueError(f"{name} must have shape ({k},), got {a.shape}")
    return a


def _runs(mask: NDArray[np.bool_]) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.intp]]:
    """Runs of ``True`` along each row of ``mask``: (row, first column, last column + 1)."""
    pad = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    pad[:, 1:-1] = mask
    step = np.diff(pad, axis=1)
    rows, first = np.nonzero(step == 1)
    _, end = np.nonzero(step == -1)  # row-major order: the n-th end closes the n-th run
    return rows, first, end


def _compute_faces(blocked: NDArray[np.bool_]) -> FloatArray:
    h, w = blocked.shape
    side = np.zeros((h, w + 2), dtype=bool)
    side[:, 1:-1] = blocked
    left, right = side[:, :-1], side[:, 1:]  # the cells left/right of vertical line x = 0..W
    vert = np.zeros((h + 2, w), dtype=bool)
    vert[1:-1] = blocked
    below, above = vert[:-1], vert[1:]  # the cells below/above horizontal line y = 0..H
    parts = []
    for kind, mask in (
        (0, (right & ~left).T), (1, (left & ~right).T),  # (W+1, H): runs along y
        (2, above & ~below), (3, below & ~above),        # (H+1, W): runs along x
    ):
        line, lo, hi = _runs(mask)
        parts.append(np.stack([np.full(len(line), kind), line, lo, hi], axis=1))
    faces = np.ascontiguousarray(np.concatenate(parts).astype(np.float64))
    faces.setflags(write=False)
    return faces


_FACES = GridMemo(64)


def wall_faces(grid: OccupancyGrid) -> FloatArray:
    """The boundary of ``grid``'s blocking cells as merged axis-aligned faces, in grid cells.

    Every unit edge between a blocking cell and a free one (cells off the map are free) belongs
    to exactly one face; collinear edges facing the same way merge into one face. Computed once
    per grid object.

    Returns:
        ``(F, 4)`` read-only float64 rows ``[kind, line, lo, hi]``: kind 0 and 1 are vertical
        faces on the grid line ``x = line`` spanning ``y ∈ [lo, hi]``, seen from ``x < line``
        (kind 0, the blocking cell to the right) or from ``x > line`` (kind 1); kinds 2 and 3 are
        horizontal faces on ``y = line`` spanning ``x ∈ [lo, hi]``, seen from ``y < line``
        (kind 2) or ``y > line`` (kind 3). Grid coordinates: ``(p − origin) / resolution``.
    """
    return _FACES.get(grid, "wall_faces", lambda: _compute_faces(np.asarray(grid.occupied)))


def use_wall_faces(faces: NDArray[np.float64], num_beams: int) -> bool:
    """Whether a map with ``faces`` is cheaper to cast face by face (:data:`FACES_PER_BEAM`)."""
    return len(faces) <= FACES_PER_BEAM * max(num_beams, 64)


class Lidar2D:
    """A planar laser scanner of one :class:`LidarSpec`, cast against one static world at a time.

    Usage: ``lidar = Lidar2D(spec)``; per episode ``lidar.bind(world.grid, world.segments_a,
    world.segments_b)``; per step ``ranges = lidar.scan(pose, agent_xy, agent_r)``. The numba
    kernels are compiled (or loaded from the on-disk cache) in the constructor.

    See the module docstring for exactly what a beam hits (closed grid cells, solid circles,
    two-sided segments) and how ranges are clipped.

    Args:
        spec: the scanner's specification (beams, ranges, noise, mount pose).
    """

    def __init__(self, spec: LidarSpec) -> None:
        self.spec = spec
        angles = spec.angles()
        angles.setflags(write=False)
        self._angles = angles
        self._cos = np.cos(angles)
        self._sin = np.sin(angles)
        # One beam (or a zero span) has no meaningful increment: the kernel then tests every beam.
        self._inc = float(spec.angle_increment) if spec.num_beams > 1 else 0.0
        self._mount = np.asarray(spec.mount, dtype=np.float64)
        self._grid: OccupancyGrid | None = None
        self._distg = np.zeros((1, 1), dtype=np.float32)
        self._faces = np.zeros((0, 4))
        self._use_faces = False
        self._seg_a = _EMPTY_PTS
        self._seg_b = _EMPTY_PTS
        self._warm_up()

    # -- set-up ------------------------------------------------------------------------------------
    @property
    def angles(self) -> FloatArray:
        """Beam angles in the sensor frame, ``(num_beams,)`` (rad, read-only)."""
        return self._angles

    @property
    def grid(self) -> OccupancyGrid | None:
        """The grid bound by :meth:`bind`, or ``None`` before the first bind."""
        return self._grid

    def bind(
        self, grid: OccupancyGrid, segments_a: ArrayLike | None = None,
        segments_b: ArrayLike | None = None,
    ) -> None:
        """Attach the static world of an episode.

        Args:
            grid: the occupancy grid; its blocking cells are walls. Its distance transform is
                computed (once per grid object, cached by the grid) and converted to cells.
            segments_a: ``(s, 2)`` start points of static obstacle edges (m), or ``None``.
            segments_b: ``(s, 2)`` end points (m), or ``None``.
        """
        a = _points(segments_a, "segments_a").copy()
        b = _points(segments_b, "segments_b").copy()
        if a.shape != b.shape:
            raise ValueError(f"segments_a {a.shape} and segments_b {b.shape} differ in shape")
        if self._grid is not grid:
            # Distances in cells, float32 to halve cache traffic; capped so that an empty map's
            # ``inf`` becomes one jump out of the map instead of an ``inf`` beam parameter.
            cap = float(grid.width + grid.height + 4)
            d = np.minimum(np.asarray(grid.distance) / grid.resolution, cap)
            self._distg = np.ascontiguousarray(d, dtype=np.float32)
            # a writeable copy: numba compiles another specialisation for read-only arrays
            self._faces = wall_faces(grid).copy()
            self._use_faces = use_wall_faces(self._faces, self.spec.num_beams)
            self._grid = grid
        self._seg_a, self._seg_b = a, b

    # -- scanning ----------------------------------------------------------------------------------
    def scan(
        self,
        pose: ArrayLike,
        circles_xy: ArrayLike | None = None,
        circles_r: ArrayLike | None = None,
        segments_a: ArrayLike | None = None,
        segments_b: ArrayLike | None = None,
        rng: np.random.Generator | None = None,
    ) -> FloatArray:
        """One scan from a robot at ``pose``.

        Args:
            pose: ``(3,)`` robot pose ``[x m, y m, yaw rad]``; the sensor sits at ``pose ⊕ mount``.
            circles_xy: ``(m, 2)`` centres of solid circles (pedestrians, round robots) (m).
            circles_r: ``(m,)`` their radii (m).
            segments_a: ``(k, 2)`` start points of extra dynamic segments (m), e.g. the edges of
                other robots' footprints; the robot's own footprint must not be included.
            segments_b: ``(k, 2)`` their end points (m).
            rng: source of range noise; without one (or with ``noise_std == 0``) the scan is
                deterministic.

        Returns:
            ``(num_beams,)`` float64 ranges (m) measured from the sensor origin.
        """
        p = np.asarray(pose, dtype=np.float64)
        if p.shape != (3,):
            raise ValueError(f"pose must have shape (3,), got {p.shape}")
        return self.scan_many(p[None], circles_xy, circles_r, segments_a, segments_b, rng)[0]

    def scan_many(
        self,
        poses: ArrayLike,
        circles_xy: ArrayLike | None = None,
        circles_r: ArrayLike | None = None,
        segments_a: ArrayLike | None = None,
        segments_b: ArrayLike | None = None,
        rng: np.random.Generator | None = None,
        *,
        circles_owner: ArrayLike | None = None,
        segments_owner: ArrayLike | None = None,
    ) -> FloatArray:
        """Scans of several robots carrying this spec, in one kernel call.

        All robots see the same circles and dynamic segments, except those whose owner index
        names the scanning robot itself (so the circles and footprint edges of every robot can be
        passed once). Without owners, ``scan_many(poses, ...)[i] == scan(poses[i], ...)``.

        Args:
            poses: ``(r, 3)`` robot poses ``[x m, y m, yaw rad]``.
            circles_xy: ``(m, 2)`` circle centres (m).
            circles_r: ``(m,)`` circle radii (m).
            segments_a: ``(k, 2)`` dynamic segment start points (m).
            segments_b: ``(k, 2)`` dynamic segment end points (m).
            rng: noise source, as in :meth:`scan`; one ``(r, num_beams)`` normal draw per call.
            circles_owner: ``(m,)`` int, the robot index (row of ``poses``) each circle belongs
                to and is invisible to, or ``-1``.
            segments_owner: ``(k,)`` int, the same for the dynamic segments.

        Returns:
            ``(r, num_beams)`` float64 ranges (m).
        """
        if self._grid is None:
            raise SimulationError("Lidar2D.bind(grid, ...) must be called before scanning")
        q = _c_array(poses, np.float64)
        if q.ndim != 2 or q.shape[1] != 3:
            raise ValueError(f"poses must have shape (r, 3), got {q.shape}")
        cxy = _points(circles_xy, "circles_xy")
        cr = _EMPTY_R if circles_r is None else _c_array(circles_r, np.float64)
        if cr.size == 0:
            cr = _EMPTY_R
        if cr.shape != (len(cxy),):
            raise ValueError(f"circles_r must have shape ({len(cxy)},), got {cr.shape}")
        da = _points(segments_a, "segments_a")
        db = _points(segments_b, "segments_b")
        if da.shape != db.shape:
            raise ValueError(f"segments_a {da.shape} and segments_b {db.shape} differ in shape")
        use_owner = circles_owner is not None or segments_owner is not None
        if use_owner:
            c_own = _owners(circles_owner, len(cxy), "circles_owner")
            d_own = _owners(segments_owner, len(da), "segments_owner")
        else:
            c_own = d_own = _EMPTY_OWNER  # never read without owners

        spec = self.spec
        grid = self._grid
        out = np.empty((q.shape[0], spec.num_beams))
        _scan_kernel(
            q, self._mount, self._cos, self._sin, spec.angle_min, self._inc,
            spec.range_min, spec.range_max,
            self._distg, grid.resolution, grid.origin[0], grid.origin[1],
            cxy, cr, c_own, self._seg_a, self._seg_b, _EMPTY_OWNER, da, db, d_own,
            use_owner, self._faces, self._use_faces, out,
        )
        if rng is not None and spec.noise_std > 0.0:
            # Draw for every beam (hit or not) so the stream advances the same way every scan.
            z = rng.standard_normal(out.shape)
            _add_noise(out, z, spec.noise_std, spec.range_min, spec.range_max)
        return out

    # -- internals ---------------------------------------------------------------------------------
    def _warm_up(self) -> None:
        """Compile (or load from cache) the kernels with the exact argument types used later."""
        grid, distg, faces, use = self._grid, self._distg, self._faces, self._use_faces
        a, b = self._seg_a, self._seg_b
        self._grid = OccupancyGrid.empty(0.5, 0.5, 0.1)
        self._distg = np.zeros((5, 5), dtype=np.float32)
        self._distg[1:4, 1:4] = 1.0
        self._faces = _compute_faces(self._distg == 0.0).copy()
        self._seg_a = np.array([[0.1, 0.35]])
        self._seg_b = np.array([[0.2, 0.35]])
        try:
            for self._use_faces in (False, True):
                self.scan_many(
                    np.array([[0.25, 0.25, 0.0]]), np.array([[0.3, 0.2]]), np.array([0.02]),
                    np.array([[0.1, 0.15]]), np.array([[0.2, 0.15]]),
                    circles_owner=np.array([-1]),
                )
            _add_noise(np.zeros((1, 1)), np.zeros((1, 1)), 0.0, 0.0, 1.0)
        finally:
            self._grid, self._distg, self._faces, self._use_faces = grid, distg, faces, use
            self._seg_a, self._seg_b = a, b
