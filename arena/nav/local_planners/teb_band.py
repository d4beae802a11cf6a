"""The Timed Elastic Band's band: poses and time intervals, their context and the helpers.

The band representation, the per-cycle context the residuals read and the finite-difference
Jacobian column grouping used by :class:`arena.nav.local_planners.teb.TEBPlanner`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix

from arena.robots.limits import VelocityLimits

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass
class Band:
    """A timed elastic band (world frame).

    Attributes:
        poses: ``(N+1, 3)`` ``[x m, y m, θ rad]`` (θ unwrapped along the band).
        dt: ``(N,)`` time intervals (s) between consecutive poses.
    """

    poses: FloatArray
    dt: FloatArray

    @property
    def times(self) -> FloatArray:
        """``(N+1,)`` time stamps (s) of the poses, the first at 0."""
        return np.concatenate([[0.0], np.cumsum(self.dt)])


@dataclass
class BandContext:
    """What the residuals of one optimisation need besides the variables.

    Attributes:
        n: number of band segments ``N``.
        start: ``(3,)`` fixed first pose (m, m, rad).
        end: ``(2,)`` fixed last position (m).
        twist: ``(3,)`` current body twist (m/s, m/s, rad/s).
        final: whether the band ends at the goal (the robot must come to rest there).
        drive: kinematics name.
        limits: velocity and acceleration limits.
        radius: robot radius (m).
        obstacles: ``(K, 2)`` obstacle points (m, world).
        max_segment: longest segment (m) before the spacing penalty.
        obstacle_idx: ``(N-1, k)`` the obstacles associated with each inner pose (its nearest,
            re-associated every outer iteration as in TEB).
        path: ``(M, 2)`` dense samples of the local path (m, world).
        times: ``(N+1,)`` time stamps (s) frozen for this outer iteration.
        peds: ``(J, 4)`` pedestrians ``[x, y, vx, vy]`` (m, m/s, world).
        ped_pred: ``(N+1, J, 2)`` pedestrian positions (m) predicted at ``times``.
    """

    n: int
    start: FloatArray
    end: FloatArray
    twist: FloatArray
    final: bool
    drive: str
    limits: VelocityLimits
    radius: float
    obstacles: FloatArray
    obstacle_idx: IntArray
    max_segment: float
    path: FloatArray
    times: FloatArray
    peds: FloatArray
    ped_pred: FloatArray

    # -- variable layout: x_1..x_{N-1}, y_1..y_{N-1}, θ_1..θ_N, ΔT_0..ΔT_{N-1} ------------------
    def x_col(self, i: IntArray) -> IntArray:
        """Column of ``x_i`` (−1 for the fixed first and last pose)."""
        return np.where((i >= 1) & (i <= self.n - 1), i - 1, -1)

    def y_col(self, i: IntArray) -> IntArray:
        """Column of ``y_i`` (−1 when fixed)."""
        return np.where((i >= 1) & (i <= self.n - 1), self.n - 1 + i - 1, -1)

    def th_col(self, i: IntArray) -> IntArray:
        """Column of ``θ_i`` (−1 for the first pose)."""
        return np.where(i >= 1, 2 * (self.n - 1) + i - 1, -1)

    def dt_col(self, i: IntArray) -> IntArray:
        """Column of ``ΔT_i``."""
        return 3 * self.n - 2 + i

    @property
    def size(self) -> int:
        """Number of free variables."""
        return 4 * self.n - 2

    def segment_deps(self, seg: IntArray) -> IntArray:
        """``(len(seg), 7)`` columns a residual of segment ``i`` (poses ``i, i+1``) uses."""
        a, b = seg, seg + 1
        return np.stack([self.x_col(a), self.y_col(a), self.x_col(b), self.y_col(b),
                         self.th_col(a), self.th_col(b), self.dt_col(seg)], axis=-1)

    def pose_deps(self, idx: IntArray) -> IntArray:
        """``(len(idx), 2)`` position columns of poses ``idx``."""
        return np.stack([self.x_col(idx), self.y_col(idx)], axis=-1)

    def unpack(self, z: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Positions ``(N+1, 2)``, headings ``(N+1,)`` and intervals ``(N,)`` from ``z``."""
        n = self.n
        pos = np.empty((n + 1, 2))
        pos[0] = self.start[:2]
        pos[n] = self.end
        pos[1:n, 0] = z[: n - 1]
        pos[1:n, 1] = z[n - 1: 2 * n - 2]
        th = np.empty(n + 1)
        th[0] = self.start[2]
        th[1:] = z[2 * n - 2: 3 * n - 2]
        return pos, th, z[3 * n - 2:]

    def pack(self, band: Band) -> FloatArray:
        """Free variables of ``band`` (its first pose and last position are the fixed ones)."""
        n = self.n
        return np.concatenate([band.poses[1:n, 0], band.poses[1:n, 1], band.poses[1:, 2],
                               band.dt])


def _hinge(x: FloatArray) -> FloatArray:
    return np.maximum(x, 0.0)


def _resample(pts: FloatArray, count: int) -> tuple[FloatArray, FloatArray]:
    """``count`` points at equal arc length along polyline ``pts`` ``(k, 2)`` (m).

    Returns:
        The points ``(count, 2)`` and the cumulative arc length (m) of the vertices of ``pts``.
    """
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = cum[-1]
    if total <= 1e-12:
        return np.repeat(pts[:1], count, axis=0), cum
    s = np.linspace(0.0, total, count)
    return np.stack([np.interp(s, cum, pts[:, 0]), np.interp(s, cum, pts[:, 1])], axis=-1), cum


_FD_STEP = 1e-7
"""Relative forward-difference step of the grouped Jacobian."""


def _column_groups(pattern: coo_matrix) -> list[tuple[IntArray, IntArray, IntArray]]:
    """Greedy groups of structurally independent columns of a sparsity ``pattern``.

    Returns:
        Per group: its columns, and the (row, column) pairs of the pattern's non-zeros in it.
    """
    csc = pattern.tocsc()
    m, n = csc.shape
    masks: list[NDArray[np.bool_]] = []
    members: list[list[int]] = []
    for c in range(n):
        rows = csc.indices[csc.indptr[c]:csc.indptr[c + 1]]
        for g, mask in enumerate(masks):
            if not mask[rows].any():
                mask[rows] = True
                members[g].append(c)
                break
        else:
            mask = np.zeros(m, dtype=bool)
            mask[rows] = True
            masks.append(mask)
            members.append([c])
    out = []
    for cols in members:
        rr = [csc.indices[csc.indptr[c]:csc.indptr[c + 1]] for c in cols]
        owner = np.concatenate([np.full(len(r), c, dtype=np.int64) for r, c in zip(rr, cols,
                                                                                 strict=True)])
        out.append((np.asarray(cols, dtype=np.int64), np.concatenate(rr).astype(np.int64),
                    owner))
    return out
