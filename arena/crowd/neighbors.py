"""Neighbour search with a cell list (numba): pairs within a cutoff in O(n) for bounded density.

Every crowd model gets its pedestrian pairs from here, and models with many static points
(wall samples) build a :class:`CellList` over them once per episode.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

_MAX_CELLS = 4_000_000  # dense cell table cap; coarser cells beyond it


class Neighbors:
    """Neighbour lists in CSR form, and the unique pairs.

    The neighbours of query ``i`` are ``indices[indptr[i]:indptr[i + 1]]``, each strictly
    closer than ``cutoff``; a point is never its own neighbour in a self-query. The order is
    deterministic (cell by cell) but not sorted; models that need nearest-first sort.

    Built from CSR arrays, or by :func:`find_neighbors` from a cell list, in which case both
    forms are computed on first use: pair models (PySocialForce) read only
    :meth:`unique_pairs`, which a half search finds with half the distance checks, and never
    pay for the CSR; per-agent models (ORCA, pedsim) read ``indptr``/``indices``. Read-only.

    Attributes:
        indptr: ``(q + 1,)`` offsets.
        indices: ``(m,)`` neighbour indices.
        cutoff: the search radius (m); ``inf`` means all pairs.
    """

    __slots__ = ("_cells", "_cutoff", "_indices", "_indptr", "_pairs")

    def __init__(self, indptr: IntArray, indices: IntArray, cutoff: float) -> None:
        self._indptr: IntArray | None = indptr
        self._indices: IntArray | None = indices
        self._pairs: tuple[IntArray, IntArray] | None = None
        self._cells: CellList | None = None
        self._cutoff = cutoff

    @classmethod
    def _deferred(cls, cells: CellList, cutoff: float) -> Neighbors:
        """The self-query of ``cells.points`` within ``cutoff``, computed when first read."""
        nb = cls.__new__(cls)
        nb._indptr = nb._indices = None
        nb._pairs = None
        nb._cells = cells
        nb._cutoff = cutoff
        return nb

    @property
    def cutoff(self) -> float:
        """The search radius (m); ``inf`` means all pairs."""
        return self._cutoff

    def _csr(self) -> tuple[IntArray, IntArray]:
        if self._indptr is None or self._indices is None:
            assert self._cells is not None
            full = self._cells.query(self._cells.points, self.cutoff, exclude_self=True)
            self._indptr, self._indices = full.indptr, full.indices
        return self._indptr, self._indices

    @property
    def indptr(self) -> IntArray:
        """``(q + 1,)`` offsets."""
        return self._csr()[0]

    @property
    def indices(self) -> IntArray:
        """``(m,)`` neighbour indices."""
        return self._csr()[1]

    def __len__(self) -> int:
        if self._indptr is None and self._cells is not None:
            return int(self._cells.points.shape[0])
        return int(self.indptr.shape[0] - 1)

    def of(self, i: int) -> IntArray:
        """Neighbours of query ``i``."""
        return self.indices[self.indptr[i] : self.indptr[i + 1]]

    def pairs(self) -> tuple[IntArray, IntArray]:
        """``(i, j)`` arrays of every listed pair (each unordered pair appears twice)."""
        counts = np.diff(self.indptr)
        return np.repeat(np.arange(len(self), dtype=np.int64), counts), self.indices

    def unique_pairs(self) -> tuple[IntArray, IntArray]:
        """``(i, j)`` ``(p,)`` arrays of each listed pair once, with ``i < j`` (self-queries).

        Ordered as the CSR rows: by ``i``, then each ``j`` in its place in row ``i``; i.e. the
        entries ``j > i`` of :meth:`pairs`. Computed once, then cached; do not modify.
        """
        if self._pairs is None:
            c = self._cells
            if self._indptr is None and c is not None:
                self._pairs = _half_pairs(
                    c.points,
                    c.order,
                    c.starts,
                    c.origin[0],
                    c.origin[1],
                    c.cell,
                    c.shape[0],
                    c.shape[1],
                    float(self.cutoff),
                    max(1, math.ceil(self.cutoff / c.cell)),
                )
            else:
                indptr, indices = self._csr()
                self._pairs = _upper_pairs(indptr, indices)
        return self._pairs


class CellList:
    """A uniform grid over fixed points for radius queries.

    Args:
        points: ``(n, 2)`` points (copied).
        cell_size: edge of a grid cell (m); queries with radius ≤ cell_size look at 3×3 cells.
    """

    def __init__(self, points: FloatArray, cell_size: float) -> None:
        pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        self.points = pts
        n = pts.shape[0]
        if n == 0:
            self.origin = np.zeros(2)
            self.cell = 1.0
            self.shape = (1, 1)
            self.order = np.zeros(0, dtype=np.int64)
            self.starts = np.zeros(2, dtype=np.int64)
            return
        # The compiled constructor (the same numbers; numpy's min over the rows of an (n, 2)
        # array alone cost more); the Python one below for what it declines.
        grid = _grid(pts, max(float(cell_size), 1e-6), _MAX_CELLS)
        if grid is not None:
            self.origin, self.cell, nx, ny, self.order, self.starts = grid
            self.shape = (nx, ny)
            return
        lo = pts.min(axis=0)
        hi = pts.max(axis=0)
        cell = max(float(cell_size), 1e-6)
        nx = math.floor((hi[0] - lo[0]) / cell) + 1
        ny = math.floor((hi[1] - lo[1]) / cell) + 1
        while nx * ny > _MAX_CELLS:  # sparse, huge extents: coarser cells, still correct
            cell *= 2.0
            nx = math.floor((hi[0] - lo[0]) / cell) + 1
            ny = math.floor((hi[1] - lo[1]) / cell) + 1
        self.origin = lo
        self.cell = cell
        self.shape = (nx, ny)
        self.order, self.starts = _build(pts, lo[0], lo[1], cell, nx, ny)

    @classmethod
    def _of_copy(cls, pts: FloatArray, cell_size: float) -> CellList:
        """``CellList(pts, cell_size)`` in one compiled call, for the per-step searches.

        ``pts``: ``(n ≥ 1, 2)`` C-contiguous float64 that the list may keep (a copy). Points
        that are not finite, or spread over more than 2³¹ cells, take the constructor's path
        (and its errors).
        """
        grid = _grid(pts, max(float(cell_size), 1e-6), _MAX_CELLS)
        if grid is None:
            return cls(pts, cell_size)
        lo, cell, nx, ny, order, starts = grid
        cl = cls.__new__(cls)
        cl.points = pts
        cl.origin = lo
        cl.cell = cell
        cl.shape = (nx, ny)
        cl.order = order
        cl.starts = starts
        return cl

    def query(self, queries: FloatArray, radius: float, *, exclude_self: bool = False) -> Neighbors:
        """Indices of the points strictly within ``radius`` of each query.

        Args:
            queries: ``(q, 2)``.
            radius: m; ``inf`` lists every point.
            exclude_self: the queries are the points themselves; drop ``i == j``.
        """
        q = np.ascontiguousarray(queries, dtype=np.float64).reshape(-1, 2)
        n = self.points.shape[0]
        if not math.isfinite(radius):
            indptr, indices = _all_pairs(q.shape[0], n, exclude_self)
            return Neighbors(indptr, indices, math.inf)
        rings = max(1, math.ceil(radius / self.cell))
        indptr, indices = _query(
            self.points,
            self.order,
            self.starts,
            self.origin[0],
            self.origin[1],
            self.cell,
            self.shape[0],
            self.shape[1],
            q,
            float(radius),
            rings,
            exclude_self,
        )
        return Neighbors(indptr, indices, float(radius))


def find_neighbors(positions: FloatArray, cutoff: float) -> Neighbors:
    """Pedestrian pairs closer than ``cutoff`` (self excluded), via a cell list."""
    n = np.asarray(positions).reshape(-1, 2).shape[0]
    if cutoff <= 0.0 or n < 2:
        return Neighbors(np.zeros(n + 1, dtype=np.int64), np.zeros(0, dtype=np.int64), cutoff)
    if not math.isfinite(cutoff):
        n = np.asarray(positions).reshape(-1, 2).shape[0]
        indptr, indices = _all_pairs(n, n, True)
        return Neighbors(indptr, indices, math.inf)
    # Half-cutoff cells scan 25 quarter-size cells (6.25 cutoff²) instead of 9 full ones (9).
    # A copy: the lists are computed when first read, and the caller may move its agents.
    pts = np.array(positions, dtype=np.float64).reshape(-1, 2)
    return Neighbors._deferred(CellList._of_copy(pts, 0.5 * cutoff), float(cutoff))


@njit(cache=True)
def _build(
    pts: FloatArray, ox: float, oy: float, cell: float, nx: int, ny: int
) -> tuple[IntArray, IntArray]:
    n = pts.shape[0]
    cid = np.empty(n, dtype=np.int64)
    for i in range(n):
        cx = min(max(int((pts[i, 0] - ox) / cell), 0), nx - 1)
        cy = min(max(int((pts[i, 1] - oy) / cell), 0), ny - 1)
        cid[i] = cy * nx + cx
    starts = np.zeros(nx * ny + 1, dtype=np.int64)
    for i in range(n):
        starts[cid[i] + 1] += 1
    for c in range(nx * ny):
        starts[c + 1] += starts[c]
    # A counting sort: the stable argsort of the cell ids (the order a stable mergesort gives),
    # in linear time.
    fill = starts[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        order[fill[cid[i]]] = i
        fill[cid[i]] += 1
    return order, starts


@njit(cache=True)
def _grid(
    pts: FloatArray, cell: float, max_cells: int
) -> tuple[FloatArray, float, int, int, IntArray, IntArray] | None:
    """:class:`CellList`'s constructor for ``(n ≥ 1, 2)`` points, the same numbers.

    Returns:
        ``(origin (2,), cell, nx, ny, order, starts)``, or None for a coordinate that is not
        finite or an extent beyond 2³¹ cells (the constructor's Python integers handle those).
    """
    lo = pts[0].copy()
    hi = pts[0].copy()
    for i in range(pts.shape[0]):
        for d in range(2):
            v = pts[i, d]
            if not math.isfinite(v):
                return None
            lo[d] = min(lo[d], v)
            hi[d] = max(hi[d], v)
    if (hi[0] - lo[0]) / cell > 2.0**31 or (hi[1] - lo[1]) / cell > 2.0**31:
        return None  # nx · ny could overflow int64
    nx = math.floor((hi[0] - lo[0]) / cell) + 1
    ny = math.floor((hi[1] - lo[1]) / cell) + 1
    while nx * ny > max_cells:  # sparse, huge extents: coarser cells, still correct
        cell *= 2.0
        nx = math.floor((hi[0] - lo[0]) / cell) + 1
        ny = math.floor((hi[1] - lo[1]) / cell) + 1
    order, starts = _build(pts, lo[0], lo[1], cell, nx, ny)
    return lo, cell, nx, ny, order, starts


@njit(cache=True)
def _query(
    pts: FloatArray,
    order: IntArray,
    starts: IntArray,
    ox: float,
    oy: float,
    cell: float,
    nx: int,
    ny: int,
    q: FloatArray,
    radius: float,
    rings: int,
    exclude_self: bool,
) -> tuple[IntArray, IntArray]:
    nq = q.shape[0]
    counts = np.zeros(nq + 1, dtype=np.int64)
    # Two passes (count, then fill) keep memory exact without growing lists.
    scratch = np.empty(0, dtype=np.int64)
    for i in range(nq):
        counts[i + 1] = counts[i] + _scan(
            pts,
            order,
            starts,
            ox,
            oy,
            cell,
            nx,
            ny,
            q[i, 0],
            q[i, 1],
            radius,
            rings,
            i if exclude_self else -1,
            scratch,
            0,
            False,
        )
    indices = np.empty(counts[nq], dtype=np.int64)
    for i in range(nq):
        _scan(
            pts,
            order,
            starts,
            ox,
            oy,
            cell,
            nx,
            ny,
            q[i, 0],
            q[i, 1],
            radius,
            rings,
            i if exclude_self else -1,
            indices,
            counts[i],
            True,
        )
    return counts, indices


@njit(cache=True, inline="always")
def _scan(
    pts: FloatArray,
    order: IntArray,
    starts: IntArray,
    ox: float,
    oy: float,
    cell: float,
    nx: int,
    ny: int,
    x: float,
    y: float,
    radius: float,
    rings: int,
    skip: int,
    out: IntArray,
    offset: int,
    write: bool,
) -> int:
    r2 = radius * radius
    cx = int((x - ox) // cell)
    cy = int((y - oy) // cell)
    k = 0
    for gy in range(max(cy - rings, 0), min(cy + rings, ny - 1) + 1):
        row = gy * nx
        for gx in range(max(cx - rings, 0), min(cx + rings, nx - 1) + 1):
            c = row + gx
            for s in range(starts[c], starts[c + 1]):
                j = order[s]
                if j == skip:
                    continue
                dx = pts[j, 0] - x
                dy = pts[j, 1] - y
                if dx * dx + dy * dy < r2:
                    if write:
                        out[offset + k] = j
                    k += 1
    return k


@njit(cache=True)
def _all_pairs(nq: int, n: int, exclude_self: bool) -> tuple[IntArray, IntArray]:
    per = n - 1 if exclude_self else n
    per = max(per, 0)
    indptr = np.arange(nq + 1, dtype=np.int64) * per
    indices = np.empty(nq * per, dtype=np.int64)
    for i in range(nq):
        k = i * per
        for j in range(n):
            if exclude_self and j == i:
                continue
            indices[k] = j
            k += 1
    return indptr, indices


@njit(cache=True)
def _half_pairs(
    pts: FloatArray,
    order: IntArray,
    starts: IntArray,
    ox: float,
    oy: float,
    cell: float,
    nx: int,
    ny: int,
    radius: float,
    rings: int,
) -> tuple[IntArray, IntArray]:
    """Pairs ``i < j`` of the points closer than ``radius``, in the order of ``_query``'s rows.

    Each point scans the same cells as ``_query`` but measures only the points ``j > i``: half
    the distance checks, in one pass. The distance test is ``_scan``'s, symmetric in ``i`` and
    ``j`` to the bit, so the set is exactly the CSR's.

    Returns:
        ``(i, j)``, each ``(p,)``.
    """
    n = pts.shape[0]
    r2 = radius * radius
    cap = 32 * n + 64
    pi = np.empty(cap, dtype=np.int64)
    pj = np.empty(cap, dtype=np.int64)
    m = 0
    for i in range(n):
        x = pts[i, 0]
        y = pts[i, 1]
        cx = int((x - ox) // cell)
        cy = int((y - oy) // cell)
        gx0 = max(cx - rings, 0)
        gx1 = min(cx + rings, nx - 1) + 1
        gy0 = max(cy - rings, 0)
        gy1 = min(cy + rings, ny - 1) + 1
        # Room for every candidate of the row first: the writes below are then unconditional.
        bound = 0
        for gy in range(gy0, gy1):
            bound += starts[gy * nx + gx1] - starts[gy * nx + gx0]
        if m + bound > cap:
            cap = max(2 * cap, m + bound)
            grown_i = np.empty(cap, dtype=np.int64)
            grown_j = np.empty(cap, dtype=np.int64)
            grown_i[:m] = pi[:m]
            grown_j[:m] = pj[:m]
            pi = grown_i
            pj = grown_j
        for gy in range(gy0, gy1):
            # A row of cells is one run of ``order``: cells are numbered row by row.
            for s in range(starts[gy * nx + gx0], starts[gy * nx + gx1]):
                j = order[s]
                # A cell lists its points in ascending index order (stable sort): the skipped
                # j <= i are a prefix of each cell, a well-predicted branch.
                if j <= i:
                    continue
                dx = pts[j, 0] - x
                dy = pts[j, 1] - y
                # Written always, kept if close: no mispredicted branch on the distance test.
                pi[m] = i
                pj[m] = j
                m += dx * dx + dy * dy < r2
    return pi[:m], pj[:m]


@njit(cache=True)
def _upper_pairs(indptr: IntArray, indices: IntArray) -> tuple[IntArray, IntArray]:
    """The entries ``j > i`` of CSR rows ``i``, as ``(i, j)`` arrays in CSR order."""
    m = 0
    for i in range(indptr.shape[0] - 1):
        for k in range(indptr[i], indptr[i + 1]):
            if indices[k] > i:
                m += 1
    pi = np.empty(m, dtype=np.int64)
    pj = np.empty(m, dtype=np.int64)
    m = 0
    for i in range(indptr.shape[0] - 1):
        for k in range(indptr[i], indptr[i + 1]):
            if indices[k] > i:
                pi[m] = i
                pj[m] = indices[k]
                m += 1
    return pi, pj
