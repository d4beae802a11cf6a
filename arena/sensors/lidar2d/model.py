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
  a segment hits it at ``t = 0`` with every beam. Static edges that close a polygon (an
  obstacle's footprint) are seen from outside only: the edges facing away from the sensor are
  not tested (:func:`polygon_sides`; the nearest hit is always on a facing edge, so the ranges
  are unchanged, at about half the cost), and a sensor inside an obstacle's polygon does not
  see that obstacle.

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

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import SimulationError
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import GridMemo
from arena.sensors.lidar2d.kernels import _add_noise, _scan_kernel
from arena.sensors.spec import LidarSpec

FloatArray = NDArray[np.float64]


#: A map's walls are cast as faces (:func:`wall_faces`) while it has at most this many faces per
#: beam; beyond that the per-face set-up costs more than walking the grid.
FACES_PER_BEAM = 2.0


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


def polygon_sides(a: FloatArray, b: FloatArray) -> FloatArray:
    """``(s,)`` back-face side of each segment ``a[k] → b[k]`` (m): ``+1``, ``-1`` or ``0``.

    Consecutive segments chained end to start (``b[k] == a[k + 1]``, exactly) that return to
    their first point form a closed polygon; its edges get ``+1`` when it runs
    counter-clockwise (shoelace area > 0), ``-1`` when clockwise. Other segments (open chains,
    degenerate polygons) get ``0``: never culled. A lidar skips an edge whose polygon's inner
    side holds the sensor (:func:`~arena.sensors.lidar2d.kernels._segments_into`): a beam from
    outside first meets a polygon on an edge it crosses inwards, whose outer side holds the
    sensor. So ranges are those of testing every edge, for a sensor outside the polygons (a
    sensor inside an obstacle's polygon does not see that obstacle).
    """
    s = a.shape[0]
    side = np.zeros(s)
    linked = np.all(b[:-1] == a[1:], axis=1).tolist() if s > 1 else []
    start = 0
    while start < s:
        end = start  # extend the chain until it closes or breaks
        while (end + 1 < s and linked[end]
               and not (b[end, 0] == a[start, 0] and b[end, 1] == a[start, 1])):
            end += 1
        closed = b[end, 0] == a[start, 0] and b[end, 1] == a[start, 1]
        if closed and end - start >= 2:
            pa, pb = a[start : end + 1], b[start : end + 1]
            area = float(np.sum(pa[:, 0] * pb[:, 1] - pa[:, 1] * pb[:, 0]))
            side[start : end + 1] = np.sign(area)
        start = end + 1
    return side


def cell_distances(grid: OccupancyGrid) -> NDArray[np.float32]:
    """``grid``'s distance map in cells, as the scan kernels read it: ``(H, W)`` float32.

    float32 halves the cache traffic; the values are capped so that an empty map's ``inf``
    becomes one jump out of the map instead of an ``inf`` beam parameter. A new writeable array.
    """
    cap = float(grid.width + grid.height + 4)
    d = np.minimum(np.asarray(grid.distance) / grid.resolution, cap)
    return np.ascontiguousarray(d, dtype=np.float32)


def beam_tables(spec: LidarSpec) -> tuple[FloatArray, FloatArray, float]:
    """Beam directions of ``spec`` in the sensor frame, as the scan kernels read them.

    Returns:
        ``(cos, sin, increment)``: ``(num_beams,)`` cosines and sines of the beam angles and the
        angle between beams (rad); one beam (or a zero span) has no meaningful increment and
        gets 0, which makes the kernels test every beam against every object.
    """
    angles = spec.angles()
    inc = float(spec.angle_increment) if spec.num_beams > 1 else 0.0
    return np.cos(angles), np.sin(angles), inc


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
        self._cos, self._sin, self._inc = beam_tables(spec)
        self._mount = np.asarray(spec.mount, dtype=np.float64)
        self._grid: OccupancyGrid | None = None
        self._distg = np.zeros((1, 1), dtype=np.float32)
        self._faces = np.zeros((0, 4))
        self._use_faces = False
        self._seg_a = _EMPTY_PTS
        self._seg_b = _EMPTY_PTS
        self._seg_side = np.zeros(0)
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
            self._distg = cell_distances(grid)
            # a writeable copy: numba compiles another specialisation for read-only arrays
            self._faces = wall_faces(grid).copy()
            self._use_faces = use_wall_faces(self._faces, self.spec.num_beams)
            self._grid = grid
        self._seg_a, self._seg_b = a, b
        self._seg_side = polygon_sides(a, b)

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
            cxy, cr, c_own, self._seg_a, self._seg_b, self._seg_side, da, db, d_own,
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
        a, b, side = self._seg_a, self._seg_b, self._seg_side
        self._grid = OccupancyGrid.empty(0.5, 0.5, 0.1)
        self._distg = np.zeros((5, 5), dtype=np.float32)
        self._distg[1:4, 1:4] = 1.0
        self._faces = _compute_faces(self._distg == 0.0).copy()
        self._seg_a = np.array([[0.1, 0.35]])
        self._seg_b = np.array([[0.2, 0.35]])
        self._seg_side = np.zeros(1)
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
            self._seg_a, self._seg_b, self._seg_side = a, b, side
