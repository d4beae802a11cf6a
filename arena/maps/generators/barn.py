"""BARN-style cellular-automaton maps (Arena-Rosnav's ``barn`` map generator).

The algorithm follows Arena-Rosnav's ``utils/misc/map_generator`` (2024), itself after the BARN
dataset (Perille et al. 2020):

1. Work on ``width − 2`` columns of generator cells (the side walls are added last). The top and
   bottom rows are filled; every other cell is filled with probability ``fill_pct``.
2. ``smooth_iter`` synchronous steps of the automaton: count the filled 8-neighbours of every cell
   (cells beyond the top/bottom border count as filled, beyond the left/right edges as free); a cell
   with ``≥ 5`` filled neighbours becomes filled, one with ``≤ 1`` becomes free, the rest keep
   their state.
3. Connectivity check in the robot's configuration space: inflation radius
   ``robot_radius × inflation_factor``, ``k = ceil(radius / cell_size)``; a cell is blocked if any
   filled cell lies in the ``(2(k − 1) + 1)²`` square around it. The largest 4-connected free
   region touching the left column and the largest touching the right column must be the same
   region, else the map is drawn again (at most ``max_tries`` maps).
4. A full column of filled cells is added on the left and on the right.

The coarse map (``cell_size``, Arena's ``map_properties.resolution``) is upsampled to the output
``resolution`` by repeating every cell ``cell_size / resolution`` times along both axes, so walls
stay axis-aligned blocks exactly as Arena's PNG shows them at its own resolution.

This module also holds the pieces the rosnav generators share (:class:`GeneratorGridParams`,
:func:`to_map_result`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from pydantic import ConfigDict, Field, model_validator
from scipy import ndimage

from arena.core.errors import MapError
from arena.maps.generators.base import register_generator
from arena.maps.grid import OccupancyGrid
from arena.maps.sources import GridSizeParams, MapResult

# 8-neighbour kernel of the automaton (the cell itself is not its own neighbour).
_NEIGHBOURS = np.array([[1, 1, 1], [1, 0, 1], [1, 1, 1]], dtype=np.int16)
# 4-connectivity of Arena's flood fill.
_CROSS = ndimage.generate_binary_structure(2, 1)


def _whole_ratio(a: float, b: float) -> int | None:
    """``a / b`` if it is a whole number (to 1e-6), else ``None``."""
    q = a / b
    n = round(q)
    return n if n >= 1 and abs(q - n) <= 1e-6 * max(1.0, q) else None


class GeneratorGridParams(GridSizeParams):
    """Map size and cell sizes shared by the barn and rosnav generators.

    Defaults are Arena-Rosnav's 2024 ``arena_bringup/params/map_generator.yaml``: 60 × 60 cells at
    0.5 m, i.e. 30 × 30 m.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    width: float = Field(30.0, gt=0, description="m, map width (Arena 2024: 60 cells × 0.5 m)")
    height: float = Field(30.0, gt=0, description="m, map height (Arena 2024: 60 cells × 0.5 m)")
    cell_size: float = Field(
        0.5, gt=0,
        description="m, the generator's own cell (Arena's map_properties.resolution, 2024: 0.5)",
    )
    resolution: float = Field(
        0.05, gt=0,
        description="m per cell of the output grid; a whole fraction of cell_size (the coarse "
        "cells are repeated, default 0.05 m = the simulator's map resolution)",
    )

    @model_validator(mode="after")
    def _check_sizes(self) -> GeneratorGridParams:
        if _whole_ratio(self.cell_size, self.resolution) is None:
            raise ValueError(
                f"cell_size ({self.cell_size} m) must be a whole multiple of resolution "
                f"({self.resolution} m): coarse cells are upsampled by repetition"
            )
        for name in ("width", "height"):
            if _whole_ratio(getattr(self, name), self.cell_size) is None:
                raise ValueError(
                    f"{name} ({getattr(self, name)} m) must be a whole number of cell_size "
                    f"({self.cell_size} m) cells"
                )
        return self

    @property
    def coarse_shape(self) -> tuple[int, int]:
        """``(rows, cols)`` of the generator's grid (cells of ``cell_size``)."""
        return round(self.height / self.cell_size), round(self.width / self.cell_size)

    @property
    def upsample(self) -> int:
        """Output cells per generator cell along each axis."""
        return round(self.cell_size / self.resolution)


def to_map_result(name: str, coarse: NDArray[np.bool_], params: GeneratorGridParams) -> MapResult:
    """Upsample a coarse map in Arena's image order into a :class:`MapResult`.

    Args:
        name: map name.
        coarse: ``(rows, cols)`` bool, True = occupied, row 0 = top of the image (Arena's arrays,
            which Arena flips before publishing, spec §3.2).
        params: the generator's grid parameters.

    Returns:
        The map with a ``(height / resolution, width / resolution)`` grid at the origin ``(0, 0)``.
    """
    k = params.upsample
    # Flip to the grid's convention (row 0 = lowest y), then repeat each cell k × k times.
    fine = np.repeat(np.repeat(coarse[::-1], k, axis=0), k, axis=1)
    return MapResult(name, OccupancyGrid.from_occupied(fine, params.resolution, (0.0, 0.0)))


def barn_automaton(
    rng: np.random.Generator, rows: int, cols: int, fill_pct: float, smooth_iter: int
) -> NDArray[np.bool_]:
    """Random fill and smoothing (steps 1–2), without the side walls.

    Args:
        rng: random source.
        rows: number of rows (incl. the filled top and bottom rows).
        cols: number of columns (the map width minus the two side walls).
        fill_pct: probability that an inner cell starts filled.
        smooth_iter: number of automaton steps.

    Returns:
        ``(rows, cols)`` bool, True = filled, row 0 = top.
    """
    grid = rng.random((rows, cols)) < fill_pct
    grid[0, :] = grid[-1, :] = True
    for _ in range(smooth_iter):
        # Pad the sides with free cells first, then the top/bottom with filled ones, so the outside
        # corners count as filled (beyond the top/bottom border everything is wall).
        padded = np.pad(grid, ((0, 0), (1, 1)), constant_values=False)
        padded = np.pad(padded, ((1, 1), (0, 0)), constant_values=True)
        count = ndimage.convolve(padded.astype(np.int16), _NEIGHBOURS, mode="constant")[1:-1, 1:-1]
        # Synchronous update: counts come from the previous state only.
        grid = (count >= 5) | (grid & (count > 1))
    return grid


def barn_connected(grid: NDArray[np.bool_], inflation_cells: int) -> bool:
    """Arena's left-to-right connectivity check in the robot's C-space (step 3).

    Args:
        grid: ``(rows, cols)`` bool automaton map without side walls, True = filled.
        inflation_cells: ``k = ceil(inflation radius / cell_size)``; blocked cells are those with
            a filled cell in the ``(2(k − 1) + 1)²`` square around them.

    Returns:
        Whether the largest 4-connected free C-space region touching column 0 is also the largest
        touching the last column.
    """
    side = 2 * (inflation_cells - 1) + 1
    if side > 1:
        # Outside the map counts as free here, as in Arena (the side walls come later).
        cspace = ndimage.binary_dilation(grid, structure=np.ones((side, side), dtype=bool))
    else:
        cspace = grid
    labels, n = ndimage.label(~cspace, structure=_CROSS)
    if n == 0:
        return False
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    sizes[0] = 0  # label 0 = blocked cells

    def largest(column: NDArray[np.int32]) -> int:
        touching = np.unique(column[column > 0])
        return int(touching[np.argmax(sizes[touching])]) if touching.size else 0

    left, right = largest(labels[:, 0]), largest(labels[:, -1])
    return left != 0 and left == right


@register_generator("barn", tags=("barn",))
class BarnGenerator:
    """Cellular-automaton obstacle field crossed from left to right (Arena's ``barn``).

    Args:
        params: validated :class:`BarnGenerator.Params`.
    """

    class Params(GeneratorGridParams):
        """Parameters of :class:`BarnGenerator` (grid fields: :class:`GeneratorGridParams`)."""

        fill_pct: float = Field(
            0.15, ge=0.0, le=1.0,
            description="initial fill probability of inner cells (Arena 2024 map_generator.yaml)",
        )
        smooth_iter: int = Field(
            5, ge=0, description="automaton steps (Arena 2024 map_generator.yaml)"
        )
        robot_radius: float = Field(
            0.3, ge=0.0,
            description="m, robot radius for the connectivity check (Arena reads the robot "
            "model's; 0.3 m is a typical mid-size robot)",
        )
        inflation_factor: float = Field(
            1.75, ge=0.0, description="× robot_radius = inflation radius of the check (Arena)"
        )
        max_tries: int = Field(
            50, ge=1, description="maps drawn before giving up (Arena's recursion limit 50)"
        )

        @model_validator(mode="after")
        def _check_columns(self) -> BarnGenerator.Params:
            if self.coarse_shape[1] < 3 or self.coarse_shape[0] < 3:
                raise ValueError(
                    f"a barn map needs at least 3 × 3 cells of cell_size, got {self.coarse_shape}"
                )
            return self

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def build(self, rng: np.random.Generator) -> MapResult:
        """Draw maps until one passes the connectivity check; return it with its side walls.

        Raises:
            MapError: no map of ``max_tries`` passed the check.
        """
        p = self.params
        rows, cols = p.coarse_shape
        radius = p.robot_radius * p.inflation_factor
        # max(1, ·): a point robot still needs its own cell free.
        k = max(1, math.ceil(radius / p.cell_size - 1e-9))
        for _ in range(p.max_tries):
            inner = barn_automaton(rng, rows, cols - 2, p.fill_pct, p.smooth_iter)
            if barn_connected(inner, k):
                wall = np.ones((rows, 1), dtype=bool)
                return to_map_result("barn", np.hstack([wall, inner, wall]), p)
        raise MapError(
            f"barn: no map of {p.max_tries} tries connects the left and right sides for an "
            f"inflation radius of {radius:.3f} m (robot_radius {p.robot_radius} m × "
            f"inflation_factor {p.inflation_factor}); lower fill_pct ({p.fill_pct}), raise "
            f"smooth_iter ({p.smooth_iter}) or max_tries, or use a smaller robot_radius "
            f"(map {p.width} × {p.height} m, cell_size {p.cell_size} m)"
        )
