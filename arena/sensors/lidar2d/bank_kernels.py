"""Rows kernels of :class:`~arena.sensors.lidar2d.LidarBank`: every due sensor of every world.

One *row* is one lidar carried by one robot (a global robot row) of one world. Each row is cast
by :func:`_scan_row`, which slices its world's tables and calls the single scan function
:func:`~arena.sensors.lidar2d.kernels._scan_one`; :func:`scan_rows` runs the due rows on the
calling thread and :func:`scan_rows_parallel` on numba's thread pool (``prange``). A row reads
only its own world's slices and writes only its own output range, so its ranges never depend on
the other rows, the number of worlds or the thread count.

Tables (built by :class:`~arena.sensors.lidar2d.bank.LidarBank`, all C-contiguous):

* rows ``(S,)``: ``row_robot`` (global robot row: pose and owner), ``row_world``, ``row_spec``;
  ``out_off`` ``(S + 1,)``: row ``s`` writes ``out[out_off[s]:out_off[s + 1]]``;
* specs ``(K, ...)``: ``beam_off`` ``(K + 1,)`` into ``cos_all``/``sin_all`` (beam directions in
  the sensor frame), ``spec_f`` ``(K, 7)`` ``[mount x m, mount y m, mount yaw rad, angle_min
  rad, increment rad (0: one beam), range_min m, range_max m]``;
* maps ``(G, ...)`` (one slot per grid object): ``map_i`` ``(G, 5)`` ``[distance offset,
  height, width, face offset, face count]`` into ``dist`` (flat float32 distance maps in cells)
  and ``faces`` ``(F, 4)``; ``map_f`` ``(G, 3)`` ``[resolution m, origin x m, origin y m]``;
  ``use_faces`` ``(G, K)``: cast the walls of map ``g`` as faces for spec ``k``;
* worlds ``(W, 3)`` ``world_i``: ``[map slot, static segment offset, static segment count]``
  into ``stat_a``/``stat_b`` ``(P, 2)`` and their back-face sides ``stat_side`` ``(P,)``
  (:func:`~arena.sensors.lidar2d.model.polygon_sides`);
* the dynamic scene (``circ_*``, ``seg_*``), per world by ``circ_off``/``seg_off``, owners being
  global robot rows.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from arena.sensors.lidar2d.kernels import _scan_one

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
I64 = NDArray[np.int64]
B1 = NDArray[np.bool_]

#: Codes of :func:`_scan_row` for a row it refused to cast.
BAD_SCENE = 1
BAD_POSE = 2


@njit(cache=True, fastmath=False)
def _scan_row(
    s: int, poses: F64, row_robot: I64, row_world: I64, row_spec: I64, out_off: I64,
    beam_off: I64, cos_all: F64, sin_all: F64, spec_f: F64,
    map_i: I64, map_f: F64, dist: F32, faces: F64, use_faces: B1,
    world_i: I64, stat_a: F64, stat_b: F64, stat_side: F64,
    circ_off: I64, circ_xy: F64, circ_r: F64, circ_owner: I64,
    seg_off: I64, seg_a: F64, seg_b: F64, seg_owner: I64,
    scratch_f: F64, scratch_i: I64, out: F64,
) -> int:
    """Row ``s``'s ranges into its slice of ``out`` (tables: see the module docstring).

    Returns:
        0, or without casting: :data:`BAD_SCENE` if the scene's slices of the row's world
        do not fit its arrays, :data:`BAD_POSE` if the robot's pose is not finite.
    """
    r = row_robot[s]
    w = row_world[s]
    k = row_spec[s]
    g = world_i[w, 0]
    d0 = map_i[g, 0]
    h = map_i[g, 1]
    wd = map_i[g, 2]
    f0 = map_i[g, 3]
    p0 = world_i[w, 1]
    p1 = p0 + world_i[w, 2]
    b0 = beam_off[k]
    b1 = beam_off[k + 1]
    c0 = circ_off[w]
    c1 = circ_off[w + 1]
    e0 = seg_off[w]
    e1 = seg_off[w + 1]
    # A bad offset would read outside the arrays (numba does not check bounds): refuse it.
    if not (
        0 <= c0 <= c1 <= circ_xy.shape[0] and c1 <= circ_r.shape[0]
        and c1 <= circ_owner.shape[0] and 0 <= e0 <= e1 <= seg_a.shape[0]
        and e1 <= seg_b.shape[0] and e1 <= seg_owner.shape[0]
    ):
        return BAD_SCENE
    if not (math.isfinite(poses[r, 0]) and math.isfinite(poses[r, 1])
            and math.isfinite(poses[r, 2])):
        return BAD_POSE
    _scan_one(
        poses[r], spec_f[k, 0:3], cos_all[b0:b1], sin_all[b0:b1], spec_f[k, 3], spec_f[k, 4],
        spec_f[k, 5], spec_f[k, 6],
        dist[d0 : d0 + h * wd].reshape((h, wd)), map_f[g, 0], map_f[g, 1], map_f[g, 2],
        faces[f0 : f0 + map_i[g, 4]], use_faces[g, k],
        stat_a[p0:p1], stat_b[p0:p1], stat_side[p0:p1],
        circ_xy[c0:c1], circ_r[c0:c1], circ_owner[c0:c1],
        seg_a[e0:e1], seg_b[e0:e1], seg_owner[e0:e1], r,
        scratch_f, scratch_i, out[out_off[s] : out_off[s + 1]],
    )
    return 0


@njit(cache=True, fastmath=False)
def scan_rows(
    rows: I64, poses: F64, row_robot: I64, row_world: I64, row_spec: I64, out_off: I64,
    beam_off: I64, cos_all: F64, sin_all: F64, spec_f: F64,
    map_i: I64, map_f: F64, dist: F32, faces: F64, use_faces: B1,
    world_i: I64, stat_a: F64, stat_b: F64, stat_side: F64,
    circ_off: I64, circ_xy: F64, circ_r: F64, circ_owner: I64,
    seg_off: I64, seg_a: F64, seg_b: F64, seg_owner: I64,
    scratch_f: F64, scratch_i: I64, out: F64,
) -> int:
    """Cast the sensor rows listed in ``rows`` on the calling thread (scratch ``[0]``).

    ``scratch_f`` ``(T, SCRATCH_F, B)`` and ``scratch_i`` ``(T, SCRATCH_I, B)`` are per-thread
    work arrays, ``B`` the most beams of any row. Returns the largest code of
    :func:`_scan_row` (0: every row cast).
    """
    worst = 0
    for j in range(rows.shape[0]):
        code = _scan_row(
            rows[j], poses, row_robot, row_world, row_spec, out_off, beam_off, cos_all, sin_all,
            spec_f, map_i, map_f, dist, faces, use_faces, world_i, stat_a, stat_b, stat_side,
            circ_off, circ_xy, circ_r, circ_owner, seg_off, seg_a, seg_b, seg_owner,
            scratch_f[0], scratch_i[0], out,
        )
        worst = max(worst, code)
    return worst


@njit(cache=True, fastmath=False, parallel=True, nogil=True)
def scan_rows_parallel(
    rows: I64, poses: F64, row_robot: I64, row_world: I64, row_spec: I64, out_off: I64,
    beam_off: I64, cos_all: F64, sin_all: F64, spec_f: F64,
    map_i: I64, map_f: F64, dist: F32, faces: F64, use_faces: B1,
    world_i: I64, stat_a: F64, stat_b: F64, stat_side: F64,
    circ_off: I64, circ_xy: F64, circ_r: F64, circ_owner: I64,
    seg_off: I64, seg_a: F64, seg_b: F64, seg_owner: I64,
    scratch_f: F64, scratch_i: I64, out: F64,
) -> int:
    """:func:`scan_rows` on numba's thread pool, each thread on its own scratch.

    The caller sets the schedule (``numba.set_parallel_chunksize``): rows differ in cost (a
    scan in a corridor ends sooner than one across a hall), so dynamic chunks balance them.
    """
    worst = 0
    for j in prange(rows.shape[0]):
        t = numba.get_thread_id()
        code = _scan_row(
            rows[j], poses, row_robot, row_world, row_spec, out_off, beam_off, cos_all, sin_all,
            spec_f, map_i, map_f, dist, faces, use_faces, world_i, stat_a, stat_b, stat_side,
            circ_off, circ_xy, circ_r, circ_owner, seg_off, seg_a, seg_b, seg_owner,
            scratch_f[t], scratch_i[t], out,
        )
        worst = max(worst, code)  # a prange reduction
    return worst
