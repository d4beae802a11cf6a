"""2.5-D terrain: a height map on the occupancy grid's cells, and a course generator.

A :class:`HeightMap` holds one ground height (m, z up, ``≥ 0``) per cell centre of a grid,
row 0 at the origin (lowest y) like :class:`~arena.maps.grid.OccupancyGrid`. Between centres
the ground is the bilinear interpolation of the four nearest centres (:meth:`HeightMap.at`);
outside the outermost centres the edge value holds. Saved as ``heights.npz`` beside a world's
``map.yaml`` (:func:`save_terrain_world`).

:func:`terrain_course` draws a map with height variation for legged-robot planners
(ArtPlanner, :mod:`arena.learn.planners.artplanner`): a plateau with cliffs on its sides,
a gentle ramp up one side and a too-steep slope up the opposite one, a low step (passable), a
high step (not), and a rough patch. The 2-D occupancy grid holds only the border walls: the
height variation is no obstacle in 2-D, a planner decides whether it can be walked.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator
from scipy import ndimage

from arena.core.errors import MapError
from arena.maps.grid import MAX_CELLS, OccupancyGrid, check_grid_size
from arena.maps.io import load_map, save_map

MAX_HEIGHT = 100.0
"""m; largest ground height accepted (a larger one is a unit mistake: mm for m)."""
HEIGHTS_FILE = "heights.npz"
"""File name of a world's height map, beside its ``map.yaml``."""
_FORMAT = 1


@dataclass(frozen=True, eq=False)
class HeightMap:
    """Ground heights on a grid's cell centres.

    Attributes:
        heights: ``(H, W)`` float64 ground height (m, ``0 ≤ h ≤`` :data:`MAX_HEIGHT`) at each
            cell centre; row 0 at ``origin`` (lowest y).
        resolution: cell edge length (m).
        origin: world position ``(x, y)`` of the lower-left corner of cell ``(0, 0)`` (m).
    """

    heights: NDArray[np.float64]
    resolution: float
    origin: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        h = np.array(self.heights, dtype=np.float64, order="C", copy=True)
        if h.ndim != 2 or min(h.shape) < 2:
            raise MapError(f"a height map must be a 2-D array of at least 2 x 2 cells, got "
                           f"shape {h.shape}")
        if h.size > MAX_CELLS:
            raise MapError(f"a height map has at most {MAX_CELLS:,} cells, got {h.shape}")
        if not np.all(np.isfinite(h)):
            raise MapError("height map: every height must be a finite number of metres")
        lo, hi = float(h.min()), float(h.max())
        if lo < 0 or hi > MAX_HEIGHT:
            raise MapError(f"height map: heights must lie in [0, {MAX_HEIGHT:g}] m (the ground is "
                           f"z = 0 and terrain rises from it), got [{lo:.3g}, {hi:.3g}]")
        if not (np.isfinite(self.resolution) and self.resolution > 0):
            raise MapError(f"height map: resolution must be > 0 m, got {self.resolution!r}")
        if len(self.origin) != 2 or not np.all(np.isfinite(self.origin)):
            raise MapError(f"height map: origin must be two finite numbers (m), got "
                           f"{self.origin!r}")
        h.setflags(write=False)
        object.__setattr__(self, "heights", h)
        object.__setattr__(self, "resolution", float(self.resolution))
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))

    @classmethod
    def flat(cls, grid: OccupancyGrid, height: float = 0.0) -> HeightMap:
        """A level height map over ``grid``'s cells at ``height`` (m)."""
        return cls(np.full(grid.data.shape, float(height)), grid.resolution, grid.origin)

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, cols)``."""
        return (int(self.heights.shape[0]), int(self.heights.shape[1]))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the covered area (m)."""
        rows, cols = self.shape
        ox, oy = self.origin
        return ox, oy, ox + cols * self.resolution, oy + rows * self.resolution

    @property
    def is_flat(self) -> bool:
        """Whether every cell has the same height."""
        return bool(np.ptp(self.heights) == 0.0)

    def at(self, xy: ArrayLike) -> NDArray[np.float64]:
        """Ground height (m) at world points ``(..., 2)``: bilinear between cell centres.

        Points beyond the outermost centres (also off the map) take the nearest edge value.
        """
        p = np.asarray(xy, dtype=np.float64)
        rows, cols = self.shape
        # Continuous index of the point among cell centres (centre of cell k sits at k).
        u = np.clip((p[..., 0] - self.origin[0]) / self.resolution - 0.5, 0.0, cols - 1.0)
        v = np.clip((p[..., 1] - self.origin[1]) / self.resolution - 0.5, 0.0, rows - 1.0)
        c0 = np.minimum(np.floor(u).astype(np.int64), cols - 2)
        r0 = np.minimum(np.floor(v).astype(np.int64), rows - 2)
        fu, fv = u - c0, v - r0
        h = self.heights
        bottom = h[r0, c0] * (1 - fu) + h[r0, c0 + 1] * fu
        top = h[r0 + 1, c0] * (1 - fu) + h[r0 + 1, c0 + 1] * fu
        return np.asarray(bottom * (1 - fv) + top * fv, dtype=np.float64)

    def check_covers(self, grid: OccupancyGrid, *, what: str = "height map") -> None:
        """Raise a one-line :class:`MapError` unless this map covers ``grid``'s extent (1 mm)."""
        a, b = self.bounds, grid.bounds
        inside = a[0] <= b[0] + 1e-3 and a[1] <= b[1] + 1e-3 and a[2] >= b[2] - 1e-3 \
            and a[3] >= b[3] - 1e-3
        if not inside:
            raise MapError(
                f"the {what} covers [{a[0]:.2f}, {a[2]:.2f}] x [{a[1]:.2f}, {a[3]:.2f}] m, not the "
                f"map's [{b[0]:.2f}, {b[2]:.2f}] x [{b[1]:.2f}, {b[3]:.2f}] m"
            )

    def save(self, path: str | Path) -> Path:
        """Write ``heights`` (float64), ``resolution`` and ``origin`` to a compressed ``.npz``."""
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        meta = json.dumps({"format": _FORMAT, "resolution": self.resolution,
                           "origin": list(self.origin)})
        with out.open("wb") as f:  # np.savez would append .npz to a name without it
            np.savez_compressed(f, heights=self.heights, meta=np.array(meta))
        return out

    @classmethod
    def load(cls, path: str | Path) -> HeightMap:
        """Read a file written by :meth:`save`.

        Raises:
            MapError: missing, unreadable or not a height map file (one line naming it).
        """
        p = Path(path)
        if not p.is_file():
            raise MapError(f"no height map file {str(p)!r} (write one with HeightMap.save or "
                           "arena.maps.terrain.save_terrain_world)")
        try:
            with np.load(p, allow_pickle=False) as z:
                heights = np.asarray(z["heights"], dtype=np.float64)
                meta = json.loads(str(z["meta"]))
            if meta.get("format") != _FORMAT:
                raise ValueError(f"format {meta.get('format')!r}, expected {_FORMAT}")
            res, origin = float(meta["resolution"]), tuple(meta["origin"])
        except (OSError, ValueError, KeyError, TypeError) as e:
            raise MapError(f"{p}: not a height map file ({e})") from None
        return cls(heights, res, (float(origin[0]), float(origin[1])))


# -- the course generator ------------------------------------------------------------------------


class TerrainCourseParams(BaseModel):
    """Parameters of :func:`terrain_course` (m, degrees where named ``_deg``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    width: float = Field(20.0, gt=0, description="m, map width")
    height: float = Field(20.0, gt=0, description="m, map height")
    resolution: float = Field(0.1, gt=0, description="m per cell")
    plateau_height: float = Field(0.5, gt=0, le=5, description="m, height of the plateau")
    plateau_size: float = Field(5.0, gt=0, description="m, side of the square plateau")
    ramp_slope_deg: float = Field(12.0, gt=0, lt=60, description="deg, the walkable ramp")
    steep_slope_deg: float = Field(40.0, gt=0, lt=80,
                                   description="deg, the slope up the opposite side (too steep)")
    ramp_width: float = Field(2.0, gt=0, description="m, width of the ramp and the steep slope")
    low_step: float = Field(0.08, ge=0, le=5, description="m, rise of the passable step")
    high_step: float = Field(0.35, ge=0, le=5, description="m, rise of the impassable step")
    step_size: float = Field(3.0, gt=0, description="m, side of each step block")
    rough_size: float = Field(3.0, gt=0, description="m, side of the rough patch")
    rough_std: float = Field(0.06, ge=0, le=1, description="m, height noise of the rough patch")
    max_tries: int = Field(200, ge=1, le=10_000, description="placements tried per feature")

    @model_validator(mode="after")
    def _fits(self) -> TerrainCourseParams:
        try:
            check_grid_size(self.width, self.height, self.resolution)
        except MapError as e:
            raise ValueError(str(e)) from None
        return self


@dataclass(frozen=True, eq=False)
class TerrainWorld:
    """A generated course: the 2-D grid (border walls), its heights and where each part lies.

    ``features`` maps a part (``plateau``, ``ramp``, ``steep``, ``low_step``, ``high_step``,
    ``rough``) to its axis-aligned extent ``(x0, y0, x1, y1)`` (m).
    """

    grid: OccupancyGrid
    heights: HeightMap
    features: dict[str, tuple[float, float, float, float]]


Rect = tuple[float, float, float, float]


def _overlaps(a: Rect, b: Rect, gap: float) -> bool:
    return not (a[2] + gap <= b[0] or b[2] + gap <= a[0] or a[3] + gap <= b[1]
                or b[3] + gap <= a[1])


def _slope_rect(plateau: Rect, side: int, length: float, width: float) -> Rect:
    """The rectangle of a slope of ``length`` leaving ``plateau`` on ``side``, centred on it.

    Sides: 0 +x, 1 +y, 2 -x, 3 -y.
    """
    x0, y0, x1, y1 = plateau
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    if side == 0:
        return (x1, cy - width / 2, x1 + length, cy + width / 2)
    if side == 1:
        return (cx - width / 2, y1, cx + width / 2, y1 + length)
    if side == 2:
        return (x0 - length, cy - width / 2, x0, cy + width / 2)
    return (cx - width / 2, y0 - length, cx + width / 2, y0)


def _slope_heights(xs: NDArray[np.float64], ys: NDArray[np.float64], rect: Rect, side: int,
                   top: float) -> NDArray[np.float64]:
    """Heights of a slope over ``rect`` falling from ``top`` at the plateau to 0 outward."""
    x0, y0, x1, y1 = rect
    if side == 0:
        t = (x1 - xs) / (x1 - x0)
    elif side == 1:
        t = (y1 - ys) / (y1 - y0)
    elif side == 2:
        t = (xs - x0) / (x1 - x0)
    else:
        t = (ys - y0) / (y1 - y0)
    return np.asarray(top * np.clip(t, 0.0, 1.0), dtype=np.float64)


def terrain_course(params: TerrainCourseParams | None, rng: np.random.Generator) -> TerrainWorld:
    """Draw a terrain course (see the module docstring); every draw comes from ``rng``.

    The plateau is placed first, with its ramp on a random side and the steep slope on the
    opposite one; then the two steps and the rough patch, each at least 1 m from the others and
    from the border.

    Raises:
        MapError: a part cannot be placed within ``max_tries`` draws (a map too small for them).
    """
    p = params if params is not None else TerrainCourseParams()
    grid = OccupancyGrid.empty(p.width, p.height, p.resolution)
    rows, cols = grid.data.shape
    xs = (np.arange(cols) + 0.5) * p.resolution
    ys = (np.arange(rows) + 0.5) * p.resolution
    gx, gy = np.meshgrid(xs, ys)
    w, h = grid.size_m
    margin = 1.0
    placed: dict[str, Rect] = {}

    def place(name: str, sx: float, sy: float, extra: Rect = (0.0, 0.0, 0.0, 0.0)) -> Rect:
        """A free ``sx × sy`` rectangle; ``extra`` grows the clearance zone (m each side)."""
        for _ in range(p.max_tries):
            x0 = rng.uniform(margin + extra[0], w - margin - extra[2] - sx)
            y0 = rng.uniform(margin + extra[1], h - margin - extra[3] - sy)
            rect = (float(x0), float(y0), float(x0 + sx), float(y0 + sy))
            zone = (rect[0] - extra[0], rect[1] - extra[1], rect[2] + extra[2], rect[3] + extra[3])
            if all(not _overlaps(zone, r, margin) for r in placed.values()):
                return rect
        raise MapError(f"terrain course: no room for the {name} on a {w:g} x {h:g} m map after "
                       f"{p.max_tries} tries (a larger map or smaller parts)")

    heights = np.zeros((rows, cols))
    top = p.plateau_height
    ramp_len = top / math.tan(math.radians(p.ramp_slope_deg))
    steep_len = top / math.tan(math.radians(p.steep_slope_deg))
    if p.width - 2 * margin < p.plateau_size + ramp_len + steep_len \
            or p.height - 2 * margin < p.plateau_size:
        raise MapError(f"terrain course: a {p.plateau_size:g} m plateau with a {ramp_len:.1f} m "
                       f"ramp and a {steep_len:.1f} m slope does not fit a {w:g} x {h:g} m map")
    side = int(rng.integers(4))
    along_x = side in (0, 2)
    lo, hi = (ramp_len, steep_len) if side in (2, 3) else (steep_len, ramp_len)
    extra = (lo, 0.0, hi, 0.0) if along_x else (0.0, lo, 0.0, hi)
    plateau = place("plateau", p.plateau_size, p.plateau_size, extra)
    ramp = _slope_rect(plateau, side, ramp_len, p.ramp_width)
    steep = _slope_rect(plateau, (side + 2) % 4, steep_len, p.ramp_width)
    # The plateau's zone already holds both slopes; keep them in ``placed`` for the report.
    placed["plateau"] = (min(plateau[0], ramp[0], steep[0]), min(plateau[1], ramp[1], steep[1]),
                         max(plateau[2], ramp[2], steep[2]), max(plateau[3], ramp[3], steep[3]))
    features: dict[str, Rect] = {"plateau": plateau, "ramp": ramp, "steep": steep}

    def inside(rect: Rect) -> NDArray[np.bool_]:
        return np.asarray((gx >= rect[0]) & (gx < rect[2]) & (gy >= rect[1]) & (gy < rect[3]))

    for rect, sd in ((ramp, side), (steep, (side + 2) % 4)):
        m = inside(rect)
        heights[m] = _slope_heights(gx[m], gy[m], rect, sd, top)
    heights[inside(plateau)] = top
    for name, rise in (("low_step", p.low_step), ("high_step", p.high_step)):
        rect = place(name, p.step_size, p.step_size)
        placed[name] = features[name] = rect
        heights[inside(rect)] = rise
    rough = place("rough", p.rough_size, p.rough_size)
    placed["rough"] = features["rough"] = rough
    m = inside(rough)
    # Cell noise smoothed over 3 x 3 cells (bumps, not a saw), lifted so it stays >= 0.
    noise = ndimage.uniform_filter(rng.normal(0.0, 1.0, heights.shape), size=3)
    noise *= p.rough_std / max(float(noise[m].std()), 1e-12) if m.any() else 0.0
    heights[m] = np.maximum(noise[m] + 2.0 * p.rough_std, 0.0)
    return TerrainWorld(grid, HeightMap(heights, grid.resolution, grid.origin), features)


def save_terrain_world(world: TerrainWorld, folder: str | Path) -> Path:
    """Write ``folder/map/map.yaml`` (+ image) and ``folder/map/heights.npz``; the map.yaml.

    The folder is then a world in Arena's layout (``map: {type: world, name: FOLDER}``); the
    2-D simulators read only the map, ArtPlanner's ``height_map`` parameter the heights.
    """
    out = Path(folder) / "map"
    yaml_path = save_map(world.grid, out / "map.yaml")
    world.heights.save(out / HEIGHTS_FILE)
    return yaml_path


def load_terrain_world(folder: str | Path) -> tuple[OccupancyGrid, HeightMap]:
    """Read a folder written by :func:`save_terrain_world`: ``(grid, heights)``."""
    out = Path(folder) / "map"
    grid = load_map(out / "map.yaml")
    heights = HeightMap.load(out / HEIGHTS_FILE)
    heights.check_covers(grid, what=f"height map {out / HEIGHTS_FILE}")
    return grid, heights
