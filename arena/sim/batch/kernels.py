"""numba kernels of :class:`~arena.sim.batch.BatchSim`: lidar, crowd and contacts of many worlds.

Every kernel runs ``prange`` over worlds and does each world's work serially, reading only that
world's slices, so a world's result never depends on the other worlds (nor on the thread count).

Per-world static data is packed as follows (``N`` worlds):

* distance maps: one flat float32 buffer; world ``i``'s ``(h_i, w_i)`` map in cells (0 marks a
  blocking cell, as :class:`~arena.sensors.lidar2d.Lidar2D` stores it) starts at ``offs[i]``;
* obstacle edges: ``(N, S, 2)`` padded arrays with ``seg_n[i]`` valid rows and ``seg_owner``
  the obstacle each edge belongs to (an obstacle's edges are consecutive and closed);
* pedestrians: ``(N, P, ...)`` padded arrays with ``ped_n[i]`` valid rows;
* wall faces (:func:`arena.sensors.lidar2d.wall_faces`): ``(N, F, 4)`` padded with
  ``face_n[i]`` valid rows; ``face_n[i] = -1`` casts world ``i``'s walls on its distance map.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from arena.sensors.lidar2d import (
    _AXIS_SNAP,
    _beam_window,
    _cast_faces,
    _cast_grid_many,
    _circle_hit,
    _fast_atan2,
    _origin_touches_wall,
    _segments_into,
)

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
I64 = NDArray[np.int64]
B1 = NDArray[np.bool_]

SQRT2 = math.sqrt(2.0)
#: Obstacle edges per bounding box in the crowd kernel's culling (a rectangle's four).
_EDGE_RUN = 4
_NO_OWNER = np.zeros(0, dtype=np.int64)

#: Collision kinds reported per world (the first that applies, in this order).
KIND_NONE = 0
KIND_WALL = 1
KIND_OBSTACLE = 2
KIND_PEDESTRIAN = 3

# Indices into the crowd parameter vector (see ``BatchCrowdParams.as_array``).
P_TAU, P_GOAL_R, P_A_PED, P_B_PED, P_A_WALL, P_B_WALL, P_A_ROB, P_B_ROB, P_CUTOFF, P_VFAC = range(
    10
)


@njit(cache=True)
def _world_map(dist_flat: F32, offs: I64, shapes: I64, i: int) -> F32:
    """World ``i``'s ``(h, w)`` distance map (cells), a C-contiguous view of the flat buffer."""
    h = shapes[i, 0]
    w = shapes[i, 1]
    return dist_flat[offs[i] : offs[i] + h * w].reshape((h, w))


# ------------------------------------------------------------------------------------------------
# lidar
# ------------------------------------------------------------------------------------------------
@njit(cache=True)
def _scan_one(
    pose: F64, mount: F64, cos_a: F64, sin_a: F64, angle_min: float, inc: float,
    range_min: float, range_max: float, distg: F32, res: float, gx0: float, gy0: float,
    circ_xy: F64, circ_r: F64, seg_a: F64, seg_b: F64,
    dx: F64, dy: F64, tlim: F64, tg: F64, t1s: F64, t2s: F64, active: I64, pending: I64,
    best: F64, faces: F64, use_faces: bool,
) -> None:
    """One robot's scan into ``best``, with caller-provided scratch arrays.

    :func:`arena.sensors.lidar2d._scan_kernel` for a single pose, no owners and no dynamic
    segments.
    The arithmetic is the same, operation by operation, so the ranges are bit-identical.
    """
    n = cos_a.shape[0]
    inv_res = 1.0 / res
    c = math.cos(pose[2])
    s = math.sin(pose[2])
    ox = pose[0] + c * mount[0] - s * mount[1]
    oy = pose[1] + s * mount[0] + c * mount[1]
    yaw = pose[2] + mount[2]
    if not (math.isfinite(ox) and math.isfinite(oy) and math.isfinite(yaw)):
        raise ValueError("Lidar2D: robot poses must be finite")
    cy_ = math.cos(yaw)
    sy_ = math.sin(yaw)
    for i in range(n):
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
        return
    for k in range(circ_xy.shape[0]):
        ccx = circ_xy[k, 0] - ox
        ccy = circ_xy[k, 1] - oy
        rad = circ_r[k]
        d2 = ccx * ccx + ccy * ccy
        c2 = d2 - rad * rad
        if c2 <= 0.0:
            best[:] = range_min
            return
        dist = math.sqrt(d2)
        if dist - rad > range_max:
            continue
        half = math.asin(min(rad / dist, 1.0))
        i0, i1, j0, j1 = _beam_window(_fast_atan2(ccy, ccx) - half, 2.0 * half, a0, inc, n)
        for i in range(i0, i1 + 1):
            _circle_hit(best, i, dx, dy, ccx, ccy, c2)
        for i in range(j0, j1 + 1):
            _circle_hit(best, i, dx, dy, ccx, ccy, c2)
    _segments_into(best, dx, dy, ox, oy, a0, inc, range_max, seg_a, seg_b, _NO_OWNER, -1)
    for i in range(n):
        tlim[i] = best[i] * inv_res
    if use_faces:
        _cast_faces(
            gox, goy, dx, dy, tlim, faces, distg.shape[1], distg.shape[0], a0, inc, tg, t1s,
            t2s,
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


@njit(cache=True, parallel=True)
def scan_worlds(
    due: B1, poses: F64, mount: F64, cos_a: F64, sin_a: F64, angle_min: float, inc: float,
    range_min: float, range_max: float,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    ped_pos: F64, ped_r: F64, ped_n: I64,
    seg_a: F64, seg_b: F64, seg_n: I64, out: F64,
    scratch_f: F64, scratch_i: I64, faces: F64, face_n: I64,
) -> None:
    """Scan every world whose ``due`` flag is set into ``out[i]`` (``(N, B)`` ranges, m).

    Each world is cast as Arena's single-robot kernel
    (:func:`arena.sensors.lidar2d._scan_kernel`) casts it, on its own map, pedestrians (solid
    circles) and obstacle edges, so a world's scan is bit-identical to :meth:`Lidar2D.scan` of
    the same scene. ``scratch_f`` ``(N, 6, B)`` and ``scratch_i`` ``(N, 2, B)`` are per-world
    work arrays (nothing is allocated per call).
    """
    for i in prange(poses.shape[0]):
        if not due[i]:
            continue
        _scan_world(
            i, poses, mount, cos_a, sin_a, angle_min, inc, range_min, range_max,
            dist_flat, offs, shapes, res, origin, ped_pos, ped_r, ped_n,
            seg_a, seg_b, seg_n, out, scratch_f, scratch_i, faces, face_n,
        )


@njit(cache=True)
def scan_worlds_serial(
    due: B1, poses: F64, mount: F64, cos_a: F64, sin_a: F64, angle_min: float, inc: float,
    range_min: float, range_max: float,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    ped_pos: F64, ped_r: F64, ped_n: I64,
    seg_a: F64, seg_b: F64, seg_n: I64, out: F64,
    scratch_f: F64, scratch_i: I64, faces: F64, face_n: I64,
) -> None:
    """:func:`scan_worlds` on the calling thread (no thread-pool launch: small ``N``)."""
    for i in range(poses.shape[0]):
        if not due[i]:
            continue
        _scan_world(
            i, poses, mount, cos_a, sin_a, angle_min, inc, range_min, range_max,
            dist_flat, offs, shapes, res, origin, ped_pos, ped_r, ped_n,
            seg_a, seg_b, seg_n, out, scratch_f, scratch_i, faces, face_n,
        )


@njit(cache=True)
def _scan_world(
    i: int, poses: F64, mount: F64, cos_a: F64, sin_a: F64, angle_min: float, inc: float,
    range_min: float, range_max: float,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    ped_pos: F64, ped_r: F64, ped_n: I64,
    seg_a: F64, seg_b: F64, seg_n: I64, out: F64,
    scratch_f: F64, scratch_i: I64, faces: F64, face_n: I64,
) -> None:
    distg = _world_map(dist_flat, offs, shapes, i)
    n = ped_n[i]
    s = seg_n[i]
    sf = scratch_f[i]
    si = scratch_i[i]
    _scan_one(
        poses[i], mount, cos_a, sin_a, angle_min, inc, range_min, range_max,
        distg, res[i], origin[i, 0], origin[i, 1], ped_pos[i, :n], ped_r[i, :n],
        seg_a[i, :s], seg_b[i, :s], sf[0], sf[1], sf[2], sf[3], sf[4], sf[5], si[0], si[1],
        out[i],
        faces[i, : max(face_n[i], 0)], face_n[i] >= 0,
    )


# ------------------------------------------------------------------------------------------------
# contacts
# ------------------------------------------------------------------------------------------------
@njit(cache=True)
def _circle_hits_grid(
    x: float, y: float, r: float, distg: F32, res: float, gx0: float, gy0: float
) -> bool:
    """Circle footprint vs blocking cells or the map border (as native2d's ``hits_grid``)."""
    h, w = distg.shape
    xmax = gx0 + w * res
    ymax = gy0 + h * res
    if not (gx0 <= x < xmax and gy0 <= y < ymax):
        return True
    if x - r < gx0 or y - r < gy0 or x + r > xmax or y + r > ymax:
        return True
    col = int((x - gx0) // res)
    row = int((y - gy0) // res)
    if distg[row, col] * res - res * SQRT2 >= r:
        return False
    k = math.ceil(r / res) + 1
    half = 0.5 * res
    for rr in range(max(row - k, 0), min(row + k + 1, h)):
        for cc in range(max(col - k, 0), min(col + k + 1, w)):
            if distg[rr, cc] != 0.0:
                continue
            ddx = max(abs(gx0 + (cc + 0.5) * res - x) - half, 0.0)
            ddy = max(abs(gy0 + (rr + 0.5) * res - y) - half, 0.0)
            if ddx * ddx + ddy * ddy < r * r:
                return True
    return False


@njit(cache=True)
def _seg_dist(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    ex = bx - ax
    ey = by - ay
    ee = ex * ex + ey * ey
    t = ((px - ax) * ex + (py - ay) * ey) / ee if ee > 0.0 else 0.0
    t = min(max(t, 0.0), 1.0)
    return math.hypot(px - ax - t * ex, py - ay - t * ey)


@njit(cache=True)
def _circle_hits_obstacle(
    x: float, y: float, r: float, seg_a: F64, seg_b: F64, owner: I64, s: int
) -> int:
    """Index of an obstacle (closed convex or not polygon) the circle overlaps, or -1."""
    k = 0
    while k < s:
        ob = owner[k]
        inside = False
        near = False
        while k < s and owner[k] == ob:
            ax, ay = seg_a[k, 0], seg_a[k, 1]
            bx, by = seg_b[k, 0], seg_b[k, 1]
            if (ay > y) != (by > y) and x < ax + (y - ay) * (bx - ax) / (by - ay):
                inside = not inside  # crossing number
            if _seg_dist(x, y, ax, ay, bx, by) <= r:
                near = True
            k += 1
        if inside or near:
            return int(ob)
    return -1


@njit(cache=True)
def _contacts_worlds_one(
    i: int,
    new_poses: F64, old_poses: F64, sweep: bool, radius: F64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_owner: I64, seg_n: I64,
    ped_pos: F64, ped_r: F64, ped_n: I64,
    wall: B1, obstacle: I64, agent: I64,
) -> None:
    distg = _world_map(dist_flat, offs, shapes, i)
    r = radius[i]
    x, y = new_poses[i, 0], new_poses[i, 1]
    rs = res[i]
    gx0, gy0 = origin[i, 0], origin[i, 1]
    hit = False
    k = 1
    if sweep:
        dist = math.hypot(x - old_poses[i, 0], y - old_poses[i, 1])
        k = max(math.ceil(dist / max(rs * 0.5, r * 0.5)), 1)
    for j in range(1, k + 1):
        s = j / k
        if k == 1:
            px, py = x, y
        else:
            px = old_poses[i, 0] + s * (x - old_poses[i, 0])
            py = old_poses[i, 1] + s * (y - old_poses[i, 1])
        if _circle_hits_grid(px, py, r, distg, rs, gx0, gy0):
            hit = True
            break
    wall[i] = hit
    obstacle[i] = _circle_hits_obstacle(x, y, r, seg_a[i], seg_b[i], seg_owner[i], seg_n[i])
    best = -1
    best_d = math.inf
    for j in range(ped_n[i]):
        d = math.hypot(ped_pos[i, j, 0] - x, ped_pos[i, j, 1] - y)
        if d < ped_r[i, j] + r and d < best_d:
            best = j
            best_d = d
    agent[i] = best


@njit(cache=True, parallel=True)
def contacts_worlds(
    new_poses: F64, old_poses: F64, sweep: bool, radius: F64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_owner: I64, seg_n: I64,
    ped_pos: F64, ped_r: F64, ped_n: I64,
    wall: B1, obstacle: I64, agent: I64,
) -> None:
    """Contacts of each world's circular robot footprint at ``new_poses``.

    Walls are also tested at poses swept from ``old_poses`` (spacing ``max(res/2, r/2)``, as
    native2d) so a fast robot cannot tunnel through a thin wall; obstacles and pedestrians at
    the end pose only. ``agent`` is the nearest overlapping pedestrian.
    """
    for i in prange(new_poses.shape[0]):
        _contacts_worlds_one(
            i, new_poses, old_poses, sweep, radius, dist_flat, offs, shapes, res, origin, seg_a,
            seg_b, seg_owner, seg_n, ped_pos, ped_r, ped_n, wall, obstacle, agent,
        )


@njit(cache=True)
def contacts_worlds_serial(
    new_poses: F64, old_poses: F64, sweep: bool, radius: F64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_owner: I64, seg_n: I64,
    ped_pos: F64, ped_r: F64, ped_n: I64,
    wall: B1, obstacle: I64, agent: I64,
) -> None:
    """:func:`contacts_worlds` on the calling thread (no thread-pool launch: small ``N``)."""
    for i in range(new_poses.shape[0]):
        _contacts_worlds_one(
            i, new_poses, old_poses, sweep, radius, dist_flat, offs, shapes, res, origin, seg_a,
            seg_b, seg_owner, seg_n, ped_pos, ped_r, ped_n, wall, obstacle, agent,
        )


# ------------------------------------------------------------------------------------------------
# crowd
# ------------------------------------------------------------------------------------------------
@njit(cache=True)
def _wall_distance(distg: F32, res: float, gx0: float, gy0: float, x: float, y: float) -> float:
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
def _wall_gradient(
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
def _crowd_worlds_one(
    w: int,
    active: B1, pos: F64, vel: F64, heading: F64, radii: F64, vmax: F64, ped_n: I64,
    wps: F64, n_wp: I64, wp_mode: I64, wp_idx: I64, rand: F64, rand_k: I64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_n: I64, robot_xy: F64, robot_r: F64,
    prm: F64, dt: float, out_pos: F64, out_vel: F64,
) -> None:
    tau = prm[P_TAU]
    goal_r = prm[P_GOAL_R]
    a_p, b_p = prm[P_A_PED], prm[P_B_PED]
    a_w, b_w = prm[P_A_WALL], prm[P_B_WALL]
    a_r, b_r = prm[P_A_ROB], prm[P_B_ROB]
    cutoff = prm[P_CUTOFF]
    vfac = prm[P_VFAC]
    n = ped_n[w]
    if not active[w] or n == 0:
        for a in range(n):
            out_pos[w, a, 0] = pos[w, a, 0]
            out_pos[w, a, 1] = pos[w, a, 1]
            out_vel[w, a, 0] = vel[w, a, 0]
            out_vel[w, a, 1] = vel[w, a, 1]
        return
    distg = _world_map(dist_flat, offs, shapes, w)
    rs = res[w]
    gx0, gy0 = origin[w, 0], origin[w, 1]
    s_n = seg_n[w]
    # Obstacle edges in runs of _EDGE_RUN (a box's four edges) with their bounding boxes: a
    # pedestrian farther than the cutoff from a run's box is farther from each of its edges,
    # whose forces are zero then, so the run is skipped. The 1e-9 m margin keeps the test
    # conservative under rounding: every edge that can act is still visited, in order, so the
    # sum is bit-identical; most pedestrians are far from most obstacles.
    n_run = (s_n + _EDGE_RUN - 1) // _EDGE_RUN
    run_box = np.empty((n_run, 4))
    for r in range(n_run):
        bx0 = by0 = math.inf
        bx1 = by1 = -math.inf
        for s in range(r * _EDGE_RUN, min((r + 1) * _EDGE_RUN, s_n)):
            for px, py in ((seg_a[w, s, 0], seg_a[w, s, 1]), (seg_b[w, s, 0], seg_b[w, s, 1])):
                bx0 = min(bx0, px)
                by0 = min(by0, py)
                bx1 = max(bx1, px)
                by1 = max(by1, py)
        run_box[r, 0], run_box[r, 1], run_box[r, 2], run_box[r, 3] = bx0, by0, bx1, by1
    far2 = (cutoff + 1e-9) * (cutoff + 1e-9)
    # Pair distances and repulsion magnitudes, once per unordered pair: both are symmetric bit
    # for bit (x_b - x_a is exactly -(x_a - x_b), hypot ignores signs, r_a + r_b = r_b + r_a),
    # so pedestrian a reads the very values it used to compute, at half the hypot/exp calls.
    pair_d = np.empty((n, n))
    pair_f = np.empty((n, n))
    for a in range(n):
        for b in range(a + 1, n):
            d = math.hypot(pos[w, a, 0] - pos[w, b, 0], pos[w, a, 1] - pos[w, b, 1])
            pair_d[a, b] = d
            if d >= cutoff:  # the tests of the loop below, NaN included
                continue
            if d < 1e-9:
                d = 1.0  # coincident: the force acts at d = 1 (see below)
            pair_f[a, b] = a_p * math.exp((radii[w, a] + radii[w, b] - d) / b_p)
    for a in range(n):
        x, y = pos[w, a, 0], pos[w, a, 1]
        vx, vy = vel[w, a, 0], vel[w, a, 1]
        ra = radii[w, a]
        # -- goal --
        k = wp_idx[w, a]
        gx = wps[w, a, k, 0] - x
        gy = wps[w, a, k, 1] - y
        gd = math.hypot(gx, gy)
        if gd < goal_r:
            m = n_wp[w, a]
            if wp_mode[w, a] == 0 or m < 2:
                k = (k + 1) % m
            else:
                u = rand[w, rand_k[w] % rand.shape[1]]
                rand_k[w] += 1
                k2 = min(int(u * (m - 1)), m - 2)
                k = k2 + 1 if k2 >= k else k2  # any waypoint but the current one
            wp_idx[w, a] = k
            gx = wps[w, a, k, 0] - x
            gy = wps[w, a, k, 1] - y
            gd = math.hypot(gx, gy)
        ax = -vx / tau
        ay = -vy / tau
        if gd > 1e-9:
            ax += vmax[w, a] * gx / gd / tau
            ay += vmax[w, a] * gy / gd / tau
        # -- other pedestrians --
        for b in range(n):
            if b == a:
                continue
            lo, hi = (a, b) if a < b else (b, a)
            d = pair_d[lo, hi]
            if d >= cutoff:
                continue
            dx = x - pos[w, b, 0]
            dy = y - pos[w, b, 1]
            if d < 1e-9:  # coincident: push apart along a fixed, index-ordered axis
                dx, dy, d = (1.0 if a > b else -1.0), 0.0, 1.0
            f = pair_f[lo, hi]  # a_p·exp((r_a + r_b - d)/b_p)
            ax += f * dx / d
            ay += f * dy / d
        # -- robot --
        dx = x - robot_xy[w, 0]
        dy = y - robot_xy[w, 1]
        d = math.hypot(dx, dy)
        if 1e-9 < d < cutoff:
            f = a_r * math.exp((ra + robot_r[w] - d) / b_r)
            ax += f * dx / d
            ay += f * dy / d
        # -- walls --
        dw = _wall_distance(distg, rs, gx0, gy0, x, y)
        if dw < cutoff:
            nx, ny = _wall_gradient(distg, rs, gx0, gy0, x, y)
            f = a_w * math.exp((ra - dw) / b_w)
            ax += f * nx
            ay += f * ny
        # -- obstacle edges (runs whose box is out of reach skipped, see above) --
        for r in range(n_run):
            ox = max(run_box[r, 0] - x, 0.0, x - run_box[r, 2])
            oy = max(run_box[r, 1] - y, 0.0, y - run_box[r, 3])
            if ox * ox + oy * oy >= far2:
                continue
            for s in range(r * _EDGE_RUN, min((r + 1) * _EDGE_RUN, s_n)):
                qx, qy = seg_a[w, s, 0], seg_a[w, s, 1]
                ex = seg_b[w, s, 0] - qx
                ey = seg_b[w, s, 1] - qy
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
        # -- integrate --
        nvx = vx + ax * dt
        nvy = vy + ay * dt
        sp = math.hypot(nvx, nvy)
        cap = vfac * vmax[w, a]
        if sp > cap:
            nvx *= cap / sp
            nvy *= cap / sp
        nx_ = x + nvx * dt
        ny_ = y + nvy * dt
        dw_new = _wall_distance(distg, rs, gx0, gy0, nx_, ny_)
        if dw_new == 0.0 or (dw_new < ra and dw_new < dw):
            nx_, ny_, nvx, nvy = x, y, 0.0, 0.0
        out_pos[w, a, 0] = nx_
        out_pos[w, a, 1] = ny_
        out_vel[w, a, 0] = nvx
        out_vel[w, a, 1] = nvy
        if math.hypot(nvx, nvy) > 0.05:
            heading[w, a] = math.atan2(nvy, nvx)


@njit(cache=True, parallel=True)
def crowd_worlds(
    active: B1, pos: F64, vel: F64, heading: F64, radii: F64, vmax: F64, ped_n: I64,
    wps: F64, n_wp: I64, wp_mode: I64, wp_idx: I64, rand: F64, rand_k: I64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_n: I64, robot_xy: F64, robot_r: F64,
    prm: F64, dt: float, out_pos: F64, out_vel: F64,
) -> None:
    """One social-force step of every active world's pedestrians (Helbing-style, no groups).

    Acceleration of pedestrian ``a`` = ``(vmax·e_goal − v)/τ``
    ``+ Σ_b A_p·exp((r_a + r_b − d)/B_p)·n_ba`` (other pedestrians within ``cutoff``)
    ``+ A_r·exp((r_a + R − d)/B_r)·n`` (the robot, footprint radius ``R``)
    ``+ A_w·exp((r_a − d_w)/B_w)·∇d_w`` (walls, from the distance map, within ``cutoff``)
    ``+ Σ A_w·exp((r_a − d_s)/B_w)·n_s`` (obstacle edges within ``cutoff``).
    Semi-implicit Euler; speed capped at ``vfac·vmax``. A move that would put the centre in a
    blocking cell, or bring the body closer into a wall it already touches, is cancelled (the
    pedestrian stops), so nobody walks into a wall. Within ``goal_radius`` of its waypoint a
    pedestrian switches to the next one (loop), or to one drawn from ``rand`` (random mode).
    Reads ``pos``/``vel`` and writes ``out_pos``/``out_vel`` (order-independent).
    """
    for w in prange(pos.shape[0]):
        _crowd_worlds_one(
            w, active, pos, vel, heading, radii, vmax, ped_n, wps, n_wp, wp_mode, wp_idx, rand,
            rand_k, dist_flat, offs, shapes, res, origin, seg_a, seg_b, seg_n, robot_xy, robot_r,
            prm, dt, out_pos, out_vel,
        )


@njit(cache=True)
def crowd_worlds_serial(
    active: B1, pos: F64, vel: F64, heading: F64, radii: F64, vmax: F64, ped_n: I64,
    wps: F64, n_wp: I64, wp_mode: I64, wp_idx: I64, rand: F64, rand_k: I64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_n: I64, robot_xy: F64, robot_r: F64,
    prm: F64, dt: float, out_pos: F64, out_vel: F64,
) -> None:
    """:func:`crowd_worlds` on the calling thread (no thread-pool launch: small ``N``)."""
    for w in range(pos.shape[0]):
        _crowd_worlds_one(
            w, active, pos, vel, heading, radii, vmax, ped_n, wps, n_wp, wp_mode, wp_idx, rand,
            rand_k, dist_flat, offs, shapes, res, origin, seg_a, seg_b, seg_n, robot_xy, robot_r,
            prm, dt, out_pos, out_vel,
        )


# ------------------------------------------------------------------------------------------------
# one fused step
# ------------------------------------------------------------------------------------------------
@njit(cache=True)
def _step_world(
    w: int, crowd: bool, stop: bool,
    active: B1, pos: F64, vel: F64, heading: F64, radii: F64, vmax: F64, ped_n: I64,
    wps: F64, n_wp: I64, wp_mode: I64, wp_idx: I64, rand: F64, rand_k: I64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_owner: I64, seg_n: I64, radius: F64,
    prm: F64, dt: float, out_pos: F64, out_vel: F64,
    old_poses: F64, new_poses: F64, new_twists: F64, new_steer: F64, steer: F64,
    wall: B1, obstacle: I64, agent: I64,
    due: B1, mount: F64, cos_a: F64, sin_a: F64, angle_min: float, inc: float,
    range_min: float, range_max: float, scans: F64, scratch_f: F64, scratch_i: I64,
    faces: F64, face_n: I64,
) -> None:
    """World ``w``'s crowd, contacts, collision response and lidar: the stages in step order.

    Each stage is the per-world function the stage kernels call, on the same inputs
    (pedestrians moved first; contacts of the new pose with the moved pedestrians; a blocked
    move undone; then the scan from the final pose), so the results are bit-identical.
    """
    if crowd:
        _crowd_worlds_one(
            w, active, pos, vel, heading, radii, vmax, ped_n, wps, n_wp, wp_mode, wp_idx, rand,
            rand_k, dist_flat, offs, shapes, res, origin, seg_a, seg_b, seg_n, old_poses,
            radius, prm, dt, out_pos, out_vel,
        )
        peds = out_pos
    else:
        peds = pos
    _contacts_worlds_one(
        w, new_poses, old_poses, True, radius, dist_flat, offs, shapes, res, origin, seg_a,
        seg_b, seg_owner, seg_n, peds, radii, ped_n, wall, obstacle, agent,
    )
    if stop and (wall[w] or obstacle[w] >= 0 or agent[w] >= 0):
        for k in range(3):
            new_poses[w, k] = old_poses[w, k]
            new_twists[w, k] = 0.0
        new_steer[w] = steer[w]
    if due[w]:
        _scan_world(
            w, new_poses, mount, cos_a, sin_a, angle_min, inc, range_min, range_max,
            dist_flat, offs, shapes, res, origin, peds, radii, ped_n,
            seg_a, seg_b, seg_n, scans, scratch_f, scratch_i, faces, face_n,
        )


@njit(cache=True, parallel=True, nogil=True)
def step_worlds(
    crowd: bool, stop: bool,
    active: B1, pos: F64, vel: F64, heading: F64, radii: F64, vmax: F64, ped_n: I64,
    wps: F64, n_wp: I64, wp_mode: I64, wp_idx: I64, rand: F64, rand_k: I64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_owner: I64, seg_n: I64, radius: F64,
    prm: F64, dt: float, out_pos: F64, out_vel: F64,
    old_poses: F64, new_poses: F64, new_twists: F64, new_steer: F64, steer: F64,
    wall: B1, obstacle: I64, agent: I64,
    due: B1, mount: F64, cos_a: F64, sin_a: F64, angle_min: float, inc: float,
    range_min: float, range_max: float, scans: F64, scratch_f: F64, scratch_i: I64,
    faces: F64, face_n: I64,
) -> None:
    """One whole simulation step of every world in a single parallel region.

    :func:`crowd_worlds`, :func:`contacts_worlds` (swept), the ``"stop"`` collision response
    and :func:`scan_worlds` (worlds flagged ``due``) fused per world, so a step pays one
    thread-pool launch and one barrier instead of three, and each world's data is touched
    while it is still in cache. ``new_poses``/``new_twists``/``new_steer`` hold the
    kinematics' result and are undone in place for blocked worlds (``stop``).
    """
    for w in prange(old_poses.shape[0]):
        _step_world(
            w, crowd, stop, active, pos, vel, heading, radii, vmax, ped_n, wps, n_wp, wp_mode,
            wp_idx, rand, rand_k, dist_flat, offs, shapes, res, origin, seg_a, seg_b, seg_owner,
            seg_n, radius, prm, dt, out_pos, out_vel, old_poses, new_poses, new_twists,
            new_steer, steer, wall, obstacle, agent, due, mount, cos_a, sin_a, angle_min, inc,
            range_min, range_max, scans, scratch_f, scratch_i, faces, face_n,
        )


@njit(cache=True, nogil=True)
def step_worlds_serial(
    crowd: bool, stop: bool,
    active: B1, pos: F64, vel: F64, heading: F64, radii: F64, vmax: F64, ped_n: I64,
    wps: F64, n_wp: I64, wp_mode: I64, wp_idx: I64, rand: F64, rand_k: I64,
    dist_flat: F32, offs: I64, shapes: I64, res: F64, origin: F64,
    seg_a: F64, seg_b: F64, seg_owner: I64, seg_n: I64, radius: F64,
    prm: F64, dt: float, out_pos: F64, out_vel: F64,
    old_poses: F64, new_poses: F64, new_twists: F64, new_steer: F64, steer: F64,
    wall: B1, obstacle: I64, agent: I64,
    due: B1, mount: F64, cos_a: F64, sin_a: F64, angle_min: float, inc: float,
    range_min: float, range_max: float, scans: F64, scratch_f: F64, scratch_i: I64,
    faces: F64, face_n: I64,
) -> None:
    """:func:`step_worlds` on the calling thread (no thread-pool launch: small ``N``)."""
    for w in range(old_poses.shape[0]):
        _step_world(
            w, crowd, stop, active, pos, vel, heading, radii, vmax, ped_n, wps, n_wp, wp_mode,
            wp_idx, rand, rand_k, dist_flat, offs, shapes, res, origin, seg_a, seg_b, seg_owner,
            seg_n, radius, prm, dt, out_pos, out_vel, old_poses, new_poses, new_twists,
            new_steer, steer, wall, obstacle, agent, due, mount, cos_a, sin_a, angle_min, inc,
            range_min, range_max, scans, scratch_f, scratch_i, faces, face_n,
        )
