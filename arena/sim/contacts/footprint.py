"""The shapes the contact tests work on: robot footprints and the static obstacles' index.

A footprint is a circle (``polygon is None``) or a convex polygon in the robot frame; non-convex
footprints are replaced by their convex hull (conservative), rectangles stay exact.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from arena.core.geometry import bounding_radius, convex_hull, transform_points
from arena.scene.state import StaticWorld

_REACH_MARGIN = 1e-6
"""m: placed vertices are within rounding (~1e-15 m) of their exact places."""

_NO_POLYGON = np.zeros((0, 2))
_NO_POLYGON.setflags(write=False)


@dataclass(frozen=True, eq=False)
class Footprint:
    """A robot footprint prepared for collision tests.

    Attributes:
        polygon: ``(k, 2)`` convex polygon in the robot frame (m), or ``None`` for a circle.
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
    def body(self) -> NDArray[np.float64]:
        """``(k, 2)`` C-contiguous float64 polygon (m) for the kernels; ``(0, 2)`` for a circle."""
        if self.polygon is None:
            return _NO_POLYGON
        return np.ascontiguousarray(self.polygon, dtype=np.float64)

    @cached_property
    def reach(self) -> float:
        """Radius (m) of a circle about the robot origin that surely holds the footprint.

        ``radius``, or for a polygon the larger of it and its farthest vertex, plus a margin
        (:data:`_REACH_MARGIN`) far above the rounding of placing the polygon at a pose.
        """
        if self.polygon is None:
            return self.radius
        return max(self.radius, bounding_radius(self.polygon)) + _REACH_MARGIN


@dataclass(frozen=True, eq=False)
class ObstacleIndex:
    """The static obstacles with bounding circles for fast rejection, packed for the kernels.

    Attributes:
        centers: ``(n, 2)`` m, each obstacle's vertex mean.
        radii: ``(n,)`` m, the farthest vertex from its centre.
        polygons: the ``n`` obstacle polygons ``(k_i, 2)`` m, as in ``StaticWorld.obstacles``.
        vstart: ``(n + 1,)`` int64, obstacle ``i``'s vertices are ``verts[vstart[i]:vstart[i+1]]``.
        verts: ``(sum k_i, 2)`` m, every polygon's vertices one after the other.
    """

    centers: NDArray[np.float64]
    radii: NDArray[np.float64]
    polygons: tuple[NDArray[np.float64], ...]
    vstart: NDArray[np.int64]
    verts: NDArray[np.float64]

    @classmethod
    def build(cls, world: StaticWorld) -> ObstacleIndex:
        """Index the obstacles of ``world``."""
        polys = tuple(ob.polygon for ob in world.obstacles)
        if not polys:
            return cls(np.zeros((0, 2)), np.zeros(0), (), np.zeros(1, np.int64), np.zeros((0, 2)))
        centers = np.array([p.mean(axis=0) for p in polys])
        radii = np.array(
            [np.linalg.norm(p - c, axis=1).max() for p, c in zip(polys, centers, strict=True)]
        )
        vstart = np.zeros(len(polys) + 1, dtype=np.int64)
        vstart[1:] = np.cumsum([len(p) for p in polys])
        verts = np.ascontiguousarray(np.concatenate(polys), dtype=np.float64)
        return cls(centers, radii, polys, vstart, verts)
