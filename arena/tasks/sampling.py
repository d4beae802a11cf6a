"""Sampling free positions on a grid with clearances (used by every random task)."""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray
from scipy import ndimage

from arena.core.errors import SamplingError
from arena.maps.grid import OccupancyGrid


def components(mask: NDArray[np.bool_]) -> NDArray[np.int32]:
    """8-connected component labels of a bool mask (0 = not in the mask)."""
    labels: NDArray[np.int32]
    labels, _ = ndimage.label(mask, structure=np.ones((3, 3), dtype=bool))
    return labels


def sample_cells(
    mask: NDArray[np.bool_], n: int, rng: np.random.Generator, *, what: str
) -> NDArray[np.int64]:
    """``n`` distinct ``[row, col]`` cells drawn uniformly from a mask."""
    flat = np.flatnonzero(mask)
    if flat.size < n:
        raise SamplingError(
            f"cannot place {what}: only {flat.size} admissible cells, {n} needed "
            "(reduce counts or clearances, or use a larger map)"
        )
    pick = rng.choice(flat, size=n, replace=False)
    return np.stack(np.unravel_index(pick, mask.shape), axis=1).astype(np.int64)


def jitter(
    grid: OccupancyGrid, cells: NDArray[np.int64], rng: np.random.Generator
) -> NDArray[np.float64]:
    """World positions uniformly inside the given cells (no grid-aligned artefacts)."""
    centers = grid.cell_to_world(cells)
    return centers + rng.uniform(-0.5, 0.5, size=centers.shape) * grid.resolution


@njit(cache=True)
def accept_spaced(
    candidates: NDArray[np.float64], chosen: NDArray[np.float64], count: int, min_gap: float
) -> int:
    """Append to ``chosen[:count]`` each candidate ≥ ``min_gap`` from all chosen so far.

    Candidates are taken in their order; candidate ``m`` is accepted if
    ``np.hypot(*(p - q)) >= min_gap`` for every chosen ``q`` (the earlier candidates accepted
    included), until ``chosen`` ``(n, 2)`` holds ``n`` rows; returns the new count. All
    coordinates must be finite (m).

    Only the pairs that can fail are tested: the points are binned into square buckets of
    side ``size ≥ min_gap · (1 + 1e-6)``, and points two or more buckets apart (in x or y)
    differ by more than ``min_gap`` in that coordinate, so their ``hypot`` passes. The
    outcome is therefore that of testing every pair (the loop this replaced, O(candidates ×
    chosen), took minutes for 1,000 people), in O(candidates + chosen) for a bounded density.
    """
    n = chosen.shape[0]
    m = candidates.shape[0]
    if m == 0 or count >= n:
        return count
    # Bounding box of everything that can be binned.
    x0 = y0 = np.inf
    x1 = y1 = -np.inf
    for j in range(count):
        x0, x1 = min(x0, chosen[j, 0]), max(x1, chosen[j, 0])
        y0, y1 = min(y0, chosen[j, 1]), max(y1, chosen[j, 1])
    for i in range(m):
        x0, x1 = min(x0, candidates[i, 0]), max(x1, candidates[i, 0])
        y0, y1 = min(y0, candidates[i, 1]), max(y1, candidates[i, 1])
    # Bucket side: a hair above the gap (rounding of the bucket indices), and large enough
    # that there are at most about 4 buckets per point (memory O(points)). A gap of 0 or less
    # separates every pair (any side will do); a NaN gap none (one bucket: every pair tested).
    size = min_gap * (1.0 + 1e-6) if min_gap > 0.0 else (1.0 if min_gap <= 0.0 else np.inf)
    cap = 4 * (n + m) + 16
    while (np.floor((x1 - x0) / size) + 1.0) * (np.floor((y1 - y0) / size) + 1.0) > cap:
        size *= 2.0
    nbx = int((x1 - x0) / size) + 1
    nby = int((y1 - y0) / size) + 1
    head = np.full(nbx * nby, -1, dtype=np.int64)  # first chosen point of each bucket
    nxt = np.empty(n, dtype=np.int64)  # the next one in the same bucket
    for j in range(count):
        b = _bucket(chosen[j, 0], chosen[j, 1], x0, y0, size, nbx, nby)
        nxt[j] = head[b]
        head[b] = j
    for i in range(m):
        if count == n:
            break
        px = candidates[i, 0]
        py = candidates[i, 1]
        b = _bucket(px, py, x0, y0, size, nbx, nby)
        bx = b % nbx
        by = b // nbx
        free = True
        for yy in range(max(by - 1, 0), min(by + 2, nby)):
            for xx in range(max(bx - 1, 0), min(bx + 2, nbx)):
                j = head[yy * nbx + xx]
                while j >= 0 and free:
                    if not np.hypot(px - chosen[j, 0], py - chosen[j, 1]) >= min_gap:
                        free = False
                    j = nxt[j]
        if free:
            chosen[count, 0] = px
            chosen[count, 1] = py
            nxt[count] = head[b]
            head[b] = count
            count += 1
    return count


@njit(cache=True)
def _bucket(x: float, y: float, x0: float, y0: float, size: float, nbx: int, nby: int) -> int:
    """Flat index of the bucket of ``(x, y)`` (clamped: clamping keeps neighbours adjacent)."""
    bx = min(max(int((x - x0) / size), 0), nbx - 1)
    by = min(max(int((y - y0) / size), 0), nby - 1)
    return by * nbx + bx


def line_of_sight(
    grid: OccupancyGrid, allowed: NDArray[np.bool_], a: NDArray[np.float64], b: NDArray[np.float64]
) -> bool:
    """Whether the segment ``a→b`` stays inside the ``allowed`` mask (sampled every 1/3 cell)."""
    length = float(np.hypot(*(b - a)))
    k = max(int(np.ceil(length / (grid.resolution / 3.0))), 1)
    t = np.linspace(0.0, 1.0, k + 1)[:, None]
    pts = a + t * (b - a)
    cells = grid.world_to_cell(pts)
    if not np.all(grid.in_bounds(cells)):
        return False
    return bool(np.all(allowed[cells[:, 0], cells[:, 1]]))


class MaskRegions:
    """The 8-connected regions of a bool mask, each found when first asked for.

    A region is what :func:`components` labels alike; here it is built from the mask's runs
    (maximal horizontal stretches of set cells) by a search from one seed, so a caller that
    needs the regions of a few cells only (a reset's pedestrian starts, which nearly all lie in
    one region) neither labels the rest of the map nor sorts its cells by label.

    Args:
        mask: ``(H, W)`` bool; not copied, so it must not change while this object is used.
    """

    def __init__(self, mask: NDArray[np.bool_]) -> None:
        self.mask = np.ascontiguousarray(mask, dtype=np.bool_)
        self._row_ptr, self._c0, self._c1 = _mask_runs(self.mask)
        self._run_label = np.zeros(len(self._c0), dtype=np.int32)
        self._cells: list[NDArray[np.int64]] = [np.zeros((0, 2), dtype=np.int64)]

    def cells(self, row: int, col: int) -> NDArray[np.int64]:
        """``(k, 2)`` ``[row, col]`` cells of the region of cell ``(row, col)``, row-major.

        Empty if the cell is not in the mask. Indices follow numpy's rules (negative ones count
        from the end, too large ones raise ``IndexError``), as ``labels[row, col]`` would.
        """
        if not self.mask[row, col]:
            return self._cells[0]
        h, w = self.mask.shape
        r, c = int(row) % h, int(col) % w
        run = _find_run(self._row_ptr, self._c0, self._c1, r, c)
        label = int(self._run_label[run])
        if label == 0:
            label = len(self._cells)
            _fill_runs(self._row_ptr, self._c0, self._c1, self._run_label, run, label)
            cells = _region_cells(self._row_ptr, self._c0, self._c1, self._run_label, label)
            self._cells.append(cells)
        return self._cells[label]


@njit(cache=True)
def _mask_runs(
    mask: NDArray[np.bool_],
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Runs of set cells, row by row: row ``r`` has runs ``row_ptr[r] : row_ptr[r + 1]``.

    Run ``j`` covers the columns ``c0[j] <= c < c1[j]``.
    """
    h, w = mask.shape
    row_ptr = np.empty(h + 1, dtype=np.int64)
    c0 = np.empty(h * ((w + 1) // 2), dtype=np.int64)
    c1 = np.empty_like(c0)
    n = 0
    for r in range(h):
        row_ptr[r] = n
        c = 0
        while c < w:
            if mask[r, c]:
                start = c
                while c < w and mask[r, c]:
                    c += 1
                c0[n] = start
                c1[n] = c
                n += 1
            else:
                c += 1
    row_ptr[h] = n
    return row_ptr, c0[:n].copy(), c1[:n].copy()


@njit(cache=True)
def _find_run(
    row_ptr: NDArray[np.int64], c0: NDArray[np.int64], c1: NDArray[np.int64], r: int, c: int
) -> int:
    """The run holding cell ``(r, c)`` (which must be set)."""
    for j in range(row_ptr[r], row_ptr[r + 1]):
        if c0[j] <= c < c1[j]:
            return j
    return -1


@njit(cache=True)
def _fill_runs(
    row_ptr: NDArray[np.int64],
    c0: NDArray[np.int64],
    c1: NDArray[np.int64],
    run_label: NDArray[np.int32],
    seed: int,
    label: int,
) -> None:
    """Label every run 8-connected to run ``seed`` (runs of adjacent rows touching or diagonal)."""
    h = row_ptr.shape[0] - 1
    row_of = np.empty(c0.shape[0], dtype=np.int64)
    for r in range(h):
        for j in range(row_ptr[r], row_ptr[r + 1]):
            row_of[j] = r
    stack = np.empty(c0.shape[0], dtype=np.int64)
    run_label[seed] = label
    stack[0] = seed
    top = 1
    while top > 0:
        top -= 1
        j = stack[top]
        r = row_of[j]
        for rr in (r - 1, r + 1):
            if rr < 0 or rr >= h:
                continue
            for k in range(row_ptr[rr], row_ptr[rr + 1]):
                # 8-connected: the runs overlap once the neighbour row's run is widened by one.
                if c0[k] <= c1[j] and c1[k] >= c0[j] and run_label[k] != label:
                    run_label[k] = label
                    stack[top] = k
                    top += 1


@njit(cache=True)
def _region_cells(
    row_ptr: NDArray[np.int64],
    c0: NDArray[np.int64],
    c1: NDArray[np.int64],
    run_label: NDArray[np.int32],
    label: int,
) -> NDArray[np.int64]:
    """``(k, 2)`` cells of the runs labelled ``label``, row-major (the order of the runs)."""
    count = 0
    for j in range(c0.shape[0]):
        if run_label[j] == label:
            count += c1[j] - c0[j]
    out = np.empty((count, 2), dtype=np.int64)
    h = row_ptr.shape[0] - 1
    k = 0
    for r in range(h):
        for j in range(row_ptr[r], row_ptr[r + 1]):
            if run_label[j] == label:
                for c in range(c0[j], c1[j]):
                    out[k, 0] = r
                    out[k, 1] = c
                    k += 1
    return out


def clear_near(
    walkable: NDArray[np.bool_],
    cells: NDArray[np.int64],
    max_sq: int,
) -> None:
    """Clear, in place, every cell of ``walkable`` within ``max_sq`` (cells²) of a given cell.

    A cell is cleared when its squared centre distance ``dr² + dc²`` to one of ``cells``
    ``(k, 2)`` (``[row, col]``, on the map) is at most ``max_sq``, the cells themselves
    included. This is the change that adding ``cells`` to the blocked set makes to a
    :func:`clearance_map` thresholded at a clearance (see :func:`max_blocked_sq`): squared
    distance transforms are exact, so that of a union is the minimum of the parts'.
    """
    if len(cells) and max_sq >= 0:
        _clear_near(walkable, np.ascontiguousarray(cells, dtype=np.int64), max_sq)


@njit(cache=True)
def _clear_near(walkable: NDArray[np.bool_], cells: NDArray[np.int64], max_sq: int) -> None:
    h, w = walkable.shape
    reach = 0
    while (reach + 1) * (reach + 1) <= max_sq:
        reach += 1
    # Half-widths of the disc per row offset.
    half = np.empty(2 * reach + 1, dtype=np.int64)
    for dr in range(-reach, reach + 1):
        k = 0
        while (k + 1) * (k + 1) + dr * dr <= max_sq:
            k += 1
        half[dr + reach] = k
    # Only cells on the set's border (an 8-neighbour outside it, or the map edge) can be the
    # nearest member for a cell outside the set; interior members are cleared one by one.
    member = np.zeros((h, w), dtype=np.bool_)
    for i in range(cells.shape[0]):
        member[cells[i, 0], cells[i, 1]] = True
    for i in range(cells.shape[0]):
        r = cells[i, 0]
        c = cells[i, 1]
        walkable[r, c] = False
        interior = True
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                rr = r + dr
                cc = c + dc
                if rr < 0 or rr >= h or cc < 0 or cc >= w or not member[rr, cc]:
                    interior = False
        if interior:
            continue
        for dr in range(-reach, reach + 1):
            rr = r + dr
            if rr < 0 or rr >= h:
                continue
            k = half[dr + reach]
            for cc in range(max(c - k, 0), min(c + k + 1, w)):
                walkable[rr, cc] = False


def max_blocked_sq(resolution: float, clearance: float) -> int:
    """Largest squared cell distance ``d²`` at which ``clearance_map`` is ``<= clearance``.

    The same float operations as :func:`clearance_map` (``sqrt(d²) · res - res / 2``) on each
    integer ``d²``; they are non-decreasing in ``d²``, so ``clearance_map > clearance`` exactly
    where ``d² > max_blocked_sq``. -1 if no distance is that close.
    """

    def value(d2: int) -> float:
        return float(np.sqrt(np.float64(d2)) * resolution - 0.5 * resolution)

    if value(0) > clearance:
        return -1
    d2 = max(int(((clearance + 0.5 * resolution) / resolution) ** 2) - 2, 0)
    while d2 > 0 and value(d2) > clearance:
        d2 -= 1
    while value(d2 + 1) <= clearance:
        d2 += 1
    return d2
