"""A height map as 3-D geometry: a MuJoCo height field, or merged boxes (SDF, any exporter).

**Height field** (``WorldParams.terrain: hfield``, MJCF): one ``<hfield>`` asset whose samples
sit exactly on the height map's cell centres, spanning from the first to the last centre (the
outer half cell along the border is the floor plane, at z = 0). MuJoCo normalises the samples to
[0, 1] and scales them by ``size[2]``, so the geom sits at ``z = min height`` with ``size[2] =
max - min``: at every cell centre the surface is the map's height (to float32 precision),
between centres MuJoCo's two triangles per cell interpolate it. MJCF lists the elevation rows
from the highest y down (image order), the reverse of the map's rows.

**Boxes** (``terrain: boxes``, and always in SDF, whose height maps need an image file): every
cell a column from z = 0 to its height, runs of equal height along a row merged, then equal runs
of consecutive rows merged. Exact at every cell centre, flat-topped cells (a ramp becomes a
staircase of one cell per tread).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from arena.core.errors import MapError
from arena.maps.terrain import HeightMap
from arena.sim.mujoco.scene import Body, Geom

TERRAIN_NAME = "terrain"
"""Name of the height field asset, its geom and the boxes' body."""
BASE_DEPTH = 0.05
"""m, thickness of the height field's solid base below its lowest point."""


@dataclass(frozen=True)
class HeightField:
    """A MuJoCo height field: ``nrow × ncol`` samples over ``±size[0] × ±size[1]`` about ``pos``.

    Attributes:
        name: asset and geom name.
        nrow: rows (y), ``≥ 2``.
        ncol: columns (x), ``≥ 2``.
        size: MuJoCo's ``(radius_x, radius_y, elevation_z, base_z)`` (m).
        pos: geom position ``(x, y, z)``: the centre of the samples, z of the lowest one (m).
        elevation: ``nrow · ncol`` heights above ``pos[2]`` (m), rows from the lowest y up.
        material: material name.
    """

    name: str
    nrow: int
    ncol: int
    size: tuple[float, float, float, float]
    pos: tuple[float, float, float]
    elevation: tuple[float, ...]
    material: str = "terrain"

    def mjcf_elevation(self) -> list[float]:
        """The samples in MJCF's order: rows from the highest y down."""
        rows = [self.elevation[r * self.ncol:(r + 1) * self.ncol] for r in range(self.nrow)]
        return [v for row in reversed(rows) for v in row]

    def height_map(self) -> HeightMap:
        """The height map the field was made from (cell centres at the samples)."""
        res = 2 * self.size[0] / (self.ncol - 1)
        h = np.asarray(self.elevation, dtype=np.float64).reshape(self.nrow, self.ncol)
        h = h + self.pos[2]
        origin = (self.pos[0] - self.size[0] - res / 2, self.pos[1] - self.size[1] - res / 2)
        return HeightMap(h, res, origin)


def height_field(heights: HeightMap, *, name: str = TERRAIN_NAME) -> HeightField | None:
    """The height field of ``heights``, or ``None`` for a map that is level at z = 0.

    A level map above z = 0 gets a field whose samples are all at its top (MuJoCo normalises a
    constant field to 0, so the geom is lifted to the height instead).
    """
    h = heights.heights
    lo, hi = float(h.min()), float(h.max())
    if hi == 0.0:
        return None
    rows, cols = heights.shape
    res = heights.resolution
    ox, oy = heights.origin
    cx = ox + (0.5 + (cols - 1) / 2) * res
    cy = oy + (0.5 + (rows - 1) / 2) * res
    span = hi - lo
    if span == 0.0:  # level above the floor: all samples at 0, the geom at the top
        elev = (0.0,) * (rows * cols)
        size = ((cols - 1) * res / 2, (rows - 1) * res / 2, 1e-6, lo + BASE_DEPTH)
        return HeightField(name, rows, cols, size, (cx, cy, lo), elev)
    elev = tuple(float(v) for v in (h - lo).ravel())
    size = ((cols - 1) * res / 2, (rows - 1) * res / 2, span, BASE_DEPTH)
    return HeightField(name, rows, cols, size, (cx, cy, lo), elev)


def terrain_boxes(heights: HeightMap, *, max_boxes: int = 20_000,
                  material: str = "terrain") -> Body | None:
    """One static body ``terrain`` of boxes from z = 0 up to each cell's height.

    ``None`` for a map level at 0.

    Raises:
        MapError: more than ``max_boxes`` boxes (a rough map: use the height field).
    """
    h = heights.heights
    res = heights.resolution
    ox, oy = heights.origin
    rects: list[tuple[int, int, int, int, float]] = []  # r0, c0, r1, c1 (exclusive), height
    open_: dict[tuple[int, int, float], int] = {}  # (c0, c1, h) -> start row of an open box
    for r in range(h.shape[0] + 1):
        runs: set[tuple[int, int, float]] = set()
        if r < h.shape[0]:
            row = h[r]
            cuts = np.flatnonzero(np.diff(row) != 0.0) + 1
            starts = np.concatenate([[0], cuts])
            ends = np.concatenate([cuts, [len(row)]])
            runs = {(int(a), int(b), float(row[a])) for a, b in zip(starts, ends, strict=True)
                    if row[a] > 0.0}
        for key in [k for k in open_ if k not in runs]:  # runs that stop here close their box
            c0, c1, z = key
            rects.append((open_.pop(key), c0, r, c1, z))
        for key in runs:
            open_.setdefault(key, r)
        if len(rects) > max_boxes:
            break
    if len(rects) > max_boxes:
        raise MapError(f"the height map needs more than {max_boxes:,} terrain boxes; build it as "
                       "a height field (WorldParams.terrain: hfield)")
    if not rects:
        return None
    rects.sort()
    geoms = tuple(
        Geom(f"{TERRAIN_NAME}/{k}", "box", ((c1 - c0) * res / 2, (r1 - r0) * res / 2, z / 2),
             (ox + (c0 + c1) * res / 2, oy + (r0 + r1) * res / 2, z / 2), material)
        for k, (r0, c0, r1, c1, z) in enumerate(rects)
    )
    return Body(TERRAIN_NAME, "terrain", (0.0, 0.0, 0.0), 0.0, geoms)
