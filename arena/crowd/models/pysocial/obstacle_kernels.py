"""Obstacle term of :mod:`arena.crowd.models.pysocial`: wall points indexed in blocks.

:class:`_ObstacleIndex` stores a :class:`~arena.crowd.neighbors.CellList`'s points cell by cell
in blocks with bounding boxes; :func:`_obstacle` scans them for one agent, skipping cells and
blocks out of reach, and :func:`_obstacle_terms` evaluates the candidates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.neighbors import CellList

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

_BLOCK = 8
"""Obstacle points per bounding box (0.8 m of wall at PySocialForce's 10 points per metre)."""


@dataclass(frozen=True, eq=False)
class _ObstacleIndex:
    """The obstacle points of a :class:`CellList`, stored in its cell order, cut into blocks.

    Storing the points in scan order (rather than indexing through ``order``) keeps a block's
    points on a few cache lines; the scan visits them in the same order, so sums are unchanged.
    """

    xy: FloatArray
    """``(2, m)`` the points' x and y rows, cell by cell (m)."""
    cell_blocks: IntArray
    """``(cells + 1,)`` the blocks of cell ``c`` are ``cell_blocks[c]:cell_blocks[c + 1]``."""
    block_lo: IntArray
    """``(b + 1,)`` block ``k`` holds points ``block_lo[k]:block_lo[k + 1]``."""
    bbox: FloatArray
    """``(b, 4)`` ``(x_min, x_max, y_min, y_max)`` of each block (m)."""
    cell_box: FloatArray
    """``(cells, 4)`` the same of each cell's points (inf, -inf for an empty cell)."""
    grid: FloatArray
    """``(3,)`` grid origin x, y and cell size (m)."""
    shape: IntArray
    """``(2,)`` cells along x and y."""
    work: FloatArray
    """``(4, m)`` scratch for one agent's candidate points."""

    @classmethod
    def build(cls, cells: CellList) -> _ObstacleIndex:
        """Index the points of ``cells``."""
        cell_blocks, block_lo, bbox = _point_blocks(cells.points, cells.order, cells.starts)
        xy = np.ascontiguousarray(cells.points[cells.order].T)
        return cls(
            xy=xy,
            cell_blocks=cell_blocks,
            block_lo=block_lo,
            bbox=bbox,
            cell_box=_cell_boxes(bbox, cell_blocks),
            grid=np.array([cells.origin[0], cells.origin[1], cells.cell], dtype=np.float64),
            shape=np.array(cells.shape, dtype=np.int64),
            work=np.empty((4, xy.shape[1])),
        )


@njit(cache=True)
def _obstacle(
    pos: FloatArray,
    radii: FloatArray,
    active: NDArray[np.bool_],
    xy: FloatArray,
    cell_blocks: IntArray,
    block_lo: IntArray,
    bbox: FloatArray,
    cell_box: FloatArray,
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    reach: float,
    threshold: float,
    sigma: float,
    work: FloatArray,
    out: FloatArray,
) -> None:
    """PySocialForce's ``ObstacleForce`` (before its factor), scanning the point grid directly.

    The points are a :class:`CellList`'s in its cell order, cut into blocks by
    :func:`_point_blocks` (see :class:`_ObstacleIndex`). A cell or block whose bounding box is
    beyond the prefilter is skipped whole: its points would all fail it (rounded differences
    and squares are monotone), so the sums, in the same order, are the same to the bit. The
    blocks left, merged into runs of consecutive points, go to :func:`_obstacle_terms`
    (vectorised) and :func:`_obstacle_sum` (the exponentials, summed in scan order).

    Args:
        pos: ``(n, 2)`` positions (m).
        radii: ``(n,)`` agent radii ``R`` (m).
        active: ``(n,)`` agents that get the force.
        xy: ``(2, p)`` the points in cell order (m).
        cell_blocks: ``(cells + 1,)`` block ranges of the cells.
        block_lo: ``(b + 1,)`` point ranges of the blocks.
        bbox: ``(b, 4)`` block bounding boxes (m).
        cell_box: ``(cells, 4)`` cell bounding boxes (m).
        gx0: grid origin x (m).
        gy0: grid origin y (m).
        cell: grid cell size (m).
        nx: cells along x.
        ny: cells along y.
        reach: search radius (m), a hair over ``threshold + 2·max(radii)``.
        threshold: PySocialForce's ``threshold`` (m); points count while
            ``|r − o| − R < threshold + R``.
        sigma: decay length σ (m).
        work: ``(4, ≥ p)`` scratch.
        out: ``(n, 2)`` the sums are added here.
    """
    rings = max(1, math.ceil(reach / cell))
    runs = np.empty((2, block_lo.shape[0]), dtype=np.int64)
    for i in range(pos.shape[0]):
        if not active[i]:
            continue
        x, y = pos[i, 0], pos[i, 1]
        r = radii[i]
        thr = threshold + r
        # Cheap squared-distance prefilter, a hair wider than the exact test below.
        far2 = (thr + r) * (thr + r) * (1.0 + 1e-9)
        cx = int((x - gx0) // cell)
        cy = int((y - gy0) // cell)
        nruns = 0
        for gy in range(max(cy - rings, 0), min(cy + rings, ny - 1) + 1):
            for gx in range(max(cx - rings, 0), min(cx + rings, nx - 1) + 1):
                c = gy * nx + gx
                if _box_gap2(cell_box, c, x, y) >= far2:  # the window's far cells, mostly
                    continue
                for blk in range(cell_blocks[c], cell_blocks[c + 1]):
                    if _box_gap2(bbox, blk, x, y) >= far2:
                        continue
                    if nruns > 0 and runs[1, nruns - 1] == block_lo[blk]:
                        runs[1, nruns - 1] = block_lo[blk + 1]  # extends the last run
                    else:
                        runs[0, nruns] = block_lo[blk]
                        runs[1, nruns] = block_lo[blk + 1]
                        nruns += 1
        m = _obstacle_terms(xy, runs, nruns, x, y, r, thr, far2, sigma, work)
        fx, fy = _obstacle_sum(work, m)
        out[i, 0] += fx
        out[i, 1] += fy


@njit(cache=True, error_model="numpy")
def _obstacle_terms(
    xy: FloatArray,
    runs: IntArray,
    nruns: int,
    x: float,
    y: float,
    r: float,
    thr: float,
    far2: float,
    sigma: float,
    work: FloatArray,
) -> int:
    """Unit vectors, exponents and inclusion of the points in ``runs`` seen from ``(x, y)``.

    Writes, per point of the runs ``xy[:, runs[0, k]:runs[1, k]]`` in order, ``(x − o)/|x − o|``
    to ``work`` rows 0-1, ``−(|x − o| − r)/σ`` to row 2 and 1.0 to row 3 where the point
    counts (PySocialForce's ``|x − o| − r < thr``, behind the ``|x − o|² < far2`` prefilter
    and ``|x − o| > 0``), else 0.0. NumPy's error model: the divisions run unguarded (``x/0``
    gives inf or NaN, not an exception) so that the loop vectorises (IEEE sqrt and division
    give the scalar bits); the points they hit are the excluded ones. Returns the count.
    """
    k = 0
    for q in range(nruns):
        lo = runs[0, q]
        c = runs[1, q] - lo
        # Slices indexed from 0: numba then knows the indices are not negative and drops
        # its wraparound selects, which would keep LLVM from vectorising.
        px, py = xy[0, lo : lo + c], xy[1, lo : lo + c]
        ux, uy = work[0, k : k + c], work[1, k : k + c]
        arg, keep = work[2, k : k + c], work[3, k : k + c]
        for j in range(c):
            dx = x - px[j]
            dy = y - py[j]
            d2 = dx * dx + dy * dy
            dist = math.sqrt(d2)
            gap = dist - r
            ux[j] = dx / dist
            uy[j] = dy / dist
            arg[j] = -gap / sigma
            keep[j] = (d2 < far2) & (gap < thr) & (dist > 0.0)
        k += c
    return k


@njit(cache=True)
def _obstacle_sum(work: FloatArray, m: int) -> tuple[float, float]:
    """``Σ u · exp(arg)`` over the first ``m`` entries of :func:`_obstacle_terms`, in order."""
    ux, uy, arg, keep = work[0], work[1], work[2], work[3]
    fx = 0.0
    fy = 0.0
    for k in range(m):
        if keep[k] != 0.0:  # mostly: only the blocks' corners fall outside
            w = math.exp(arg[k])
            fx += ux[k] * w
            fy += uy[k] * w
    return fx, fy


@njit(cache=True, inline="always")
def _box_gap2(box: FloatArray, k: int, x: float, y: float) -> float:
    """Squared distance (m²) from ``(x, y)`` to box ``k`` of ``box`` ``(·, 4)``, 0 inside.

    A lower bound of every contained point's ``dx² + dy²`` as rounded (rounding is monotone),
    so ``≥ far2`` rules out the whole box without changing any sum.
    """
    bx: float = max(box[k, 0] - x, x - box[k, 1], 0.0)
    by: float = max(box[k, 2] - y, y - box[k, 3], 0.0)
    return bx * bx + by * by


@njit(cache=True)
def _cell_boxes(bbox: FloatArray, cell_blocks: IntArray) -> FloatArray:
    """``(cells, 4)`` bounding boxes of each cell's blocks ``bbox`` ``(b, 4)`` (m)."""
    cells = cell_blocks.shape[0] - 1
    out = np.empty((cells, 4))
    for c in range(cells):
        out[c, 0] = out[c, 2] = math.inf
        out[c, 1] = out[c, 3] = -math.inf
        for blk in range(cell_blocks[c], cell_blocks[c + 1]):
            out[c, 0] = min(out[c, 0], bbox[blk, 0])
            out[c, 1] = max(out[c, 1], bbox[blk, 1])
            out[c, 2] = min(out[c, 2], bbox[blk, 2])
            out[c, 3] = max(out[c, 3], bbox[blk, 3])
    return out


@njit(cache=True)
def _point_blocks(
    points: FloatArray, order: IntArray, starts: IntArray
) -> tuple[IntArray, IntArray, FloatArray]:
    """Cut each cell's points into runs of ``_BLOCK`` (in cell order) with bounding boxes.

    Wall samples are ordered along their segments, so a run is a short piece of wall with a
    tight box, and most of a cell's runs lie beyond an agent's reach.

    Returns:
        ``(cell_blocks, block_lo, bbox)``: the blocks of cell ``c`` are
        ``cell_blocks[c]:cell_blocks[c + 1]``, block ``b`` holds
        ``order[block_lo[b]:block_lo[b + 1]]``, ``bbox[b]`` is ``(x_min, x_max, y_min, y_max)``
        (m).
    """
    cells = starts.shape[0] - 1
    cell_blocks = np.zeros(cells + 1, dtype=np.int64)
    for c in range(cells):
        cell_blocks[c + 1] = cell_blocks[c] + (starts[c + 1] - starts[c] + _BLOCK - 1) // _BLOCK
    nb = cell_blocks[cells]
    block_lo = np.empty(nb + 1, dtype=np.int64)
    bbox = np.empty((nb, 4))
    block_lo[nb] = starts[cells]
    for c in range(cells):
        for k in range(cell_blocks[c + 1] - cell_blocks[c]):
            blk = cell_blocks[c] + k
            lo = starts[c] + k * _BLOCK
            hi = min(lo + _BLOCK, starts[c + 1])
            block_lo[blk] = lo
            bbox[blk, 0] = bbox[blk, 2] = math.inf
            bbox[blk, 1] = bbox[blk, 3] = -math.inf
            for s in range(lo, hi):
                px = points[order[s], 0]
                py = points[order[s], 1]
                bbox[blk, 0] = min(bbox[blk, 0], px)
                bbox[blk, 1] = max(bbox[blk, 1], px)
                bbox[blk, 2] = min(bbox[blk, 2], py)
                bbox[blk, 3] = max(bbox[blk, 3], py)
    return cell_blocks, block_lo, bbox
