"""Contact tests between robot footprints and the world (grid walls, obstacles, agents, robots).

A footprint is a circle (``polygon is None``) or a convex polygon in the robot frame; non-convex
footprints are replaced by their convex hull (conservative). Every test first rejects with a
bounding circle, so the common "nothing near" case costs a few array look-ups.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.core.geometry import (
    bounding_radius,
    circles_overlap_polygon,
    convex_hull,
    convex_polygon_overlaps_squares,
    polygons_overlap,
    transform_points,
)
from arena.maps.grid import OccupancyGrid
from arena.scene.state import StaticWorld

SQRT2 = math.sqrt(2.0)


@dataclass(frozen=True, eq=False)
class Footprint:
    """A robot footprint prepared for collision tests.

    Attributes:
        polygon: ``(k, 2)`` convex polygon in the robot frame, or ``None`` for a circle.
        radius: circle radius, or the polygon's circumscribed radius about the robot origin (m).
    """

    polygon: NDArray[np.float64] | None
    radius: float

    @classmethod
    def make(cls, polygon: NDArray[np.float64] | None, radius: float) -> Footprint:
        """Build from a preset footprint (polygon in the robot frame, or ``None`` and a radius)."""
        if polygon is None:
            return cls(None, float(radius))
        hull = convex_hull(polygon)
        return cls(hull, bounding_radius(hull))

    def world_polygon(self, pose: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """``(k, 2)`` polygon at ``pose``, or ``None`` for a circle."""
        return None if self.polygon is None else transform_points(self.polygon, pose)

    @cached_property
    def reach(self) -> float:
        """Radius (m) of a circle about the robot origin that surely holds the footprint.

        ``radius``, or for a polygon the larger of it and its farthest vertex, plus a margin
        (:data:`_REACH_MARGIN`) far above the rounding of placing the polygon at a pose.
        """
        if self.polygon is None:
            return self.radius
        return max(self.radius, bounding_radius(self.polygon)) + _REACH_MARGIN


_REACH_MARGIN = 1e-6
"""m: placed vertices are within rounding (~1e-15 m) of their exact places."""


def hits_grid(
    grid: OccupancyGrid,
    fp: Footprint,
    pose: NDArray[np.float64],
    *,
    bounds: tuple[float, float, float, float] | None = None,
) -> bool:
    """Whether the footprint at ``pose`` overlaps a blocking cell or leaves the map.

    ``bounds``: ``grid.bounds`` (m) when the caller has it at hand (a simulator testing every
    step against the same grid), to skip recomputing it.
    """
    x, y = float(pose[0]), float(pose[1])
    xmin, ymin, xmax, ymax = grid.bounds if bounds is None else bounds
    if not (xmin <= x < xmax and ymin <= y < ymax):
        return True
    r = fp.radius
    if x - r < xmin or y - r < ymin or x + r > xmax or y + r > ymax:
        # Near the border: only a real overhang counts.
        pts = fp.world_polygon(pose)
        if pts is None or (
            pts[:, 0].min() < xmin
            or pts[:, 1].min() < ymin
            or pts[:, 0].max() > xmax
            or pts[:, 1].max() > ymax
        ):
            return True
    res = grid.resolution
    col = int((x - grid.origin[0]) // res)
    row = int((y - grid.origin[1]) // res)
    # No blocking cell square lies nearer than EDT(centre cell) - res*sqrt2 (two half diagonals).
    if grid.distance[row, col] - res * SQRT2 >= r:
        return False
    k = math.ceil(r / res) + 1
    r0, r1 = max(row - k, 0), min(row + k + 1, grid.height)
    c0, c1 = max(col - k, 0), min(col + k + 1, grid.width)
    ox, oy = grid.origin
    # A circle's exact test; for a polygon, a square that misses the circle holding it misses
    # the polygon too, so the separating-axis tests run only when some square comes that near.
    near = _squares_within(grid.occupied, r0, r1, c0, c1, ox, oy, res, x, y, fp.reach)
    if fp.polygon is None or not near:
        return near
    rows, cols = np.nonzero(grid.occupied[r0:r1, c0:c1])
    cx = ox + (cols + c0 + 0.5) * res
    cy = oy + (rows + r0 + 0.5) * res
    half = 0.5 * res
    poly = transform_points(fp.polygon, pose)
    return bool(np.any(convex_polygon_overlaps_squares(poly, np.stack([cx, cy], axis=1), half)))


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
    ``radius`` (m) about ``(x, y)`` (m): the clamped-gap test ``dx² + dy² < radius²`` with
    :func:`hits_grid`'s former NumPy expressions, element by element (the same bits).
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


@dataclass(frozen=True, eq=False)
class ObstacleIndex:
    """Bounding circles of the static obstacles, for fast rejection."""

    centers: NDArray[np.float64]
    radii: NDArray[np.float64]
    polygons: tuple[NDArray[np.float64], ...]

    @classmethod
    def build(cls, world: StaticWorld) -> ObstacleIndex:
        """Index the obstacles of ``world``."""
        polys = tuple(ob.polygon for ob in world.obstacles)
        if not polys:
            return cls(np.zeros((0, 2)), np.zeros(0), ())
        centers = np.array([p.mean(axis=0) for p in polys])
        radii = np.array(
            [np.linalg.norm(p - c, axis=1).max() for p, c in zip(polys, centers, strict=True)]
        )
        return cls(centers, radii, polys)


def first_obstacle_hit(index: ObstacleIndex, fp: Footprint, pose: NDArray[np.float64]) -> int:
    """Index of one obstacle the footprint at ``pose`` overlaps, or -1."""
    if not index.polygons:
        return -1
    near = _near_circles(index.centers, index.radii, float(pose[0]), float(pose[1]), fp.radius)
    if near.size == 0:
        return -1
    poly = fp.world_polygon(pose)
    for j in near:  # only the few obstacles whose bounding circles touch
        ob = index.polygons[j]
        if poly is None:
            if circles_overlap_polygon(pose[None, :2], [fp.radius], ob)[0]:
                return int(j)
        elif polygons_overlap(poly, ob):
            return int(j)
    return -1


@njit(cache=True)
def _near_circles(
    centers: NDArray[np.float64], radii: NDArray[np.float64], x: float, y: float, radius: float
) -> NDArray[np.int64]:
    """Indices (ascending) of the circles ``(k, 2)``, ``(k,)`` within ``radius`` of ``(x, y)``.

    ``flatnonzero(hypot(c - p) <= radii + radius)`` in one compiled call (numba's ``hypot`` is
    the C library's, as numpy's): the rejection test runs once per robot and step.
    """
    out = np.empty(centers.shape[0], dtype=np.int64)
    k = 0
    for j in range(centers.shape[0]):
        if math.hypot(centers[j, 0] - x, centers[j, 1] - y) <= radii[j] + radius:
            out[k] = j
            k += 1
    return out[:k]


def first_agent_hit(
    fp: Footprint,
    pose: NDArray[np.float64],
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
) -> int:
    """Index of the nearest pedestrian circle the footprint overlaps, or -1."""
    if positions.shape[0] == 0:
        return -1
    body = _EMPTY_POLY if fp.polygon is None else fp.polygon
    pose = np.asarray(pose, dtype=np.float64)
    return int(_agent_hit_kernel(pose, float(fp.radius), body, positions, radii))


@njit(cache=True)
def _place(polygon: NDArray[np.float64], pose: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`transform_points` for one pose, compiled (hot path: once per robot and step)."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    out = np.empty_like(polygon)
    for k in range(polygon.shape[0]):
        out[k, 0] = pose[0] + c * polygon[k, 0] - s * polygon[k, 1]
        out[k, 1] = pose[1] + s * polygon[k, 0] + c * polygon[k, 1]
    return out


_EMPTY_POLY = np.zeros((0, 2))


@njit(cache=True)
def _agent_hit_kernel(
    pose: NDArray[np.float64],
    radius: float,
    body: NDArray[np.float64],
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
) -> int:
    """Nearest circle overlapping a circle (``body`` empty) or a convex polygon, else -1.

    ``pose`` ``(3,)`` ``(x, y, θ)`` (m, rad); ``radius`` the footprint's bounding radius (m);
    ``body`` ``(k, 2)`` the polygon in the robot frame, placed here (:func:`_place`, one call
    per robot and step); ``positions`` ``(n, 2)`` m and ``radii`` ``(n,)`` m the circles.

    A circle overlaps a convex polygon when its centre is inside, or when it comes within its
    radius of an edge (touching counts, as in :func:`circles_overlap_polygon`).
    """
    x, y = pose[0], pose[1]
    poly = _place(body, pose)
    best, best_d = -1, np.inf
    k = poly.shape[0]
    for i in range(positions.shape[0]):
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


def footprints_overlap(
    fa: Footprint, pa: NDArray[np.float64], fb: Footprint, pb: NDArray[np.float64]
) -> bool:
    """Whether two robot footprints overlap."""
    if math.hypot(pa[0] - pb[0], pa[1] - pb[1]) >= fa.radius + fb.radius:
        return False
    if fa.polygon is None and fb.polygon is None:
        return True
    if fa.polygon is None:
        return bool(circles_overlap_polygon(pa[None, :2], [fa.radius], fb.world_polygon(pb))[0])
    if fb.polygon is None:
        return bool(circles_overlap_polygon(pb[None, :2], [fb.radius], fa.world_polygon(pa))[0])
    return polygons_overlap(fa.world_polygon(pa), fb.world_polygon(pb))
