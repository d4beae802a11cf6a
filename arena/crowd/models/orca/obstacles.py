"""Static obstacles of :mod:`arena.crowd.models.orca` in RVO2's representation.

:class:`Obstacles` holds RVO2's obstacle vertices (linked polygons, convexity flags), its
obstacle k-d tree and a grid of edges for the neighbour query, built once per world and passed
to :func:`~arena.crowd.models.orca.kernels.orca_kernel`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.models.orca.kernels import RVO_EPSILON, _left_of

FloatArray = NDArray[np.floating]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

_MAX_CELLS = 4_000_000  # obstacle grid cap; coarser cells beyond it
_EMPTY: dict[str, Obstacles] = {}  # Obstacles.empty() per dtype: built once, not every step


# ---------------------------------------------------------------------------------------------
# Static obstacles in RVO2's representation
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Obstacles:
    """Static obstacles as RVO2 stores them: polygon vertices linked into edges.

    Vertex ``k`` starts the edge ``k → next[k]``. Polygons run counter-clockwise (the blocked
    side is left of each edge); a 2-vertex obstacle is a line segment blocked from both sides
    (edges ``a → b`` and ``b → a``), as in RVO2's ``addObstacle``. An agent considers an edge
    only while it is on the edge's right, so a segment acts once, from the agent's side.

    RVO2's ``processObstacles`` builds a k-d tree over the edges and splits every edge that
    crosses a splitting edge's line into two, inserting a collinear convex vertex. We run the
    same build once (same splits, same vertex numbering) and keep the tree only as
    ``parent``/``side``/``depth`` links: the neighbour search itself uses a uniform grid, and the
    tree decides the order of exactly equidistant edges (RVO2 inserts neighbours in tree
    traversal order, and the order matters for its "already covered" checks).

    Attributes:
        point: ``(m, 2)`` vertex positions (m).
        direction: ``(m, 2)`` unit vector from each vertex to the next.
        next: ``(m,)`` index of the next vertex.
        prev: ``(m,)`` index of the previous vertex.
        convex: ``(m,)`` RVO2's ``isConvex`` (always true for 2-vertex obstacles and splits).
        parent: ``(m,)`` the edge's parent in RVO2's obstacle tree (-1 at the root).
        side: ``(m,)`` 0 if the edge is in its parent's left subtree, 1 if right (-1 at root).
        depth: ``(m,)`` depth in the tree (root 0).
        cell0: ``(m, 2)`` first grid cell ``(cx, cy)`` of each edge's bounding box.
        starts: ``(nx·ny + 1,)`` CSR offsets of the grid cells (row-major, ``cy·nx + cx``).
        items: edge indices, cell by cell (each edge in every cell its bounding box touches).
        origin: ``(2,)`` grid origin (m).
        cell: grid cell edge (m).
        shape: ``(nx, ny)``.
    """

    point: FloatArray
    direction: FloatArray
    next: IntArray
    prev: IntArray
    convex: BoolArray
    parent: IntArray
    side: IntArray
    depth: IntArray
    cell0: IntArray
    starts: IntArray
    items: IntArray
    origin: NDArray[np.float64]
    cell: float
    shape: tuple[int, int]

    def __len__(self) -> int:
        return int(self.point.shape[0])

    def kernel_args(self, dtype: type = np.float64) -> tuple[object, ...]:
        """The arrays and grid constants as :func:`orca_kernel` takes them (geometry in dtype)."""
        return (
            np.ascontiguousarray(self.point, dtype=dtype),
            np.ascontiguousarray(self.direction, dtype=dtype),
            self.next,
            self.prev,
            self.convex,
            self.parent,
            self.side,
            self.depth,
            self.cell0,
            self.starts,
            self.items,
            float(self.origin[0]),
            float(self.origin[1]),
            float(self.cell),
            int(self.shape[0]),
            int(self.shape[1]),
        )

    @classmethod
    def empty(cls, dtype: type = np.float64) -> Obstacles:
        """No obstacles (one shared, immutable instance per dtype)."""
        key = np.dtype(dtype).str
        if key not in _EMPTY:
            _EMPTY[key] = cls.from_polygons([], dtype=dtype)
        return _EMPTY[key]

    @classmethod
    def from_segments(
        cls, a: FloatArray, b: FloatArray, cell: float = 4.0, dtype: type = np.float64
    ) -> Obstacles:
        """Each segment ``a[k] → b[k]`` as a 2-vertex RVO2 obstacle (vertices ``2k``, ``2k+1``).

        Zero-length segments are dropped (RVO2 would divide by their length).

        Args:
            a: ``(s, 2)`` segment starts (m).
            b: ``(s, 2)`` segment ends (m).
            cell: grid cell edge (m); about the obstacle range is a good choice.
            dtype: float type of the geometry (float32 reproduces the C++ library bit for bit).
        """
        a = np.asarray(a, dtype=np.float64).reshape(-1, 2)
        b = np.asarray(b, dtype=np.float64).reshape(-1, 2)
        keep = np.any(a != b, axis=1)
        return cls.from_polygons(list(np.stack([a[keep], b[keep]], axis=1)), cell=cell, dtype=dtype)

    @classmethod
    def from_polygons(
        cls, polygons: Sequence[FloatArray], cell: float = 4.0, dtype: type = np.float64
    ) -> Obstacles:
        """RVO2's ``addObstacle`` for each polygon, then its ``processObstacles``.

        Args:
            polygons: ``(k, 2)`` vertex lists (m), counter-clockwise; ``k = 2`` is a segment,
                ``k < 2`` is skipped.
            cell: grid cell edge (m).
            dtype: float type of the geometry.
        """
        one = dtype(1.0)
        pts, dirs, nxt, prv, cvx = [np.zeros((0, 2), dtype)], [np.zeros((0, 2), dtype)], [], [], []
        base = 0
        for poly in polygons:
            v = np.asarray(poly, dtype=dtype).reshape(-1, 2)
            k = v.shape[0]
            if k < 2:
                continue
            idx = np.arange(k)
            succ, pred = (idx + 1) % k, (idx - 1) % k
            d = v[succ] - v
            # RVO2's normalize multiplies by the reciprocal of the length (same rounding).
            inv = one / np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
            dirs.append(d * inv[:, None])
            if k == 2:
                cvx.append(np.ones(k, dtype=np.bool_))
            else:
                # leftOf(prev, this, next) = det(prev - next, this - prev) >= 0
                p, q = v[pred] - v[succ], v - v[pred]
                cvx.append(p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0] >= 0)
            pts.append(v)
            nxt.append(base + succ)
            prv.append(base + pred)
            base += k
        ints = [np.zeros(0, np.int64)]
        tree = _process_obstacles(
            np.concatenate(pts),
            np.concatenate(dirs),
            np.concatenate(nxt + ints).astype(np.int64),
            np.concatenate(prv + ints).astype(np.int64),
            np.concatenate([*cvx, np.zeros(0, np.bool_)]),
        )
        return cls._with_grid(*tree, cell=cell)

    @classmethod
    def _with_grid(
        cls,
        point: FloatArray,
        direction: FloatArray,
        nxt: IntArray,
        prv: IntArray,
        convex: BoolArray,
        parent: IntArray,
        side: IntArray,
        depth: IntArray,
        cell: float,
    ) -> Obstacles:
        m = point.shape[0]
        p64 = point.astype(np.float64)
        lo = np.minimum(p64, p64[nxt]) if m else np.zeros((0, 2))
        hi = np.maximum(p64, p64[nxt]) if m else np.zeros((0, 2))
        origin = lo.min(axis=0) if m else np.zeros(2)
        cell = max(float(cell), 1e-3)
        ext = hi.max(axis=0) - origin if m else np.zeros(2)
        nx, ny = (int(e // cell) + 1 for e in ext)
        while nx * ny > _MAX_CELLS:  # sparse, huge extents: coarser cells, still correct
            cell *= 2.0
            nx, ny = (int(e // cell) + 1 for e in ext)
        c0 = np.minimum(((lo - origin) // cell).astype(np.int64), [nx - 1, ny - 1])
        c1 = np.minimum(((hi - origin) // cell).astype(np.int64), [nx - 1, ny - 1])
        starts, items = _bin_edges(c0.reshape(-1, 2), c1.reshape(-1, 2), nx, ny)
        return cls(
            point,
            direction,
            nxt,
            prv,
            convex,
            parent,
            side,
            depth,
            c0.reshape(-1, 2),
            starts,
            items,
            origin,
            cell,
            (nx, ny),
        )


def _process_obstacles(
    point: FloatArray, direction: FloatArray, nxt: IntArray, prv: IntArray, convex: BoolArray
) -> tuple[FloatArray, FloatArray, IntArray, IntArray, BoolArray, IntArray, IntArray, IntArray]:
    """RVO2's obstacle k-d tree build: split edges, return the vertices and the tree links."""
    cap = 2 * point.shape[0] + 16
    while True:
        out = _build_obstacle_tree(point, direction, nxt, prv, convex, cap)
        count = int(out[-1])
        if count >= 0:
            return tuple(a[:count] for a in out[:-1])  # type: ignore[return-value]
        cap *= 2  # more splits than room: retry with more


@njit(cache=True, error_model="numpy")
def _build_obstacle_tree(point, direction, nxt, prv, convex, cap):
    """``KdTree::buildObstacleTreeRecursive``, depth first, left before right, as RVO2 does.

    Returns the grown arrays, the tree links and the vertex count (-1 if ``cap`` is too small).
    """
    m = point.shape[0]
    pt = np.empty((cap, 2), dtype=point.dtype)
    dr = np.empty((cap, 2), dtype=point.dtype)
    nx_ = np.empty(cap, dtype=np.int64)
    pv = np.empty(cap, dtype=np.int64)
    cv = np.empty(cap, dtype=np.bool_)
    parent = np.full(cap, -1, dtype=np.int64)
    side = np.full(cap, -1, dtype=np.int64)
    depth = np.zeros(cap, dtype=np.int64)
    pt[:m], dr[:m], nx_[:m], pv[:m], cv[:m] = point, direction, nxt, prv, convex
    eps = np.full(1, RVO_EPSILON, dtype=point.dtype)[0]
    count = m
    # Work items: an obstacle list and its (parent edge, side, depth).
    stack = [np.arange(m, dtype=np.int64)]
    meta = np.empty((cap + 1, 3), dtype=np.int64)  # at most one pending item per edge
    meta[0] = (-1, -1, 0)
    if m == 0:
        stack.pop()
    while len(stack) > 0:
        obs = stack.pop()
        par, sd, dep = meta[len(stack)]
        n = obs.shape[0]
        # The splitter that minimises (max(left, right), min(left, right)).
        best_i, min_left, min_right = 0, n, n
        for i in range(n):
            i1 = obs[i]
            i2 = nx_[i1]
            left_size, right_size = 0, 0
            for j in range(n):
                if i == j:
                    continue
                j1 = obs[j]
                j2 = nx_[j1]
                a = _left_of(pt[i1, 0], pt[i1, 1], pt[i2, 0], pt[i2, 1], pt[j1, 0], pt[j1, 1])
                b = _left_of(pt[i1, 0], pt[i1, 1], pt[i2, 0], pt[i2, 1], pt[j2, 0], pt[j2, 1])
                if a >= -eps and b >= -eps:
                    left_size += 1
                elif a <= eps and b <= eps:
                    right_size += 1
                else:
                    left_size += 1
                    right_size += 1
                if (max(left_size, right_size), min(left_size, right_size)) >= (
                    max(min_left, min_right),
                    min(min_left, min_right),
                ):
                    break
            if (max(left_size, right_size), min(left_size, right_size)) < (
                max(min_left, min_right),
                min(min_left, min_right),
            ):
                best_i, min_left, min_right = i, left_size, right_size
        if count + n > cap:
            return pt, dr, nx_, pv, cv, parent, side, depth, -1
        left = np.empty(min_left, dtype=np.int64)
        right = np.empty(min_right, dtype=np.int64)
        n_left, n_right = 0, 0
        i1 = obs[best_i]
        i2 = nx_[i1]
        for j in range(n):
            if j == best_i:
                continue
            j1 = obs[j]
            j2 = nx_[j1]
            a = _left_of(pt[i1, 0], pt[i1, 1], pt[i2, 0], pt[i2, 1], pt[j1, 0], pt[j1, 1])
            b = _left_of(pt[i1, 0], pt[i1, 1], pt[i2, 0], pt[i2, 1], pt[j2, 0], pt[j2, 1])
            if a >= -eps and b >= -eps:
                left[n_left] = j1
                n_left += 1
            elif a <= eps and b <= eps:
                right[n_right] = j1
                n_right += 1
            else:
                # Split edge j1 → j2 where it crosses the splitter's line.
                ex, ey = pt[i2, 0] - pt[i1, 0], pt[i2, 1] - pt[i1, 1]
                t = (ex * (pt[j1, 1] - pt[i1, 1]) - ey * (pt[j1, 0] - pt[i1, 0])) / (
                    ex * (pt[j1, 1] - pt[j2, 1]) - ey * (pt[j1, 0] - pt[j2, 0])
                )
                new = count
                count += 1
                pt[new, 0] = pt[j1, 0] + t * (pt[j2, 0] - pt[j1, 0])
                pt[new, 1] = pt[j1, 1] + t * (pt[j2, 1] - pt[j1, 1])
                dr[new] = dr[j1]
                nx_[new] = j2
                pv[new] = j1
                cv[new] = True
                nx_[j1] = new
                pv[j2] = new
                if a > 0.0:
                    left[n_left] = j1
                    right[n_right] = new
                else:
                    right[n_right] = j1
                    left[n_left] = new
                n_left += 1
                n_right += 1
        parent[i1], side[i1], depth[i1] = par, sd, dep
        # Stack: push right first so the left subtree is built (and numbered) first.
        if n_right > 0:
            meta[len(stack)] = (i1, 1, dep + 1)
            stack.append(right)
        if n_left > 0:
            meta[len(stack)] = (i1, 0, dep + 1)
            stack.append(left)
    return pt, dr, nx_, pv, cv, parent, side, depth, count


@njit(cache=True)
def _bin_edges(c0: IntArray, c1: IntArray, nx: int, ny: int) -> tuple[IntArray, IntArray]:
    """CSR lists of the edges whose bounding-box cells ``c0..c1`` cover each grid cell."""
    m = c0.shape[0]
    starts = np.zeros(nx * ny + 1, dtype=np.int64)
    for e in range(m):
        for cy in range(c0[e, 1], c1[e, 1] + 1):
            for cx in range(c0[e, 0], c1[e, 0] + 1):
                starts[cy * nx + cx + 1] += 1
    for c in range(nx * ny):
        starts[c + 1] += starts[c]
    fill = starts[:-1].copy()
    items = np.empty(starts[-1], dtype=np.int64)
    for e in range(m):
        for cy in range(c0[e, 1], c1[e, 1] + 1):
            for cx in range(c0[e, 0], c1[e, 0] + 1):
                c = cy * nx + cx
                items[fill[c]] = e
                fill[c] += 1
    return starts, items
