"""ORCA: optimal reciprocal collision avoidance among pedestrians, computed as RVO2 does.

Each agent picks the velocity closest to its preferred velocity that lies outside every
neighbour's velocity obstacle truncated at ``time_horizon`` (van den Berg, Guy, Lin, Manocha,
"Reciprocal n-body collision avoidance", ISRR 2009). Each velocity obstacle becomes one ORCA
half-plane (each of two reciprocating agents takes half the avoidance); the 2-D linear program
over the half-planes inside the max-speed disk is solved incrementally (RVO2's
``linearProgram1/2``), and when it is infeasible the 3-D fallback (``linearProgram3``) finds the
velocity that violates the soft (agent) constraints least while keeping the hard (obstacle) ones.

This module re-implements RVO2's ``Agent::computeNeighbors``/``computeNewVelocity`` and its
obstacle processing (v2.0, Apache-2.0, https://gamma.cs.unc.edu/RVO2/) in numba, with the same
order of floating-point operations: run in float32 (the C++ library's ``float``), the kernel
reproduces the library step for step; the models run in float64 and differ from it by float32
rounding only (below a millimetre over 100 steps of the reference scenarios; a chaotic crowd
amplifies any difference eventually). What differs, and why:

* Neighbour search: the simulator's cell list lists every pedestrian closer than
  ``neighbor_dist``; the kernel keeps the ``max_neighbors`` nearest of them, nearest first, as
  RVO2's k-d tree query does. Exact distance ties are broken by agent index (RVO2: by k-d tree
  traversal order).
* Robots are non-reciprocating moving obstacles: an ORCA line with the robot's velocity and
  full responsibility (the robot does not make room), after the pedestrian lines, not counted
  in ``max_neighbors``. Inactive agents (not started or finished) stand still, so their
  neighbours take full responsibility for them too.
* Agent parameters are per model (``Params``), except the radius (``state.radii`` plus a
  ``safety_margin``) and the max speed (``state.vmax · state.vmax_factor``, the simulator's
  speed cap), which are per agent. The preferred velocity is RVO2's examples' (toward the
  destination at the max speed, slowing on the last metre), with their tiny random nudge.

Static obstacles (RVO2's obstacle ORCA lines) are in the same kernel; the ``orca`` model passes
none, :mod:`arena.crowd.models.rvo2` passes the world's walls.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.state import CrowdState
from arena.scene.state import StaticWorld

FloatArray = NDArray[np.floating]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

RVO_EPSILON = 1e-5
"""RVO2's tolerance for parallel lines and "already covered" obstacle checks."""

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


@njit(cache=True, error_model="numpy", inline="always")
def _left_of(ax, ay, bx, by, cx, cy):
    # RVO2's leftOf(a, b, c) = det(a - c, b - a): > 0 when c is left of a → b.
    return (ax - cx) * (by - ay) - (ay - cy) * (bx - ax)


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


# ---------------------------------------------------------------------------------------------
# Preferred velocity
# ---------------------------------------------------------------------------------------------
def preferred_velocities(
    positions: FloatArray, destinations: FloatArray, speeds: FloatArray, arrival_time: float
) -> FloatArray:
    """Toward the destination at ``speeds``, slowing to arrive within ``arrival_time``.

    RVO2's examples (``Circle``, ``Blocks``) use the goal vector, normalised when longer than
    1 m, with unit preferred speed: that is ``speeds = 1``, ``arrival_time = 1``. In general the
    preferred velocity is ``d · min(speed / |d|, 1 / arrival_time)`` for ``d = destination − p``.

    Args:
        positions: ``(n, 2)`` m.
        destinations: ``(n, 2)`` m.
        speeds: ``(n,)`` preferred speed (m/s).
        arrival_time: s, the preferred velocity on the last ``speed · arrival_time`` metres.

    Returns:
        ``(n, 2)`` m/s.
    """
    d = np.asarray(destinations, dtype=np.float64) - positions
    dist = np.hypot(d[:, 0], d[:, 1])
    far = dist > speeds * arrival_time
    scale = np.where(far, speeds / np.where(far, dist, 1.0), 1.0 / arrival_time)
    return d * scale[:, None]


# ---------------------------------------------------------------------------------------------
# The kernel: RVO2's Agent::computeNeighbors + computeNewVelocity and its linear programs
# ---------------------------------------------------------------------------------------------
# Conventions (all numba, generic in the float type T of the inputs so that a float32 run
# rounds exactly like the C++ library):
#   lines: (L, 4) rows [direction x, direction y, point x, point y]; an ORCA half-plane allows
#          the velocities left of the directed line.
#   c:     typed constants (zero, half, one, eps, inf); a Python literal in arithmetic would
#          silently promote float32 to float64.
# Vector expressions are written out in RVO2's operand order; RVO2's vector division multiplies
# by the reciprocal, so we do too.
_JIT = {"cache": True, "error_model": "numpy"}  # numpy model: no ZeroDivisionError checks
_INLINE = {**_JIT, "inline": "always"}  # small hot helpers: numba call overhead dominates


@njit(**_INLINE)
def _normalize(x, y, one):
    inv = one / math.sqrt(x * x + y * y)
    return x * inv, y * inv


@njit(**_JIT)
def _lp1(lines, line_no, radius, optx, opty, direction_opt, c):
    """linearProgram1: the optimum on line ``line_no`` subject to lines ``0..line_no-1``.

    Returns ``(feasible, rx, ry)``.
    """
    dx, dy, px, py = lines[line_no, 0], lines[line_no, 1], lines[line_no, 2], lines[line_no, 3]
    dot = px * dx + py * dy
    disc = dot * dot + radius * radius - (px * px + py * py)
    if disc < 0.0:
        return False, px, py  # the max-speed circle fully invalidates this line
    sq = math.sqrt(disc)
    t_left = -dot - sq
    t_right = -dot + sq
    for i in range(line_no):
        denominator = dx * lines[i, 1] - dy * lines[i, 0]
        numerator = lines[i, 0] * (py - lines[i, 3]) - lines[i, 1] * (px - lines[i, 2])
        if abs(denominator) <= c[3]:
            # Lines line_no and i are (almost) parallel.
            if numerator < 0.0:
                return False, px, py
            continue
        t = numerator / denominator
        if denominator >= 0.0:
            t_right = min(t_right, t)  # line i bounds line_no on the right
        else:
            t_left = max(t_left, t)  # line i bounds line_no on the left
        if t_left > t_right:
            return False, px, py
    if direction_opt:
        if optx * dx + opty * dy > 0.0:
            return True, px + t_right * dx, py + t_right * dy
        return True, px + t_left * dx, py + t_left * dy
    t = dx * (optx - px) + dy * (opty - py)
    if t < t_left:
        return True, px + t_left * dx, py + t_left * dy
    if t > t_right:
        return True, px + t_right * dx, py + t_right * dy
    return True, px + t * dx, py + t * dy


@njit(**_JIT)
def _lp2(lines, n_lines, radius, optx, opty, direction_opt, c):
    """linearProgram2: returns ``(index of the first infeasible line or n_lines, rx, ry)``."""
    if direction_opt:
        rx, ry = optx * radius, opty * radius  # opt is a unit direction here
    elif optx * optx + opty * opty > radius * radius:
        nx, ny = _normalize(optx, opty, c[2])
        rx, ry = nx * radius, ny * radius
    else:
        rx, ry = optx, opty
    for i in range(n_lines):
        if lines[i, 0] * (lines[i, 3] - ry) - lines[i, 1] * (lines[i, 2] - rx) > 0.0:
            # The result violates line i: the new optimum lies on it.
            ok, nrx, nry = _lp1(lines, i, radius, optx, opty, direction_opt, c)
            if not ok:
                return i, rx, ry
            rx, ry = nrx, nry
    return n_lines, rx, ry


@njit(**_JIT)
def _lp3(lines, n_lines, n_obst, begin, radius, rx, ry, proj, c):
    """linearProgram3: minimise the largest violation of the soft lines, keeping the hard ones.

    Lines ``0..n_obst-1`` (obstacles) are hard; ``proj`` is scratch for the projected lines.
    """
    distance = c[0]
    for i in range(begin, n_lines):
        dxi, dyi, pxi, pyi = lines[i, 0], lines[i, 1], lines[i, 2], lines[i, 3]
        if dxi * (pyi - ry) - dyi * (pxi - rx) > distance:
            # The result violates line i more than the worst so far: optimise on it.
            proj[:n_obst] = lines[:n_obst]
            nq = n_obst
            for j in range(n_obst, i):
                dxj, dyj, pxj, pyj = lines[j, 0], lines[j, 1], lines[j, 2], lines[j, 3]
                determinant = dxi * dyj - dyi * dxj
                if abs(determinant) <= c[3]:
                    # Lines i and j are parallel.
                    if dxi * dxj + dyi * dyj > 0.0:
                        continue  # same direction
                    proj[nq, 2] = c[1] * (pxi + pxj)
                    proj[nq, 3] = c[1] * (pyi + pyj)
                else:
                    s = (dxj * (pyi - pyj) - dyj * (pxi - pxj)) / determinant
                    proj[nq, 2] = pxi + s * dxi
                    proj[nq, 3] = pyi + s * dyi
                proj[nq, 0], proj[nq, 1] = _normalize(dxj - dxi, dyj - dyi, c[2])
                nq += 1
            fail, nrx, nry = _lp2(proj, nq, radius, -dyi, dxi, True, c)
            # Failure would only be floating-point error (the result is feasible by
            # construction); RVO2 then keeps the current result.
            if fail >= nq:
                rx, ry = nrx, nry
            distance = dxi * (pyi - ry) - dyi * (pxi - rx)
    return rx, ry


@njit(**_JIT)
def _obstacle_neighbors(px, py, rng, ob, ob_idx, ob_d):
    """Edges closer than ``rng`` that have the agent on their right, nearest first.

    RVO2's obstacle query over a grid instead of its k-d tree; exactly equidistant edges are
    ordered as RVO2's tree traversal meets them. Fills ``ob_idx``/``ob_d``, returns the count.
    """
    point, _, nxt, _, _, parent, side, depth, cell0, starts, items, ox, oy, cell, nx, ny = ob
    if point.shape[0] == 0:
        return 0
    range_sq = rng * rng
    r64 = float(rng)
    qx0 = min(max(math.floor((float(px) - r64 - ox) / cell), 0), nx - 1)
    qx1 = min(max(math.floor((float(px) + r64 - ox) / cell), 0), nx - 1)
    qy0 = min(max(math.floor((float(py) - r64 - oy) / cell), 0), ny - 1)
    qy1 = min(max(math.floor((float(py) + r64 - oy) / cell), 0), ny - 1)
    n_ob = 0
    for cy in range(qy0, qy1 + 1):
        for cx in range(qx0, qx1 + 1):
            cid = cy * nx + cx
            for s in range(starts[cid], starts[cid + 1]):
                e = items[s]
                # An edge is listed in every cell of its box: test it in the first shared one.
                if cx != max(qx0, cell0[e, 0]) or cy != max(qy0, cell0[e, 1]):
                    continue
                e2 = nxt[e]
                ax, ay = point[e, 0], point[e, 1]
                bx, by = point[e2, 0], point[e2, 1]
                left = _left_of(ax, ay, bx, by, px, py)
                len_sq = (bx - ax) * (bx - ax) + (by - ay) * (by - ay)
                # RVO2 tests the distance to the edge's line, then (right side only) the edge.
                if not (left * left / len_sq < range_sq and left < 0.0):
                    continue
                r = ((px - ax) * (bx - ax) + (py - ay) * (by - ay)) / len_sq
                if r < 0.0:
                    d_sq = (px - ax) * (px - ax) + (py - ay) * (py - ay)
                elif r > 1.0:
                    d_sq = (px - bx) * (px - bx) + (py - by) * (py - by)
                else:
                    qx = px - (ax + r * (bx - ax))
                    qy = py - (ay + r * (by - ay))
                    d_sq = qx * qx + qy * qy
                if not d_sq < range_sq:
                    continue
                # Insertion sort by distance; ties in RVO2's traversal order.
                k = n_ob
                while k > 0 and (
                    d_sq < ob_d[k - 1]
                    or (
                        d_sq == ob_d[k - 1]
                        and _visited_first(
                            e, ob_idx[k - 1], px, py, point, nxt, parent, side, depth
                        )
                    )
                ):
                    ob_d[k] = ob_d[k - 1]
                    ob_idx[k] = ob_idx[k - 1]
                    k -= 1
                ob_d[k] = d_sq
                ob_idx[k] = e
                n_ob += 1
    return n_ob


@njit(**_INLINE)
def _visited_first(e, f, px, py, point, nxt, parent, side, depth):
    """Whether RVO2's obstacle-tree query from ``p`` meets edge ``e`` before edge ``f``.

    At each node the query descends first into the subtree on the agent's side of the node's
    edge, then tries the node's edge, then the other subtree (``queryObstacleTreeRecursive``).
    """
    a, b = e, f
    sa, sb = -1, -1  # the child side through which each walk reached the current node
    while depth[a] > depth[b]:
        sa, a = side[a], parent[a]
    while depth[b] > depth[a]:
        sb, b = side[b], parent[b]
    while a != b:
        sa, a = side[a], parent[a]
        sb, b = side[b], parent[b]
    n2 = nxt[a]
    near = 0 if _left_of(point[a, 0], point[a, 1], point[n2, 0], point[n2, 1], px, py) >= 0.0 else 1
    if sa == -1:
        return sb != near  # e is the common node: before f unless f is on the near side
    if sb == -1:
        return sa == near
    return sa == near


@njit(**_INLINE)
def _add(lines, k, dx, dy, px, py):
    lines[k, 0], lines[k, 1], lines[k, 2], lines[k, 3] = dx, dy, px, py
    return k + 1


@njit(**_JIT)
def _obstacle_lines(px, py, vx, vy, r, ito, ob_idx, n_ob, ob, lines, c):
    """RVO2's obstacle ORCA lines for the sorted edge neighbours; returns the line count."""
    point, direction, nxt, prv, convex = ob[0], ob[1], ob[2], ob[3], ob[4]
    zero, half, one, eps, inf = c
    nl = 0
    radius_sq = r * r
    for k in range(n_ob):
        o1 = ob_idx[k]
        o2 = nxt[o1]
        rp1x, rp1y = point[o1, 0] - px, point[o1, 1] - py
        rp2x, rp2y = point[o2, 0] - px, point[o2, 1] - py
        # Skip the edge if the lines so far already cover its velocity obstacle.
        covered = False
        for j in range(nl):
            dxj, dyj, pxj, pyj = lines[j, 0], lines[j, 1], lines[j, 2], lines[j, 3]
            a = (ito * rp1x - pxj) * dyj - (ito * rp1y - pyj) * dxj
            b = (ito * rp2x - pxj) * dyj - (ito * rp2y - pyj) * dxj
            if a - ito * r >= -eps and b - ito * r >= -eps:
                covered = True
                break
        if covered:
            continue
        dist_sq1 = rp1x * rp1x + rp1y * rp1y
        dist_sq2 = rp2x * rp2x + rp2y * rp2y
        ovx, ovy = point[o2, 0] - point[o1, 0], point[o2, 1] - point[o1, 1]
        s = (-rp1x * ovx + -rp1y * ovy) / (ovx * ovx + ovy * ovy)
        wx, wy = -rp1x - s * ovx, -rp1y - s * ovy
        dist_sq_line = wx * wx + wy * wy

        if s < 0.0 and dist_sq1 <= radius_sq:
            # Collision with the left vertex; ignored if non-convex.
            if convex[o1]:
                dx, dy = _normalize(-rp1y, rp1x, one)
                nl = _add(lines, nl, dx, dy, zero, zero)
            continue
        if s > 1.0 and dist_sq2 <= radius_sq:
            # Collision with the right vertex; ignored if non-convex or if the neighbouring
            # edge takes care of it.
            if convex[o2] and rp2x * direction[o2, 1] - rp2y * direction[o2, 0] >= 0.0:
                dx, dy = _normalize(-rp2y, rp2x, one)
                nl = _add(lines, nl, dx, dy, zero, zero)
            continue
        if s >= 0.0 and s <= 1.0 and dist_sq_line <= radius_sq:
            # Collision with the edge itself.
            nl = _add(lines, nl, -direction[o1, 0], -direction[o1, 1], zero, zero)
            continue

        # No collision: the legs. Seen obliquely, both legs can come from one vertex; at a
        # non-convex vertex the leg extends the cut-off line.
        if s < 0.0 and dist_sq_line <= radius_sq:
            if not convex[o1]:
                continue
            o2 = o1
            leg1 = math.sqrt(dist_sq1 - radius_sq)
            inv = one / dist_sq1
            llx, lly = (rp1x * leg1 - rp1y * r) * inv, (rp1x * r + rp1y * leg1) * inv
            rlx, rly = (rp1x * leg1 + rp1y * r) * inv, (-rp1x * r + rp1y * leg1) * inv
        elif s > 1.0 and dist_sq_line <= radius_sq:
            if not convex[o2]:
                continue
            o1 = o2
            leg2 = math.sqrt(dist_sq2 - radius_sq)
            inv = one / dist_sq2
            llx, lly = (rp2x * leg2 - rp2y * r) * inv, (rp2x * r + rp2y * leg2) * inv
            rlx, rly = (rp2x * leg2 + rp2y * r) * inv, (-rp2x * r + rp2y * leg2) * inv
        else:
            if convex[o1]:
                leg1 = math.sqrt(dist_sq1 - radius_sq)
                inv = one / dist_sq1
                llx, lly = (rp1x * leg1 - rp1y * r) * inv, (rp1x * r + rp1y * leg1) * inv
            else:
                llx, lly = -direction[o1, 0], -direction[o1, 1]
            if convex[o2]:
                leg2 = math.sqrt(dist_sq2 - radius_sq)
                inv = one / dist_sq2
                rlx, rly = (rp2x * leg2 + rp2y * r) * inv, (-rp2x * r + rp2y * leg2) * inv
            else:
                rlx, rly = direction[o1, 0], direction[o1, 1]

        # A leg never points into the neighbouring edge at a convex vertex: use that edge's
        # cut-off line instead; a velocity projected on such a "foreign" leg adds no line.
        left_nb = prv[o1]
        left_foreign = False
        right_foreign = False
        if convex[o1] and llx * -direction[left_nb, 1] - lly * -direction[left_nb, 0] >= 0.0:
            llx, lly = -direction[left_nb, 0], -direction[left_nb, 1]
            left_foreign = True
        if convex[o2] and rlx * direction[o2, 1] - rly * direction[o2, 0] <= 0.0:
            rlx, rly = direction[o2, 0], direction[o2, 1]
            right_foreign = True

        # Cut-off centres, and the current velocity projected on the velocity obstacle.
        lcx, lcy = ito * (point[o1, 0] - px), ito * (point[o1, 1] - py)
        rcx, rcy = ito * (point[o2, 0] - px), ito * (point[o2, 1] - py)
        cvx, cvy = rcx - lcx, rcy - lcy
        rho = r * ito
        t = half if o1 == o2 else ((vx - lcx) * cvx + (vy - lcy) * cvy) / (cvx * cvx + cvy * cvy)
        t_left = (vx - lcx) * llx + (vy - lcy) * lly
        t_right = (vx - rcx) * rlx + (vy - rcy) * rly

        if (t < 0.0 and t_left < 0.0) or (o1 == o2 and t_left < 0.0 and t_right < 0.0):
            # On the left cut-off circle.
            ux, uy = _normalize(vx - lcx, vy - lcy, one)
            nl = _add(lines, nl, uy, -ux, lcx + rho * ux, lcy + rho * uy)
            continue
        if t > 1.0 and t_right < 0.0:
            # On the right cut-off circle.
            ux, uy = _normalize(vx - rcx, vy - rcy, one)
            nl = _add(lines, nl, uy, -ux, rcx + rho * ux, rcy + rho * uy)
            continue

        # On the left leg, the right leg or the cut-off line, whichever is closest.
        d_cut, d_left, d_right = inf, inf, inf
        if not (t < 0.0 or t > 1.0 or o1 == o2):
            ex, ey = vx - (lcx + t * cvx), vy - (lcy + t * cvy)
            d_cut = ex * ex + ey * ey
        if not t_left < 0.0:
            ex, ey = vx - (lcx + t_left * llx), vy - (lcy + t_left * lly)
            d_left = ex * ex + ey * ey
        if not t_right < 0.0:
            ex, ey = vx - (rcx + t_right * rlx), vy - (rcy + t_right * rly)
            d_right = ex * ex + ey * ey

        if d_cut <= d_left and d_cut <= d_right:
            dx, dy = -direction[o1, 0], -direction[o1, 1]
            nl = _add(lines, nl, dx, dy, lcx + rho * -dy, lcy + rho * dx)
        elif d_left <= d_right:
            if not left_foreign:
                nl = _add(lines, nl, llx, lly, lcx + rho * -lly, lcy + rho * llx)
        elif not right_foreign:
            dx, dy = -rlx, -rly
            nl = _add(lines, nl, dx, dy, rcx + rho * -dy, rcy + rho * dx)
    return nl


@njit(**_INLINE)
def _agent_line(rpx, rpy, rvx, rvy, vx, vy, cr, ith, its, share, flip, c):
    """The ORCA line ``(dx, dy, px, py)`` induced by one neighbour.

    Args (scalars): relative position ``rp`` (neighbour − self), relative velocity ``rv``
    (self − neighbour), own velocity ``v``, combined radius ``cr``, ``1/time_horizon``,
    ``1/dt``, this agent's ``share`` of the avoidance (½ reciprocal, 1 when the neighbour does
    not react), and ``flip`` (±1) to split exactly coincident agents at relative rest.
    """
    one = c[2]
    dist_sq = rpx * rpx + rpy * rpy
    cr_sq = cr * cr
    if dist_sq > cr_sq:
        # No collision. w: from the cut-off centre to the relative velocity.
        wx, wy = rvx - ith * rpx, rvy - ith * rpy
        w_len_sq = wx * wx + wy * wy
        dot = wx * rpx + wy * rpy
        if dot < 0.0 and dot * dot > cr_sq * w_len_sq:
            # Project on the cut-off circle.
            w_len = math.sqrt(w_len_sq)
            inv = one / w_len
            ux, uy = wx * inv, wy * inv
            dx, dy = uy, -ux
            f = cr * ith - w_len
            ux, uy = f * ux, f * uy
        else:
            # Project on the left or right leg.
            leg = math.sqrt(dist_sq - cr_sq)
            inv = one / dist_sq
            if rpx * wy - rpy * wx > 0.0:
                dx, dy = (rpx * leg - rpy * cr) * inv, (rpx * cr + rpy * leg) * inv
            else:
                dx, dy = -(rpx * leg + rpy * cr) * inv, -(-rpx * cr + rpy * leg) * inv
            f = rvx * dx + rvy * dy
            ux, uy = f * dx - rvx, f * dy - rvy
    else:
        # Collision: project on the cut-off circle of time dt.
        wx, wy = rvx - its * rpx, rvy - its * rpy
        w_len = math.sqrt(wx * wx + wy * wy)
        if w_len > 0.0:
            inv = one / w_len
            ux, uy = wx * inv, wy * inv
        else:
            ux, uy = -flip, c[0]  # coincident at relative rest (RVO2: NaN): split along x
        dx, dy = uy, -ux
        f = cr * its - w_len
        ux, uy = f * ux, f * uy
    return dx, dy, vx + share * ux, vy + share * uy


@njit(**_INLINE)
def _nearest_agents(i, pos, indptr, indices, max_neighbors, nd_sq, nb_idx, nb_d):
    """The ``max_neighbors`` nearest candidates closer than ``√nd_sq``, nearest first.

    RVO2's ``insertAgentNeighbor``: an insertion sort whose range shrinks to the farthest kept
    neighbour once the list is full. Exact ties are ordered by index (RVO2: k-d tree order).
    Fills ``nb_idx``/``nb_d``, returns the count.
    """
    if max_neighbors == 0:
        return 0
    px, py = pos[i, 0], pos[i, 1]
    n_nb = 0
    worst = nd_sq  # the shrinking range (exclusive)
    for s in range(indptr[i], indptr[i + 1]):
        j = indices[s]
        ex, ey = px - pos[j, 0], py - pos[j, 1]
        d_sq = ex * ex + ey * ey
        if d_sq > worst or j == i:
            continue
        if d_sq == worst and (n_nb < max_neighbors or j > nb_idx[n_nb - 1]):
            continue  # at the range (or tied with the farthest kept one and a higher index)
        if n_nb < max_neighbors:
            k = n_nb
            n_nb += 1
        else:
            k = n_nb - 1
        while k > 0 and (d_sq < nb_d[k - 1] or (d_sq == nb_d[k - 1] and j < nb_idx[k - 1])):
            nb_d[k] = nb_d[k - 1]
            nb_idx[k] = nb_idx[k - 1]
            k -= 1
        nb_d[k] = d_sq
        nb_idx[k] = j
        if n_nb == max_neighbors:
            worst = nb_d[n_nb - 1]
    return n_nb


@njit(**_JIT)
def orca_kernel(agents, nbrs, robots, ob, horizons, max_neighbors):
    """New velocities, as RVO2's ``computeNeighbors`` + ``computeNewVelocity`` for every agent.

    Every float array and scalar shares one dtype ``T`` (float64 in the models; float32
    reproduces the C++ library, which computes in ``float``). ``n`` agents, ``r`` robots.

    Args:
        agents: ``(pos (n, 2) m, vel (n, 2) m/s, radius (n,) m, max_speed (n,) m/s,
            pref (n, 2) m/s, active (n,) bool)``; inactive agents get zero and are obstacles
            that do not react.
        nbrs: ``(indptr, indices)`` CSR candidate neighbours (any order; a superset of those
            closer than ``neighbor_dist``).
        robots: ``(pos (r, 2), vel (r, 2), radius (r,))``; robots closer than ``neighbor_dist``
            are avoided with full responsibility.
        ob: :meth:`Obstacles.kernel_args` (empty arrays for none).
        horizons: ``(neighbor_dist m, time_horizon s, time_horizon_obst s, dt s)``.
        max_neighbors: pedestrians considered per agent, nearest first.

    Returns:
        ``(n, 2)`` new velocities (m/s), dtype ``T``; zero for inactive agents.
    """
    pos, vel, radius, max_speed, pref, active = agents
    indptr, indices = nbrs
    rob_pos, rob_vel, rob_radius = robots
    neighbor_dist, time_horizon, time_horizon_obst, dt = horizons
    n = pos.shape[0]
    out = np.zeros_like(vel)
    one = np.ones(1, dtype=pos.dtype)[0]
    eps = np.full(1, RVO_EPSILON, dtype=pos.dtype)[0]
    c = (one - one, one / (one + one), one, eps, one / (one - one))  # zero, ½, 1, ε, inf in T
    m = ob[0].shape[0]
    n_rob = rob_pos.shape[0]
    lines = np.empty((m + max_neighbors + n_rob, 4), dtype=pos.dtype)
    proj = np.empty_like(lines)
    ob_idx = np.empty(m, dtype=np.int64)
    ob_d = np.empty(m, dtype=pos.dtype)
    nb_idx = np.empty(max_neighbors, dtype=np.int64)
    nb_d = np.empty(max_neighbors, dtype=pos.dtype)
    nd_sq = neighbor_dist * neighbor_dist
    ith, its, ito = one / time_horizon, one / dt, one / time_horizon_obst
    for i in range(n):
        if not active[i]:
            continue
        px, py = pos[i, 0], pos[i, 1]
        vx, vy = vel[i, 0], vel[i, 1]
        ri = radius[i]
        vmax = max_speed[i]
        # Obstacle neighbours within time_horizon_obst · max_speed + radius.
        n_ob = _obstacle_neighbors(px, py, time_horizon_obst * vmax + ri, ob, ob_idx, ob_d)
        n_nb = _nearest_agents(i, pos, indptr, indices, max_neighbors, nd_sq, nb_idx, nb_d)
        # Lines: obstacles (hard), pedestrians nearest first, robots (soft).
        nl = _obstacle_lines(px, py, vx, vy, ri, ito, ob_idx, n_ob, ob, lines, c)
        n_obst_lines = nl
        for k in range(n_nb):
            j = nb_idx[k]
            share = c[1] if active[j] else one
            flip = one if i < j else -one
            rpx, rpy = pos[j, 0] - px, pos[j, 1] - py
            rvx, rvy = vx - vel[j, 0], vy - vel[j, 1]
            cr = ri + radius[j]
            dx, dy, lx, ly = _agent_line(rpx, rpy, rvx, rvy, vx, vy, cr, ith, its, share, flip, c)
            nl = _add(lines, nl, dx, dy, lx, ly)
        for k in range(n_rob):
            rpx, rpy = rob_pos[k, 0] - px, rob_pos[k, 1] - py
            if rpx * rpx + rpy * rpy >= nd_sq:
                continue
            rvx, rvy = vx - rob_vel[k, 0], vy - rob_vel[k, 1]
            cr = ri + rob_radius[k]
            dx, dy, lx, ly = _agent_line(rpx, rpy, rvx, rvy, vx, vy, cr, ith, its, one, one, c)
            nl = _add(lines, nl, dx, dy, lx, ly)

        fail, rx, ry = _lp2(lines, nl, vmax, pref[i, 0], pref[i, 1], False, c)
        if fail < nl:
            rx, ry = _lp3(lines, nl, n_obst_lines, fail, vmax, rx, ry, proj, c)
        if math.isfinite(rx) and math.isfinite(ry):
            out[i, 0], out[i, 1] = rx, ry
    return out


def orca_velocities(
    positions: FloatArray,
    velocities: FloatArray,
    radii: FloatArray,
    max_speeds: FloatArray,
    pref: FloatArray,
    active: BoolArray,
    neighbors: tuple[IntArray, IntArray],
    *,
    max_neighbors: int,
    neighbor_dist: float,
    time_horizon: float,
    time_horizon_obst: float,
    dt: float,
    robots: tuple[FloatArray, FloatArray, FloatArray] | None = None,
    obstacles: Obstacles | None = None,
    dtype: type = np.float64,
) -> FloatArray:
    """New ORCA velocities for every agent (arrays are cast to ``dtype``).

    Args:
        positions: ``(n, 2)`` m.
        velocities: ``(n, 2)`` current velocities (m/s).
        radii: ``(n,)`` m.
        max_speeds: ``(n,)`` m/s.
        pref: ``(n, 2)`` preferred velocities (m/s).
        active: ``(n,)`` bool; inactive agents get zero and are avoided with full share.
        neighbors: ``(indptr, indices)`` CSR candidate pedestrian neighbours.
        max_neighbors: pedestrians considered per agent (nearest first).
        neighbor_dist: m.
        time_horizon: s.
        time_horizon_obst: s.
        dt: s.
        robots: ``(positions (r, 2) m, velocities (r, 2) m/s, radii (r,) m)`` or ``None``.
        obstacles: static obstacles or ``None``.
        dtype: float type of the computation (float32 reproduces the C++ RVO2 library).

    Returns:
        ``(n, 2)`` m/s, ``dtype``.
    """
    t = np.dtype(dtype).type

    def arr(x: FloatArray, shape: tuple[int, ...]) -> FloatArray:
        return np.ascontiguousarray(x, dtype=dtype).reshape(shape)

    n = np.asarray(positions).shape[0]
    if robots is None:
        robots = (np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))
    r = np.asarray(robots[0]).shape[0]
    ob = obstacles if obstacles is not None else Obstacles.empty(dtype)
    agents = (
        arr(positions, (n, 2)),
        arr(velocities, (n, 2)),
        arr(radii, (n,)),
        arr(max_speeds, (n,)),
        arr(pref, (n, 2)),
        np.ascontiguousarray(active, dtype=np.bool_),
    )
    nbrs = (
        np.ascontiguousarray(neighbors[0], dtype=np.int64),
        np.ascontiguousarray(neighbors[1], dtype=np.int64),
    )
    rob = (arr(robots[0], (r, 2)), arr(robots[1], (r, 2)), arr(robots[2], (r,)))
    horizons = (t(neighbor_dist), t(time_horizon), t(time_horizon_obst), t(dt))
    out: FloatArray = orca_kernel(
        agents, nbrs, rob, ob.kernel_args(dtype), horizons, int(max_neighbors)
    )
    return out


# ---------------------------------------------------------------------------------------------
# The model
# ---------------------------------------------------------------------------------------------
class OrcaParams(BaseModel):
    """Parameters of :class:`OrcaModel`, named after RVO2's agent parameters.

    The agent radius is ``state.radii`` (plus ``safety_margin``) and the max speed
    ``state.vmax · state.vmax_factor`` (per agent; the simulator's speed cap), so they are not
    parameters here. RVO2 has no library defaults; ours are pedestrian-scale: a 2 s horizon
    (with 4-5 s, CrowdNav's choice, ORCA, RVO2 included, stalls for good when eight people of
    different speeds swap sides of a 4 m circle), and 5 m of neighbour range, beyond which a
    pedestrian cannot constrain the velocity within that horizon at walking speeds.
    ``safety_margin = 0`` and ``pref_perturbation = 0`` give RVO2's results.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    neighbor_dist: float = Field(
        5.0, gt=0, description="m, pedestrians farther away are ignored (RVO2 neighborDist)"
    )
    max_neighbors: int = Field(
        10, ge=0, description="nearest pedestrians considered per agent (RVO2 maxNeighbors)"
    )
    time_horizon: float = Field(
        2.0, gt=0, description="s, collisions this far ahead are avoided (RVO2 timeHorizon)"
    )
    safety_margin: float = Field(
        0.05,
        ge=0,
        description="m, added to each agent's radius for avoidance (0 reproduces RVO2; when "
        "RVO2's linear program is infeasible in dense crowds it lets agents overlap by a few cm)",
    )
    pref_speed_factor: float = Field(
        1.0, gt=0, le=1, description="preferred speed as a fraction of the max speed"
    )
    arrival_time: float = Field(
        1.0,
        gt=0,
        description="s, the preferred velocity is (destination − p)/arrival_time on the last "
        "stretch (RVO2's examples: 1 s)",
    )
    pref_perturbation: float = Field(
        1e-4,
        ge=0,
        description="m/s, random nudge of the preferred velocity against deadlocks from "
        "perfect symmetry (RVO2's Blocks example: 1e-4; 0 for none)",
    )
    avoid_robots: bool = Field(
        True, description="avoid robots as non-reciprocating moving obstacles (full share)"
    )


@CROWD_MODELS.register("orca", tags=("velocity_obstacle",))
class OrcaModel:
    """ORCA reciprocal collision avoidance among pedestrians (RVO2's algorithm, no obstacles)."""

    output: ClassVar[Literal["acceleration", "velocity"]] = "velocity"
    Params: ClassVar[type[OrcaParams]] = OrcaParams

    def __init__(self, params: OrcaParams | None = None) -> None:
        self.params = params or self.Params()

    def neighbor_cutoff(self) -> float:
        """``neighbor_dist`` (m)."""
        return float(self.params.neighbor_dist)

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Nothing to prepare: ORCA keeps no state between steps."""

    def _obstacles(self, frame: CrowdFrame) -> Obstacles | None:
        return None

    def _time_horizon_obst(self) -> float:
        return 1.0  # unused without obstacles

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """New velocities (m/s): the ORCA optimum nearest each agent's preferred velocity."""
        p = self.params
        s = frame.state
        vmax = s.vmax * s.vmax_factor
        pref = preferred_velocities(
            s.positions, frame.destinations, vmax * p.pref_speed_factor, p.arrival_time
        )
        if p.pref_perturbation > 0:
            # As RVO2's Blocks example does: perfect symmetry can leave ORCA agents stalled.
            u = frame.rng.random((len(s), 2))
            angle, dist = 2.0 * np.pi * u[:, 0], p.pref_perturbation * u[:, 1]
            pref = pref + dist[:, None] * np.stack([np.cos(angle), np.sin(angle)], axis=1)
        rob = frame.robots
        v = orca_velocities(
            s.positions,
            s.velocities,
            s.radii + p.safety_margin,
            vmax,
            pref,
            frame.active,
            (frame.neighbors.indptr, frame.neighbors.indices),
            max_neighbors=p.max_neighbors,
            neighbor_dist=p.neighbor_dist,
            time_horizon=p.time_horizon,
            time_horizon_obst=self._time_horizon_obst(),
            dt=frame.dt,
            robots=(rob.positions, rob.velocities, rob.radii) if p.avoid_robots else None,
            obstacles=self._obstacles(frame),
        )
        return ModelOutput(velocities=v)
