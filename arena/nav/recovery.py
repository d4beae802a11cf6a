"""Oscillation detection, recovery behaviours and path-blocking checks of the navigation stack.

After move_base_flex: while the stack is active, an :class:`OscillationMonitor` watches whether
the robot has moved more than ``oscillation_distance`` (m) within ``oscillation_timeout`` (s).
When it has not, the stack runs the next recovery behaviour of its configured list
(:data:`RECOVERY_BEHAVIORS`):

``clear_costmap``
    Forget the obstacle layers of the costmaps (and any scan marks) and replan; instantaneous.
``rotate``
    Turn in place through 360° so the laser sees all around (skipped by car-like robots).
``back_up``
    Reverse slowly by ``back_up_distance`` (m) if the laser shows the rear free (skipped by
    robots that cannot reverse).

Progress (the robot more than ``oscillation_distance + back_up_distance`` from where it got
stuck) re-arms the whole list. When every behaviour has run and the robot is still stuck, the
stack reports ``STUCK``. The helpers here are pure functions or small state objects; the stack
(:mod:`arena.nav.stack`) owns the sequencing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.types import wrap_angle_scalar
from arena.maps.grid import OccupancyGrid

RecoveryName = Literal["clear_costmap", "rotate", "back_up"]
"""Name of a recovery behaviour."""

RECOVERY_BEHAVIORS: tuple[RecoveryName, ...] = ("clear_costmap", "rotate", "back_up")
"""The default recovery order (move_base's: clear, rotate, then the extra back-up)."""


class OscillationMonitor:
    """Detects that the robot has not moved ``distance`` (m) within ``timeout`` (s).

    Args:
        timeout: seconds without progress that count as stuck; 0 disables the monitor.
        distance: metres the robot must move to count as progress.
    """

    def __init__(self, timeout: float, distance: float) -> None:
        self.timeout = float(timeout)
        self.distance = float(distance)
        self._xy = np.zeros(2)
        self._time = 0.0

    @property
    def enabled(self) -> bool:
        """Whether the monitor can fire (``timeout > 0``)."""
        return self.timeout > 0

    def reset(self, xy: ArrayLike, time: float) -> None:
        """Restart the watch at position ``xy`` (m) and ``time`` (s)."""
        self._xy = np.asarray(xy, dtype=np.float64).reshape(-1)[:2].copy()
        self._time = float(time)

    def update(self, xy: ArrayLike, time: float) -> bool:
        """Feed the current position (m) and time (s); return whether the robot is stuck."""
        p = np.asarray(xy, dtype=np.float64).reshape(-1)[:2]
        if float(np.hypot(*(p - self._xy))) > self.distance:
            self.reset(p, time)
            return False
        return self.enabled and time - self._time >= self.timeout - 1e-9


@dataclass
class RecoveryRun:
    """State of a running motion recovery (``rotate`` or ``back_up``).

    Attributes:
        name: the behaviour.
        start_xy: ``(2,)`` position where it started (m).
        start_time: when it started (s).
        last_yaw: heading at the previous tick (rad).
        turned: accumulated absolute rotation (rad).
        deadline: time (s) after which it ends even if unfinished.
    """

    name: RecoveryName
    start_xy: NDArray[np.float64]
    start_time: float
    last_yaw: float
    turned: float = 0.0
    deadline: float = math.inf

    def track(self, yaw: float) -> None:
        """Accumulate the rotation since the previous tick (rad)."""
        self.turned += abs(wrap_angle_scalar(yaw - self.last_yaw))
        self.last_yaw = float(yaw)


def scan_to_world(
    pose: ArrayLike,
    ranges: ArrayLike,
    angles: ArrayLike,
    origin: ArrayLike,
    range_max: float = math.inf,
) -> NDArray[np.float64]:
    """Laser returns as world points ``(m, 2)`` (m); beams without a hit are dropped.

    A beam has no hit when its range is non-finite or at least ``range_max``.

    Args:
        pose: ``(3,)`` robot pose ``[x m, y m, yaw rad]``.
        ranges: ``(n,)`` ranges (m).
        angles: ``(n,)`` beam angles in the robot frame (rad).
        origin: ``(2,)`` sensor position in the robot frame (m).
        range_max: the sensor's maximum range (m).
    """
    q = np.asarray(pose, dtype=np.float64).reshape(3)
    r = np.asarray(ranges, dtype=np.float64).reshape(-1)
    a = np.asarray(angles, dtype=np.float64).reshape(-1)
    if r.size == 0 or r.shape != a.shape:
        return np.zeros((0, 2))
    ok = np.isfinite(r) & np.isfinite(a) & (r < range_max - 1e-6)
    o = np.asarray(origin, dtype=np.float64).reshape(2)
    body = np.stack([o[0] + r[ok] * np.cos(a[ok]), o[1] + r[ok] * np.sin(a[ok])], axis=-1)
    c, s = math.cos(q[2]), math.sin(q[2])
    world: NDArray[np.float64] = body @ np.array([[c, s], [-s, c]]) + q[:2]
    return world


def rear_is_free(
    pose: ArrayLike, points: NDArray[np.float64], robot_radius: float, distance: float
) -> bool:
    """Whether no laser return lies in the corridor the robot sweeps reversing ``distance`` m.

    Args:
        pose: ``(3,)`` robot pose (m, rad).
        points: ``(m, 2)`` laser returns, world frame (m).
        robot_radius: radius of the robot's bounding circle (m).
        distance: how far it would reverse (m).
    """
    if len(points) == 0:
        return True
    q = np.asarray(pose, dtype=np.float64).reshape(3)
    c, s = math.cos(q[2]), math.sin(q[2])
    d = points - q[:2]
    x = d[:, 0] * c + d[:, 1] * s
    y = -d[:, 0] * s + d[:, 1] * c
    margin = 0.05
    behind = (x < 0.0) & (x > -(robot_radius + distance + margin)) & (np.abs(y) < robot_radius)
    return not bool(np.any(behind))


def sample_path(
    path: NDArray[np.float64], step: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Points every ``step`` m along a ``(k, 2)`` polyline and their arc lengths (m)."""
    p = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    if len(p) < 2:
        return p.copy(), np.zeros(len(p))
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.append(np.arange(0.0, cum[-1], step), cum[-1])
    x = np.interp(s, cum, p[:, 0])
    y = np.interp(s, cum, p[:, 1])
    return np.stack([x, y], axis=-1), s


def mark_points(grid: OccupancyGrid, points: NDArray[np.float64], radius: float) -> OccupancyGrid:
    """``grid`` with every cell within ``radius`` (m) of a point ``(m, 2)`` (m) occupied."""
    if len(points) == 0:
        return grid
    res = grid.resolution
    k = math.ceil(radius / res)
    off = np.arange(-k, k + 1)
    dr, dc = np.meshgrid(off, off, indexing="ij")
    keep = np.hypot(dr, dc) * res <= radius + 0.5 * res
    dr, dc = dr[keep], dc[keep]
    cells = grid.world_to_cell(points)
    rows = (cells[:, 0, None] + dr[None, :]).ravel()
    cols = (cells[:, 1, None] + dc[None, :]).ravel()
    h, w = grid.data.shape
    ok = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
    mask = np.zeros((h, w), dtype=bool)
    mask[rows[ok], cols[ok]] = True
    return grid.with_occupied(mask)
