"""The one integrator for every crowd model, with walls as hard constraints.

``v += a·dt`` (or the model's velocity), hard speed cap ``|v| ≤ vmax·vmax_factor``,
``p += v·dt``; then a wall guard: a pedestrian's centre never crosses a wall or obstacle segment
and keeps at least ``clearance`` from it (pushed out along the wall normal, which also removes
the velocity component into the wall, so agents slide along walls). Models' wall forces do the
steering; the guard makes "no agent walks through a wall" hold for every model, including
deliberately odd ones like ``spinny``.

The speed cap holds exactly, after the guard too: ``sqrt(vx² + vy²) ≤ vmax·vmax_factor`` for the
returned velocity of every agent, computed in float64 as written (:func:`cap_speed` re-checks
its own rescaling). A push-out longer than the cap allows (an agent that starts inside a wall's
clearance, or squeezed at a corner) is shortened to the cap along its own direction (a part of
the guarded move): the agent gets its clearance back over the next steps, at its walking speed,
instead of jumping.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.walls import WallIndex

FloatArray = NDArray[np.float64]


WallGuard = tuple[Any, ...]
"""The kernel's wall-guard arguments, fixed for an episode (:func:`wall_guard`)."""


def wall_guard(
    walls: WallIndex,
    clearance_map: FloatArray,
    grid_origin: tuple[float, float],
    resolution: float,
) -> WallGuard:
    """The arguments :func:`integrate_guarded` passes for the walls, gathered once.

    Args:
        walls: the static segments (indexed).
        clearance_map: ``(H, W)`` distance (m) from each cell centre to the nearest wall,
            obstacle or map edge, minus half a cell (:func:`arena.maps.distance.clearance_map`);
            agents clearly farther from every wall than their step skip the exact test.
        grid_origin: ``(x, y)`` of the map's lower-left corner (m).
        resolution: cell size (m).

    Returns:
        An opaque tuple; a caller that steps one episode keeps it instead of regathering its
        dozen attributes every step.
    """
    cl = walls._cells
    return (
        clearance_map,
        float(grid_origin[0]),
        float(grid_origin[1]),
        float(resolution),
        walls.a,
        walls.b,
        cl.points,
        cl.order,
        cl.starts,
        float(cl.origin[0]),
        float(cl.origin[1]),
        float(cl.cell),
        int(cl.shape[0]),
        int(cl.shape[1]),
        float(walls.half),
    )


def integrate(
    walls: WallIndex,
    clearance_map: FloatArray,
    grid_origin: tuple[float, float],
    resolution: float,
    positions: FloatArray,
    velocities: FloatArray,
    update: FloatArray,
    update_is_velocity: bool,
    active: NDArray[np.bool_],
    vmax: FloatArray,
    clearance: FloatArray,
    dt: float,
    *,
    vmax_factor: FloatArray | None = None,
    clearance_scale: float = 1.0,
) -> tuple[FloatArray, FloatArray]:
    """One compiled step for all agents: velocity update, speed cap, move, wall guard.

    Args:
        walls: the static segments (indexed).
        clearance_map: ``(H, W)`` (see :func:`wall_guard`).
        grid_origin: ``(x, y)`` of the map's lower-left corner (m).
        resolution: cell size (m).
        positions: ``(n, 2)`` m.
        velocities: ``(n, 2)`` m/s before the step.
        update: ``(n, 2)`` accelerations (m/s²), or new velocities when ``update_is_velocity``.
        update_is_velocity: the model returned velocities (ORCA) rather than accelerations.
        active: ``(n,)`` agents that may move; the others stop.
        vmax: ``(n,)`` speed caps (m/s).
        clearance: ``(n,)`` minimum centre-to-wall distance (m).
        dt: s.
        vmax_factor: ``(n,)`` optional factors on ``vmax`` (the cap is ``vmax · vmax_factor``,
            formed in the kernel: the same bits as multiplying first).
        clearance_scale: factor on ``clearance`` (likewise).

    Returns:
        ``(positions, velocities)`` after the step; the velocity is the displacement over ``dt``
        (so sliding along a wall is what the next step starts from).
    """
    return integrate_guarded(
        wall_guard(walls, clearance_map, grid_origin, resolution),
        positions,
        velocities,
        update,
        update_is_velocity,
        active,
        vmax,
        clearance,
        dt,
        vmax_factor=vmax_factor,
        clearance_scale=clearance_scale,
    )


def integrate_guarded(
    guard: WallGuard,
    positions: FloatArray,
    velocities: FloatArray,
    update: FloatArray,
    update_is_velocity: bool,
    active: NDArray[np.bool_],
    vmax: FloatArray,
    clearance: FloatArray,
    dt: float,
    *,
    vmax_factor: FloatArray | None = None,
    clearance_scale: float = 1.0,
) -> tuple[FloatArray, FloatArray]:
    """:func:`integrate` with the walls gathered beforehand by :func:`wall_guard`."""
    pos = np.ascontiguousarray(positions, dtype=np.float64)
    vel = np.ascontiguousarray(velocities, dtype=np.float64)
    # Outputs allocated here: a numba function's returned arrays cost more to box than this.
    new_p, new_v = np.empty_like(pos), np.empty_like(vel)
    _integrate(
        pos,
        vel,
        np.ascontiguousarray(update, dtype=np.float64),
        update_is_velocity,
        np.ascontiguousarray(active),
        np.ascontiguousarray(vmax, dtype=np.float64),
        np.ascontiguousarray(vmax if vmax_factor is None else vmax_factor, dtype=np.float64),
        vmax_factor is not None,
        np.ascontiguousarray(clearance, dtype=np.float64),
        float(clearance_scale),
        float(dt),
        new_p,
        new_v,
        *guard,
    )
    return new_p, new_v


@njit(cache=True)
def _integrate(
    pos: FloatArray,
    vel: FloatArray,
    update: FloatArray,
    is_velocity: bool,
    active: NDArray[np.bool_],
    vmax: FloatArray,
    vmax_factor: FloatArray,
    has_factor: bool,
    clearance: FloatArray,
    clearance_scale: float,
    dt: float,
    new_p: FloatArray,
    new_v: FloatArray,
    cmap: FloatArray,
    gox: float,
    goy: float,
    res: float,
    wa: FloatArray,
    wb: FloatArray,
    mids: FloatArray,
    order: NDArray[np.int64],
    starts: NDArray[np.int64],
    cox: float,
    coy: float,
    cell: float,
    nx: int,
    ny: int,
    half: float,
) -> None:
    """:func:`integrate_guarded`'s step, written into ``new_p`` and ``new_v``.

    Every row of the ``(n, 2)`` outputs (positions m, velocities m/s) is written.
    """
    n = pos.shape[0]
    h, w = cmap.shape
    cand = np.empty(max(wa.shape[0], 1), dtype=np.int64)
    for i in range(n):
        if not active[i]:
            new_p[i, 0], new_p[i, 1] = pos[i, 0], pos[i, 1]
            new_v[i, 0], new_v[i, 1] = 0.0, 0.0
            continue
        if is_velocity:
            vx, vy = update[i, 0], update[i, 1]
        else:
            vx, vy = vel[i, 0] + update[i, 0] * dt, vel[i, 1] + update[i, 1] * dt
        cap = vmax[i] * vmax_factor[i] if has_factor else vmax[i]
        vx, vy = cap_speed(vx, vy, cap)
        sp = math.sqrt(vx * vx + vy * vy)
        x0, y0 = pos[i, 0], pos[i, 1]
        x1, y1 = x0 + vx * dt, y0 + vy * dt
        step = sp * dt
        clear = clearance_scale * clearance[i]
        # Fast path: clearly far from every wall (a point of the cell lies within half a
        # diagonal of its centre; the map is centre-to-edge already).
        col = int((x0 - gox) // res)
        row = int((y0 - goy) // res)
        bound = 0.0
        if 0 <= row < h and 0 <= col < w:
            bound = cmap[row, col] - 0.75 * res
        if bound > step + clear or wa.shape[0] == 0:
            new_p[i, 0], new_p[i, 1] = x1, y1
            new_v[i, 0], new_v[i, 1] = vx, vy
            continue
        # Exact test against the wall pieces near the move.
        mx, my = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        reach = 0.5 * step + clear + half + 1e-9
        rings = max(1, math.ceil(reach / cell))
        ccx = int((mx - cox) // cell)
        ccy = int((my - coy) // cell)
        m = 0
        r2 = reach * reach
        for gy in range(max(ccy - rings, 0), min(ccy + rings, ny - 1) + 1):
            for gx in range(max(ccx - rings, 0), min(ccx + rings, nx - 1) + 1):
                c = gy * nx + gx
                for s in range(starts[c], starts[c + 1]):
                    j = order[s]
                    if (mids[j, 0] - mx) ** 2 + (mids[j, 1] - my) ** 2 < r2:
                        cand[m] = j
                        m += 1
        qx, qy = _guard_one(x0, y0, x1, y1, clear, wa, wb, cand, 0, m)
        ux, uy = (qx - x0) / dt, (qy - y0) / dt
        if math.sqrt(ux * ux + uy * uy) > cap:
            # The push-out made the move longer than the cap: the first part of it, at the cap.
            ux, uy = cap_speed(ux, uy, cap)
            qx, qy = x0 + ux * dt, y0 + uy * dt
        new_p[i, 0], new_p[i, 1] = qx, qy
        new_v[i, 0], new_v[i, 1] = ux, uy


@njit(cache=True, inline="always")
def cap_speed(vx: float, vy: float, cap: float) -> tuple[float, float]:
    """``(vx, vy)`` scaled down to ``sqrt(vx² + vy²) ≤ cap`` exactly (m/s; ``cap ≥ 0``).

    The rescaled vector's norm, rounded, can exceed ``cap`` by an ulp; it is shrunk by a few
    ulps more until the check, computed the same way, holds. Vectors within the cap (and NaN)
    are returned unchanged.
    """
    sp = math.sqrt(vx * vx + vy * vy)
    if not sp > cap:
        return vx, vy
    k = cap / sp
    vx, vy = vx * k, vy * k
    while math.sqrt(vx * vx + vy * vy) > cap:
        vx, vy = vx * (1.0 - 2e-16), vy * (1.0 - 2e-16)
    return vx, vy


def guard_walls(
    walls: WallIndex,
    p0: FloatArray,
    p1: FloatArray,
    clearance: FloatArray,
    wall_distance: FloatArray | None = None,
) -> FloatArray:
    """Move proposed positions ``p1`` so no agent crosses a wall or comes closer than ``clearance``.

    Args:
        walls: the static segments.
        p0: ``(n, 2)`` positions before the step.
        p1: ``(n, 2)`` proposed positions.
        clearance: ``(n,)`` minimum centre-to-wall distance (m).
        wall_distance: ``(n,)`` optional lower bounds on each agent's distance to every wall
            (e.g. from a distance map); agents whose bound exceeds their step plus clearance
            skip the exact test. An optimisation only: it never changes the result.

    Returns:
        ``(n, 2)`` corrected positions.
    """
    if len(walls) == 0 or p0.shape[0] == 0:
        return p1
    step = np.hypot(p1[:, 0] - p0[:, 0], p1[:, 1] - p0[:, 1])
    if wall_distance is not None:
        far = wall_distance > step + clearance
        if far.all():
            return p1
        near = np.flatnonzero(~far)
        out = p1.copy()
        out[near] = guard_walls(walls, p0[near], p1[near], clearance[near])
        return out
    mid = 0.5 * (p0 + p1)
    reach = float(np.max(0.5 * step + clearance)) + 1e-9
    cand = walls.query(mid, reach)
    guarded: FloatArray = _guard(
        np.ascontiguousarray(p0),
        np.ascontiguousarray(p1),
        np.ascontiguousarray(clearance),
        walls.a,
        walls.b,
        cand.indptr,
        cand.indices,
    )
    return guarded


@njit(cache=True)
def _guard(
    p0: FloatArray,
    p1: FloatArray,
    clearance: FloatArray,
    a: FloatArray,
    b: FloatArray,
    indptr: NDArray[np.int64],
    indices: NDArray[np.int64],
) -> FloatArray:
    out = p1.copy()
    for i in range(p0.shape[0]):
        x0, y0, x1, y1 = p0[i, 0], p0[i, 1], p1[i, 0], p1[i, 1]
        lo, hi = indptr[i], indptr[i + 1]
        out[i, 0], out[i, 1] = _guard_one(x0, y0, x1, y1, clearance[i], a, b, indices, lo, hi)
    return out


@njit(cache=True)
def _guard_one(
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    c: float,
    a: FloatArray,
    b: FloatArray,
    indices: NDArray[np.int64],
    lo: int,
    hi: int,
) -> tuple[float, float]:
    """The guarded end point of one move ``(x0, y0) → (x1, y1)`` (m).

    Against the segments ``a[j] → b[j]`` for ``j`` in ``indices[lo:hi]``, keeping clearance
    ``c`` (m). Returns ``(x, y)``.
    """
    # 1. Stop short of the first wall the move would cross.
    dx, dy = x1 - x0, y1 - y0
    t_hit = 1.0
    for k in range(lo, hi):
        j = indices[k]
        ex, ey = b[j, 0] - a[j, 0], b[j, 1] - a[j, 1]
        den = dx * ey - dy * ex
        if abs(den) < 1e-15:
            continue
        wx, wy = a[j, 0] - x0, a[j, 1] - y0
        t = (wx * ey - wy * ex) / den
        u = (wx * dy - wy * dx) / den
        if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0 and t < t_hit:
            t_hit = t
    if t_hit < 1.0:
        t_hit = max(t_hit - 1e-3, 0.0)
        x1, y1 = x0 + t_hit * dx, y0 + t_hit * dy
    # 2. Keep the clearance: push out along the normal of every wall that is too close.
    for _ in range(3):  # corners need more than one push; three settle every case tested
        moved = False
        for k in range(lo, hi):
            j = indices[k]
            ax, ay = a[j, 0], a[j, 1]
            ex, ey = b[j, 0] - ax, b[j, 1] - ay
            ee = ex * ex + ey * ey
            t = ((x1 - ax) * ex + (y1 - ay) * ey) / ee if ee > 0.0 else 0.0
            t = min(max(t, 0.0), 1.0)
            cx, cy = ax + t * ex, ay + t * ey
            nx, ny = x1 - cx, y1 - cy
            d = math.sqrt(nx * nx + ny * ny)
            if d >= c:
                continue
            if d < 1e-12:
                # On the wall line: push toward the side the agent came from.
                nx, ny = -ey, ex
                if (x0 - ax) * nx + (y0 - ay) * ny < 0.0:
                    nx, ny = -nx, -ny
                d = 0.0
                norm = math.sqrt(nx * nx + ny * ny)
                nx, ny = nx / norm, ny / norm
            else:
                nx, ny = nx / d, ny / d
            x1 += nx * (c - d)
            y1 += ny * (c - d)
            moved = True
        if not moved:
            break
    return x1, y1
