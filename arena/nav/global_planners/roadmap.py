"""The probabilistic roadmap of ArtPlanner: where a legged robot can stand, nodes, edges.

* :func:`standable`: per height-map cell, whether the robot can stand there, after
  ArtPlanner's reachability check (the torso clear of the ground, a foothold under each foot)
  reduced to the 2.5-D map: a plane fitted over the stance (a ``(2k+1)²`` window, ``k`` cells of
  half a stance length) must be no steeper than ``max_slope`` and the ground must not deviate from
  it by more than ``max_roughness`` (standard deviation) - a step or a rock under the body does.
* :func:`sample_nodes`: a jittered lattice of ``spacing`` over the free, standable cells, plus
  bridge-test samples (Hsu et al. 2003: two blocked points a normal draw apart whose midpoint
  is free) that put nodes into narrow passages a lattice misses.
* :func:`free_pairs`: node pairs closer than the connection radius whose straight segment
  crosses only free cells (exact cell traversal, the A* planner's line-of-sight test).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import cKDTree

from arena.maps.grid import OccupancyGrid
from arena.maps.terrain import HeightMap
from arena.nav.global_planners.astar import _line_cost


def standable(heights: HeightMap, stance: float, max_slope: float, max_roughness: float
              ) -> NDArray[np.bool_]:
    """``(H, W)`` bool over ``heights``' cells: level and smooth enough to stand on.

    Args:
        heights: the ground.
        stance: m, the robot's hind-to-front foothold distance (the window's side).
        max_slope: rad, steepest plane stood on.
        max_roughness: m, largest standard deviation of the ground about that plane.
    """
    z = heights.heights
    res = heights.resolution
    k = max(1, round(stance / 2 / res))
    off = np.arange(-k, k + 1) * res
    ones = np.ones(2 * k + 1)
    xk = np.outer(ones, off)  # x offset of each window cell (columns), m
    yk = np.outer(off, ones)  # y offset (rows)
    n = float(xk.size)
    mean = ndimage.uniform_filter(z, size=2 * k + 1, mode="nearest")
    mean2 = ndimage.uniform_filter(z * z, size=2 * k + 1, mode="nearest")
    sxx = float(np.sum(xk * xk))
    # Least-squares plane over the window: x, y and 1 are orthogonal on a symmetric window.
    a = ndimage.correlate(z, xk, mode="nearest") / sxx
    b = ndimage.correlate(z, yk, mode="nearest") / sxx
    var = mean2 - mean * mean - (a * a + b * b) * sxx / n
    rough = np.sqrt(np.clip(var, 0.0, None))
    return np.asarray((np.hypot(a, b) <= math.tan(max_slope)) & (rough <= max_roughness))


def _cell_mask(grid: OccupancyGrid, mask: NDArray[np.bool_] | None,
               heights: HeightMap | None, pts: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether points ``(n, 2)`` lie in free grid cells and (with a mask) standable ones."""
    ok = ~grid.is_occupied(pts)
    if mask is not None and heights is not None:
        rows, cols = heights.shape
        c = np.clip(np.floor((pts[:, 0] - heights.origin[0]) / heights.resolution), 0, cols - 1)
        r = np.clip(np.floor((pts[:, 1] - heights.origin[1]) / heights.resolution), 0, rows - 1)
        ok &= mask[r.astype(np.int64), c.astype(np.int64)]
    return np.asarray(ok)


def sample_nodes(grid: OccupancyGrid, spacing: float, bridges: int, rng: np.random.Generator,
                 mask: NDArray[np.bool_] | None = None, heights: HeightMap | None = None
                 ) -> NDArray[np.float64]:
    """Roadmap nodes ``(n, 2)`` (m): a jittered lattice and up to ``bridges`` bridge samples.

    Args:
        grid: the (inflated) map; nodes lie in its free cells.
        spacing: m between lattice points.
        bridges: bridge-test pairs drawn.
        rng: every draw comes from it.
        mask: standable cells of ``heights`` (:func:`standable`), or ``None`` on flat ground.
        heights: the ground the mask belongs to.
    """
    xmin, ymin, xmax, ymax = grid.bounds
    xs = np.arange(xmin + spacing / 2, xmax, spacing)
    ys = np.arange(ymin + spacing / 2, ymax, spacing)
    lattice = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    lattice = lattice + rng.uniform(-spacing / 2, spacing / 2, lattice.shape)
    nodes = [lattice[_cell_mask(grid, mask, heights, lattice)]]
    if bridges > 0:
        lo, hi = np.array([xmin, ymin]), np.array([xmax, ymax])
        p1 = rng.uniform(lo, hi, (bridges, 2))
        p2 = p1 + rng.normal(0.0, spacing, (bridges, 2))
        mid = (p1 + p2) / 2
        keep = grid.is_occupied(p1) & grid.is_occupied(p2) & _cell_mask(grid, mask, heights, mid)
        nodes.append(mid[keep])
    return np.concatenate(nodes)


@njit(cache=True)
def _pairs_free(blocked: NDArray[np.bool_], pts: NDArray[np.float64], i: NDArray[np.int64],
                j: NDArray[np.int64]) -> NDArray[np.bool_]:
    out = np.empty(len(i), dtype=np.bool_)
    zero = np.zeros((1, 1))
    for k in range(len(i)):
        a, b = i[k], j[k]
        cost = _line_cost(blocked, zero, False, pts[a, 0], pts[a, 1], pts[b, 0], pts[b, 1])
        out[k] = np.isfinite(cost)
    return out


def segments_free(grid: OccupancyGrid, a: NDArray[np.float64], b: NDArray[np.float64]
                  ) -> NDArray[np.bool_]:
    """Whether each straight segment ``a[k]→b[k]`` (``(n, 2)`` m) crosses only free cells."""
    pts = (np.concatenate([a, b]) - np.asarray(grid.origin)) / grid.resolution
    n = len(a)
    idx = np.arange(n, dtype=np.int64)
    return np.asarray(_pairs_free(grid.occupied, pts, idx, idx + n))


def free_pairs(grid: OccupancyGrid, nodes: NDArray[np.float64], radius: float
               ) -> NDArray[np.int64]:
    """``(m, 2)`` node index pairs ``i < j`` within ``radius`` (m) joined by a free segment.

    Sorted, so the roadmap does not depend on the k-d tree's internal order.
    """
    pairs = cKDTree(nodes).query_pairs(radius, output_type="ndarray").astype(np.int64)
    if len(pairs) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
    pts = (nodes - np.asarray(grid.origin)) / grid.resolution
    ok = _pairs_free(grid.occupied, pts, pairs[:, 0], pairs[:, 1])
    return np.asarray(pairs[ok], dtype=np.int64)
