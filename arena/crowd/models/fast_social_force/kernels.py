"""numba kernels of the ``fast_social_force`` crowd: one world's pedestrians, one step.

Walls are read from the map's distance transform in cells (float32, capped: the array
:class:`~arena.sensors.lidar2d.Lidar2D` binds; 0 marks a blocking cell), obstacles as their
polygon edges, robots as circles. See :mod:`arena.crowd.models.fast_social_force.model` for the
model.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.models.fast_social_force.params import (
    P_A_PED,
    P_A_ROB,
    P_A_WALL,
    P_B_PED,
    P_B_ROB,
    P_B_WALL,
    P_CUTOFF,
    P_GOAL_R,
    P_TAU,
    P_VFAC,
)

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
I64 = NDArray[np.int64]

#: Obstacle edges per bounding box in the edge culling (a rectangle's four).
EDGE_RUN = 4


@njit(cache=True)
def wall_distance(distg: F32, res: float, gx0: float, gy0: float, x: float, y: float) -> float:
    """Approximate distance (m) from ``(x, y)`` to the nearest blocking cell's surface.

    Cell-centre distance transform at the point's cell less half a cell; 0 in a blocking cell
    or off the map (off-map counts as a wall for pedestrians).
    """
    h, w = distg.shape
    col = math.floor((x - gx0) / res)
    row = math.floor((y - gy0) / res)
    if col < 0 or row < 0 or col >= w or row >= h:
        return 0.0
    d = distg[row, col]
    if d == 0.0:
        return 0.0
    return max(float(d) * res - 0.5 * res, 0.0)


@njit(cache=True)
def wall_gradient(
    distg: F32, res: float, gx0: float, gy0: float, x: float, y: float
) -> tuple[float, float]:
    """Unit direction of increasing wall distance (central differences on the map), or 0."""
    h, w = distg.shape
    col = min(max(math.floor((x - gx0) / res), 1), w - 2)
    row = min(max(math.floor((y - gy0) / res), 1), h - 2)
    gx = float(distg[row, col + 1]) - float(distg[row, col - 1])
    gy = float(distg[row + 1, col]) - float(distg[row - 1, col])
    n = math.hypot(gx, gy)
    if n == 0.0:
        return 0.0, 0.0
    return gx / n, gy / n


@njit(cache=True)
def edge_run_boxes(seg_a: F64, seg_b: F64) -> F64:
    """Bounding boxes ``(ceil(s / EDGE_RUN), 4)`` ``[x0, y0, x1, y1]`` of runs of edges (m).

    Run ``r`` holds edges ``r·EDGE_RUN`` up to the next multiple (a box obstacle's four edges
    are consecutive in :class:`~arena.scene.state.StaticWorld`).
    """
    s_n = seg_a.shape[0]
    n_run = (s_n + EDGE_RUN - 1) // EDGE_RUN
    box = np.empty((n_run, 4))
    for r in range(n_run):
        bx0 = by0 = math.inf
        bx1 = by1 = -math.inf
        for s in range(r * EDGE_RUN, min((r + 1) * EDGE_RUN, s_n)):
            for px, py in ((seg_a[s, 0], seg_a[s, 1]), (seg_b[s, 0], seg_b[s, 1])):
                bx0 = min(bx0, px)
                by0 = min(by0, py)
                bx1 = max(bx1, px)
                by1 = max(by1, py)
        box[r, 0], box[r, 1], box[r, 2], box[r, 3] = bx0, by0, bx1, by1
    return box


@njit(cache=True)
def pair_repulsion(pos: F64, radii: F64, a_p: float, b_p: float, cutoff: float) -> F64:
    """``(n, 2)`` the pedestrians' mutual repulsion, ``Σ_b A_p·exp((r_a + r_b − d)/B_p)·n_ba``.

    Pairs closer than ``cutoff`` (m) only, found through a grid of cells at least ``cutoff``
    wide (the 3 x 3 cells around a pedestrian hold every such pair): O(n) for a crowd of
    bounded density. Each pair is computed once and added to both with opposite signs, so the
    forces are antisymmetric to the bit. Coincident pedestrians (``d < 1e-9`` m) push apart
    along x, the lower index toward −x, as if ``d = 1`` m.
    """
    n = pos.shape[0]
    acc = np.zeros((n, 2))
    if n < 2:
        return acc
    x0 = y0 = math.inf
    x1 = y1 = -math.inf
    for a in range(n):  # NaN coordinates fail every comparison: left out of the box
        if pos[a, 0] < x0:
            x0 = pos[a, 0]
        if pos[a, 0] > x1:
            x1 = pos[a, 0]
        if pos[a, 1] < y0:
            y0 = pos[a, 1]
        if pos[a, 1] > y1:
            y1 = pos[a, 1]
    if not (x1 >= x0 and y1 >= y0):
        x0 = x1 = y0 = y1 = 0.0
    # cells of at least the cutoff, and at most about 4n of them (a sparse crowd on a big map)
    per_axis = 2.0 * math.sqrt(n) + 1.0
    cell = max(cutoff, (x1 - x0) / per_axis, (y1 - y0) / per_axis)
    nx = int((x1 - x0) / cell) + 1
    ny = int((y1 - y0) / cell) + 1
    cid = np.empty(n, dtype=np.int64)
    for a in range(n):
        cx = (pos[a, 0] - x0) / cell
        cy = (pos[a, 1] - y0) / cell
        ix = min(int(cx), nx - 1) if cx > 0.0 else 0  # NaN: cell 0
        iy = min(int(cy), ny - 1) if cy > 0.0 else 0
        cid[a] = iy * nx + ix
    # counting sort: the pedestrians of cell c are order[start[c]:start[c + 1]], by index
    start = np.zeros(nx * ny + 1, dtype=np.int64)
    for a in range(n):
        start[cid[a] + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    for a in range(n):
        order[fill[cid[a]]] = a
        fill[cid[a]] += 1
    for a in range(n):
        ix = cid[a] % nx
        iy = cid[a] // nx
        for gy in range(max(iy - 1, 0), min(iy + 2, ny)):
            for gx in range(max(ix - 1, 0), min(ix + 2, nx)):
                c = gy * nx + gx
                for q in range(start[c], start[c + 1]):
                    b = order[q]
                    if b <= a:
                        continue
                    dx = pos[a, 0] - pos[b, 0]
                    dy = pos[a, 1] - pos[b, 1]
                    d = math.hypot(dx, dy)
                    if not d < cutoff:
                        continue
                    if d < 1e-9:  # coincident: a fixed, index-ordered axis (a < b)
                        dx, dy, d = -1.0, 0.0, 1.0
                    f = a_p * math.exp((radii[a] + radii[b] - d) / b_p)
                    fx = f * dx / d
                    fy = f * dy / d
                    acc[a, 0] += fx
                    acc[a, 1] += fy
                    acc[b, 0] -= fx
                    acc[b, 1] -= fy
    return acc


@njit(cache=True)
def step_crowd(
    pos: F64, vel: F64, heading: F64, radii: F64, vmax: F64,
    wps: F64, n_wp: I64, wp_mode: I64, wp_idx: I64, rand: F64, rand_k: int,
    distg: F32, res: float, gx0: float, gy0: float,
    seg_a: F64, seg_b: F64, run_box: F64, robot_xy: F64, robot_r: F64,
    prm: F64, dt: float, out_pos: F64, out_vel: F64, out_dest: F64,
) -> int:
    """One social-force step of one world's ``n`` pedestrians.

    Args:
        pos: ``(n, 2)`` positions (m), read.
        vel: ``(n, 2)`` velocities (m/s), read.
        heading: ``(n,)`` rad, updated in place (the motion's direction above 5 cm/s).
        radii: ``(n,)`` m.
        vmax: ``(n,)`` preferred speeds (m/s).
        wps: ``(n, K, 2)`` waypoints (m).
        n_wp: ``(n,)`` valid waypoints per pedestrian.
        wp_mode: ``(n,)`` 0 loop, 1 random.
        wp_idx: ``(n,)`` waypoint walked to, updated in place.
        rand: ``(T,)`` uniforms in [0, 1) for random waypoint choices, read cyclically.
        rand_k: uniforms of ``rand`` used so far.
        distg: ``(h, w)`` distance map in cells (0: blocking cell).
        res: cell size (m).
        gx0: map origin x (m).
        gy0: map origin y (m).
        seg_a: ``(s, 2)`` obstacle edge starts (m).
        seg_b: ``(s, 2)`` obstacle edge ends (m).
        run_box: :func:`edge_run_boxes` of the edges.
        robot_xy: ``(r, 2)`` robot positions (m).
        robot_r: ``(r,)`` robot radii (m).
        prm: the parameter vector (``FastSocialForceParams.as_array``).
        dt: s.
        out_pos: ``(n, 2)`` new positions, written.
        out_vel: ``(n, 2)`` new velocities, written.
        out_dest: ``(n, 2)`` the waypoint each pedestrian walked to this step (m), written.

    Returns:
        ``rand_k`` after the step.
    """
    tau = prm[P_TAU]
    goal_r = prm[P_GOAL_R]
    a_p, b_p = prm[P_A_PED], prm[P_B_PED]
    a_w, b_w = prm[P_A_WALL], prm[P_B_WALL]
    a_r, b_r = prm[P_A_ROB], prm[P_B_ROB]
    cutoff = prm[P_CUTOFF]
    vfac = prm[P_VFAC]
    n = pos.shape[0]
    s_n = seg_a.shape[0]
    n_run = run_box.shape[0]
    # A pedestrian farther than the cutoff from a run's box is farther from each of its edges,
    # whose forces are zero then, so the run is skipped. The 1e-9 m margin keeps the test
    # conservative under rounding: every edge that can act is still visited, in order, so the
    # sum is the same as without culling; most pedestrians are far from most obstacles.
    far2 = (cutoff + 1e-9) * (cutoff + 1e-9)
    social = pair_repulsion(pos, radii, a_p, b_p, cutoff)
    for a in range(n):
        x, y = pos[a, 0], pos[a, 1]
        vx, vy = vel[a, 0], vel[a, 1]
        ra = radii[a]
        # -- goal --
        k = wp_idx[a]
        gx = wps[a, k, 0] - x
        gy = wps[a, k, 1] - y
        gd = math.hypot(gx, gy)
        if gd < goal_r:
            m = n_wp[a]
            if wp_mode[a] == 0 or m < 2:
                k = (k + 1) % m
            else:
                u = rand[rand_k % rand.shape[0]]
                rand_k += 1
                k2 = min(int(u * (m - 1)), m - 2)
                k = k2 + 1 if k2 >= k else k2  # any waypoint but the current one
            wp_idx[a] = k
            gx = wps[a, k, 0] - x
            gy = wps[a, k, 1] - y
            gd = math.hypot(gx, gy)
        out_dest[a, 0] = wps[a, k, 0]
        out_dest[a, 1] = wps[a, k, 1]
        ax = -vx / tau
        ay = -vy / tau
        if gd > 1e-9:
            ax += vmax[a] * gx / gd / tau
            ay += vmax[a] * gy / gd / tau
        # -- other pedestrians --
        ax += social[a, 0]
        ay += social[a, 1]
        # -- robots, in row order --
        for j in range(robot_xy.shape[0]):
            dx = x - robot_xy[j, 0]
            dy = y - robot_xy[j, 1]
            d = math.hypot(dx, dy)
            if 1e-9 < d < cutoff:
                f = a_r * math.exp((ra + robot_r[j] - d) / b_r)
                ax += f * dx / d
                ay += f * dy / d
        # -- walls --
        dw = wall_distance(distg, res, gx0, gy0, x, y)
        if dw < cutoff:
            nx, ny = wall_gradient(distg, res, gx0, gy0, x, y)
            f = a_w * math.exp((ra - dw) / b_w)
            ax += f * nx
            ay += f * ny
        # -- obstacle edges (runs whose box is out of reach skipped, see above) --
        for r in range(n_run):
            ox = max(run_box[r, 0] - x, 0.0, x - run_box[r, 2])
            oy = max(run_box[r, 1] - y, 0.0, y - run_box[r, 3])
            if ox * ox + oy * oy >= far2:
                continue
            for s in range(r * EDGE_RUN, min((r + 1) * EDGE_RUN, s_n)):
                qx, qy = seg_a[s, 0], seg_a[s, 1]
                ex = seg_b[s, 0] - qx
                ey = seg_b[s, 1] - qy
                ee = ex * ex + ey * ey
                t = ((x - qx) * ex + (y - qy) * ey) / ee if ee > 0.0 else 0.0
                t = min(max(t, 0.0), 1.0)
                dx = x - qx - t * ex
                dy = y - qy - t * ey
                d = math.hypot(dx, dy)
                if 1e-9 < d < cutoff:
                    f = a_w * math.exp((ra - d) / b_w)
                    ax += f * dx / d
                    ay += f * dy / d
        # -- integrate (semi-implicit Euler, speed cap) --
        nvx = vx + ax * dt
        nvy = vy + ay * dt
        sp = math.hypot(nvx, nvy)
        cap = vfac * vmax[a]
        if sp > cap:
            nvx *= cap / sp
            nvy *= cap / sp
        nx_ = x + nvx * dt
        ny_ = y + nvy * dt
        # A move that puts the centre on a blocking cell (or off the map), or the body deeper
        # into a wall it already touches, is cancelled: nobody walks into a wall.
        dw_new = wall_distance(distg, res, gx0, gy0, nx_, ny_)
        if dw_new == 0.0 or (dw_new < ra and dw_new < dw):
            nx_, ny_, nvx, nvy = x, y, 0.0, 0.0
        out_pos[a, 0] = nx_
        out_pos[a, 1] = ny_
        out_vel[a, 0] = nvx
        out_vel[a, 1] = nvy
        if math.hypot(nvx, nvy) > 0.05:
            heading[a] = math.atan2(nvy, nvx)
    return rand_k
