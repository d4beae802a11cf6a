"""The scan kernels of :mod:`arena.sensors.lidar2d`: wall faces, circles, segments and noise.

:func:`_scan_one` casts every beam of one sensor against the wall faces (or the grid walk of
:mod:`.grid_kernels`), the circles and the segments; it is the only scan code, called per pose
by :func:`_scan_kernel` (:class:`~arena.sensors.lidar2d.Lidar2D`) and per sensor row by
:mod:`.bank_kernels` (:class:`~arena.sensors.lidar2d.LidarBank`). :func:`_add_noise` draws
nothing itself (the caller's generator gives the normal deviates).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.sensors.lidar2d.grid_kernels import CORNER_EPS, _cast_grid_many, _origin_touches_wall

# Directions closer than this to an axis are snapped onto it (1e-12 rad ≈ 3e-11 m at 30 m), so
# that beams meant to be axis-aligned (yaw 90° gives cos = 6e-17) traverse the grid exactly.
_AXIS_SNAP = 1e-12
_TWO_PI = 2.0 * math.pi

_NO_SIDE = np.zeros(0)  # no back-face culling (dynamic segments)

#: Rows of the float and int scratch arrays :func:`_scan_one` needs (each ``num_beams`` long).
SCRATCH_F = 6
SCRATCH_I = 2


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
    robot: int, side: NDArray[np.float64],
) -> None:
    """Lower ``best`` with the hits on every segment (skipping those owned by ``robot``).

    ``side`` ``(s,)`` (or empty: none) culls back faces: an edge of a closed polygon with
    ``side[k] = +1`` (counter-clockwise polygon) or ``-1`` (clockwise) is skipped when the
    origin lies on its polygon's inner side of its line. A beam entering a polygon crosses an
    edge with the origin on that edge's outer side, so the nearest hit on a polygon seen from
    outside is always on a front edge; about half the edges need no beam tests (see
    :func:`~arena.sensors.lidar2d.model.polygon_sides`).
    """
    n = best.shape[0]
    culled = side.shape[0] == seg_a.shape[0]
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
        if culled and side[k] * (ey * ax - ex * ay) > 0.0:
            continue  # back face: the origin is on the polygon's inner side of this edge
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


@njit(cache=True, fastmath=False, inline="always")
def _scan_one(
    pose: NDArray[np.float64], mount: NDArray[np.float64],
    cos_a: NDArray[np.float64], sin_a: NDArray[np.float64], angle_min: float, inc: float,
    range_min: float, range_max: float,
    distg: NDArray[np.float32], res: float, gx0: float, gy0: float,
    faces: NDArray[np.float64], use_faces: bool,
    stat_a: NDArray[np.float64], stat_b: NDArray[np.float64], stat_side: NDArray[np.float64],
    circ_xy: NDArray[np.float64], circ_r: NDArray[np.float64], circ_owner: NDArray[np.int64],
    dyn_a: NDArray[np.float64], dyn_b: NDArray[np.float64], dyn_owner: NDArray[np.int64],
    robot: int, scratch_f: NDArray[np.float64], scratch_i: NDArray[np.int64],
    best: NDArray[np.float64],
) -> None:
    """One sensor's clipped ranges (m) into ``best``; see the package docstring.

    The sensor pose, origin checks, circles and segments (each testing only the beams in its
    angular window), then the grid limited to the nearest hit so far, then clipping. This is
    the only scan code: :func:`_scan_kernel` (one world, one spec) and the rows kernels of
    :mod:`.bank_kernels` (every sensor of every world) both call it per sensor.
    Inlined into its callers (numba IR): a call with some thirty array arguments costs about
    1 % of a jackal scan.

    Args:
        pose: ``(3,)`` robot pose ``[x m, y m, yaw rad]``.
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
        faces: ``(F, 4)`` the map's :func:`wall_faces` (read only if ``use_faces``).
        use_faces: cast the walls as faces instead of walking the grid.
        stat_a: ``(s, 2)`` static segment starts (m).
        stat_b: ``(s, 2)`` static segment ends (m).
        stat_side: ``(s,)`` back-face sides of the static segments
            (:func:`~arena.sensors.lidar2d.model.polygon_sides`), or empty: no culling.
        circ_xy: ``(m, 2)`` circle centres (m).
        circ_r: ``(m,)`` circle radii (m).
        circ_owner: ``(m,)`` owner of each circle (read only if ``robot >= 0``).
        dyn_a: ``(k, 2)`` dynamic segment starts (m).
        dyn_b: ``(k, 2)`` dynamic segment ends (m).
        dyn_owner: ``(k,)`` owner of each dynamic segment (read only if ``robot >= 0``).
        robot: the circles and dynamic segments whose owner equals it are invisible; -1: none.
        scratch_f: ``(SCRATCH_F, >= n)`` float work array (overwritten).
        scratch_i: ``(SCRATCH_I, >= n)`` int work array (overwritten).
        best: ``(n,)`` output ranges (m).
    """
    n = cos_a.shape[0]
    dx = scratch_f[0, :n]
    dy = scratch_f[1, :n]
    tlim = scratch_f[2, :n]
    tg = scratch_f[3, :n]
    t1s = scratch_f[4, :n]
    t2s = scratch_f[5, :n]
    active = scratch_i[0, :n]
    pending = scratch_i[1, :n]
    inv_res = 1.0 / res
    # Sensor origin and heading in the world (pose ⊕ mount).
    c = math.cos(pose[2])
    s = math.sin(pose[2])
    ox = pose[0] + c * mount[0] - s * mount[1]
    oy = pose[1] + s * mount[0] + c * mount[1]
    yaw = pose[2] + mount[2]
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
        return

    # -- circles: solid discs, only the beams in each disc's angular window are tested --
    for k in range(circ_xy.shape[0]):
        if robot >= 0 and circ_owner[k] == robot:
            continue
        ccx = circ_xy[k, 0] - ox
        ccy = circ_xy[k, 1] - oy
        rad = circ_r[k]
        d2 = ccx * ccx + ccy * ccy
        c2 = d2 - rad * rad
        if c2 <= 0.0:
            best[:] = range_min  # origin inside or on the disc: every beam hits it at t = 0
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

    # -- segments: static obstacle edges, then dynamic ones --
    _segments_into(best, dx, dy, ox, oy, a0, inc, range_max, stat_a, stat_b, dyn_owner, -1,
                   stat_side)
    _segments_into(best, dx, dy, ox, oy, a0, inc, range_max, dyn_a, dyn_b, dyn_owner, robot,
                   _NO_SIDE)

    # -- grid, limited to the nearest hit found so far --
    for i in range(n):
        tlim[i] = best[i] * inv_res
    if use_faces:
        _cast_faces(
            gox, goy, dx, dy, tlim, faces, distg.shape[1], distg.shape[0], a0, inc, tg, t1s, t2s,
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
def _scan_kernel(
    poses: NDArray[np.float64], mount: NDArray[np.float64],
    cos_a: NDArray[np.float64], sin_a: NDArray[np.float64], angle_min: float, inc: float,
    range_min: float, range_max: float,
    distg: NDArray[np.float32], res: float, gx0: float, gy0: float,
    circ_xy: NDArray[np.float64], circ_r: NDArray[np.float64], circ_owner: NDArray[np.int64],
    stat_a: NDArray[np.float64], stat_b: NDArray[np.float64], stat_side: NDArray[np.float64],
    dyn_a: NDArray[np.float64], dyn_b: NDArray[np.float64], dyn_owner: NDArray[np.int64],
    use_owner: bool, faces: NDArray[np.float64], use_faces: bool, out: NDArray[np.float64],
) -> None:
    """Fill ``out`` with the clipped ranges (m) of every robot: :func:`_scan_one` per pose.

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
        stat_side: ``(s,)`` back-face sides of the static segments, or empty: no culling.
        dyn_a: ``(k, 2)`` dynamic segment starts (m).
        dyn_b: ``(k, 2)`` dynamic segment ends (m).
        dyn_owner: ``(k,)`` robot owning each dynamic segment (read only if ``use_owner``).
        use_owner: robot ``i`` ignores the circles and dynamic segments owned by ``i``.
        faces: ``(F, 4)`` the map's :func:`wall_faces` (read only if ``use_faces``).
        use_faces: cast the walls as faces instead of walking the grid.
        out: ``(r, n)`` output ranges (m).
    """
    n = cos_a.shape[0]
    scratch_f = np.empty((SCRATCH_F, n))
    scratch_i = np.empty((SCRATCH_I, n), dtype=np.int64)
    for r in range(poses.shape[0]):
        _scan_one(
            poses[r], mount, cos_a, sin_a, angle_min, inc, range_min, range_max,
            distg, res, gx0, gy0, faces, use_faces, stat_a, stat_b, stat_side,
            circ_xy, circ_r, circ_owner, dyn_a, dyn_b, dyn_owner, r if use_owner else -1,
            scratch_f, scratch_i, out[r],
        )


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
