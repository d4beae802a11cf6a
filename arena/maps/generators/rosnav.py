"""Arena-Rosnav's ``rosnav`` map generators: ``indoor`` corridor trees and ``outdoor`` blocks.

Both follow Arena-Rosnav's ``utils/misc/map_generator`` (2024) on a grid of generator cells
(``cell_size``, Arena's ``map_properties.resolution``), row 0 at the top as in Arena's arrays,
then upsample to the output ``resolution`` by repetition
(:func:`~arena.maps.generators.barn.to_map_result`).

*indoor* (RRT-like tree of L-shaped corridors): the map starts fully occupied with the root node
``(⌊H/2⌋, ⌊W/2⌋)`` free. Each of ``iterations`` steps samples a cell ``(x, y)`` with
``x ∈ [r + 2, H − r − 2]``, ``y ∈ [r + 2, W − r − 2]`` (inclusive, ``r = corridor_radius``), links
it to the nearest existing node (L1 distance) and carves an L-shaped corridor ``2r + 1`` cells wide
between them: a horizontal strip along one node's row and a vertical strip along the other node's
column, each extended by ``r`` past its ends; a fair coin picks which of the two corners is used.
The tree is connected by construction; the sampling margin keeps the carving off the outermost
row and column (two wall cells remain at the top/left, one at the bottom/right).

*outdoor*: a one-cell border around a free interior and ``obstacle_num`` filled squares of
``(2r + 1)²`` cells (``r = obstacle_extra_radius``) centred on cells sampled as above; squares may
overlap (as in Arena).

The maps carry no obstacle models: every obstacle is part of the occupancy grid, as in Arena.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from arena.maps.generators.barn import GeneratorGridParams, to_map_result
from arena.maps.generators.base import register_generator
from arena.maps.sources import MapResult


def _centres(
    rng: np.random.Generator, n: int, rows: int, cols: int, r: int
) -> NDArray[np.int64]:
    """``(n, 2)`` cells ``[x, y]`` with ``x ∈ [r+2, rows−r−2]``, ``y ∈ [r+2, cols−r−2]``."""
    x = rng.integers(r + 2, rows - r - 2, size=n, endpoint=True)
    y = rng.integers(r + 2, cols - r - 2, size=n, endpoint=True)
    return np.stack([x, y], axis=1)


def _check_margin(shape: tuple[int, int], r: int, what: str) -> None:
    if min(shape) < 2 * r + 4:
        raise ValueError(
            f"the map ({shape[0]} × {shape[1]} cells of cell_size) is too small for "
            f"{what} {r}: it needs at least 2·{r} + 4 = {2 * r + 4} cells per side"
        )


def rosnav_indoor_map(
    rng: np.random.Generator, rows: int, cols: int, corridor_radius: int, iterations: int
) -> NDArray[np.bool_]:
    """Carve the corridor tree.

    Args:
        rng: random source.
        rows: map rows ``H`` (generator cells).
        cols: map columns ``W`` (generator cells).
        corridor_radius: corridor half-width ``r`` (cells); corridors are ``2r + 1`` cells wide.
        iterations: nodes added to the tree.

    Returns:
        ``(rows, cols)`` bool, True = occupied, row 0 = top.
    """
    r = corridor_radius
    occupied = np.ones((rows, cols), dtype=bool)
    nodes = np.empty((iterations + 1, 2), dtype=np.int64)
    nodes[0] = (rows // 2, cols // 2)
    occupied[rows // 2, cols // 2] = False
    samples = _centres(rng, iterations, rows, cols, r)
    # One coin per corridor, drawn up front (the sample stream is the same either way).
    flips = rng.random(iterations) < 0.5
    for i in range(iterations):
        new = samples[i]
        # Nearest node by L1 distance; argmin keeps the earliest node on ties.
        old = nodes[np.argmin(np.abs(nodes[: i + 1] - new).sum(axis=1))]
        nodes[i + 1] = new
        a, b = (new, old) if flips[i] else (old, new)
        # Horizontal strip along a's row spanning both columns, vertical strip along b's column
        # spanning both rows: they meet at the corner (a_x, b_y).
        c0, c1 = min(a[1], b[1]) - r, max(a[1], b[1]) + r
        r0, r1 = min(a[0], b[0]) - r, max(a[0], b[0]) + r
        occupied[a[0] - r : a[0] + r + 1, c0 : c1 + 1] = False
        occupied[r0 : r1 + 1, b[1] - r : b[1] + r + 1] = False
    return occupied


def rosnav_outdoor_map(
    rng: np.random.Generator, rows: int, cols: int, obstacle_num: int, obstacle_extra_radius: int
) -> NDArray[np.bool_]:
    """Border and square obstacles.

    Args:
        rng: random source.
        rows: map rows ``H`` (generator cells).
        cols: map columns ``W`` (generator cells).
        obstacle_num: number of squares.
        obstacle_extra_radius: square half-size ``r`` (cells); squares are ``2r + 1`` cells wide.

    Returns:
        ``(rows, cols)`` bool, True = occupied, row 0 = top.
    """
    r = obstacle_extra_radius
    occupied = np.zeros((rows, cols), dtype=bool)
    occupied[0, :] = occupied[-1, :] = occupied[:, 0] = occupied[:, -1] = True
    if obstacle_num == 0:
        return occupied
    centres = _centres(rng, obstacle_num, rows, cols, r)
    # Mark every square's cells at once: centre + each offset of the (2r+1)² block.
    off = np.arange(-r, r + 1)
    rr = (centres[:, 0, None, None] + off[None, :, None]).repeat(2 * r + 1, axis=2)
    cc = (centres[:, 1, None, None] + off[None, None, :]).repeat(2 * r + 1, axis=1)
    occupied[rr.ravel(), cc.ravel()] = True
    return occupied


@register_generator("rosnav_indoor", tags=("rosnav", "indoor"))
class RosnavIndoorGenerator:
    """Maze-like indoor map: a random tree of L-shaped corridors (Arena's rosnav ``indoor``).

    Args:
        params: validated :class:`RosnavIndoorGenerator.Params`.
    """

    class Params(GeneratorGridParams):
        """Parameters of :class:`RosnavIndoorGenerator` (grid: :class:`GeneratorGridParams`)."""

        corridor_radius: int = Field(
            4, ge=0,
            description="cells of cell_size, corridor half-width; corridors are 2r + 1 cells wide "
            "(Arena 2024 map_generator.yaml: 4, i.e. 4.5 m at 0.5 m cells)",
        )
        iterations: int = Field(
            50, ge=0, description="tree nodes added (Arena 2024 map_generator.yaml)"
        )

        @model_validator(mode="after")
        def _check_fit(self) -> RosnavIndoorGenerator.Params:
            _check_margin(self.coarse_shape, self.corridor_radius, "corridor_radius")
            return self

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def build(self, rng: np.random.Generator) -> MapResult:
        """Carve a corridor tree."""
        p = self.params
        rows, cols = p.coarse_shape
        coarse = rosnav_indoor_map(rng, rows, cols, p.corridor_radius, p.iterations)
        return to_map_result("rosnav_indoor", coarse, p)


@register_generator("rosnav_outdoor", tags=("rosnav", "outdoor"))
class RosnavOutdoorGenerator:
    """Open area with scattered square blocks (Arena's rosnav ``outdoor``).

    Args:
        params: validated :class:`RosnavOutdoorGenerator.Params`.
    """

    class Params(GeneratorGridParams):
        """Parameters of :class:`RosnavOutdoorGenerator` (grid: :class:`GeneratorGridParams`)."""

        obstacle_num: int = Field(
            15, ge=0, description="number of square blocks (Arena 2024 map_generator.yaml)"
        )
        obstacle_extra_radius: int = Field(
            1, ge=0,
            description="cells of cell_size, block half-size; blocks are 2r + 1 cells wide "
            "(Arena 2024 map_generator.yaml: 1, i.e. 1.5 m at 0.5 m cells)",
        )

        @model_validator(mode="after")
        def _check_fit(self) -> RosnavOutdoorGenerator.Params:
            _check_margin(self.coarse_shape, self.obstacle_extra_radius, "obstacle_extra_radius")
            return self

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def build(self, rng: np.random.Generator) -> MapResult:
        """Place the blocks."""
        p = self.params
        rows, cols = p.coarse_shape
        coarse = rosnav_outdoor_map(rng, rows, cols, p.obstacle_num, p.obstacle_extra_radius)
        return to_map_result("rosnav_outdoor", coarse, p)
