"""Subgoals on a planned path (numpy only: the ``rosnav_rl`` planner uses them without gymnasium).

Arena's "spacial horizon" (arena_specs §8.1): the learned policies see a subgoal a fixed arc
length ahead on the global path instead of the final goal.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def project_on_path(path: FloatArray, position: FloatArray) -> tuple[float, float]:
    """Arc length (m) of ``position``'s nearest point on the polyline ``path`` ``(K, 2)``.

    Returns ``(arc length, distance)``: the distance (m) to that point as well; ties go to the
    earliest segment.
    """
    path = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    p = np.asarray(position, dtype=np.float64)[:2]
    if path.shape[0] == 1:
        return 0.0, float(np.hypot(*(p - path[0])))
    a, seg = path[:-1], np.diff(path, axis=0)
    length2 = np.einsum("ij,ij->i", seg, seg)
    t = np.einsum("ij,ij->i", p - a, seg) / np.where(length2 > 0, length2, 1.0)
    t = np.clip(t, 0.0, 1.0)
    near = a + t[:, None] * seg
    d = np.hypot(near[:, 0] - p[0], near[:, 1] - p[1])
    j = int(np.argmin(d))
    lengths = np.sqrt(length2)
    return float(lengths[:j].sum() + t[j] * lengths[j]), float(d[j])


def subgoal_on_path(path: FloatArray, position: FloatArray, horizon: float) -> FloatArray:
    """The subgoal ``(2,)`` (m) of Arena's "spacial horizon" (arena_specs §8.1).

    The point of the polyline ``path`` ``(K, 2)`` (start … goal) that lies ``horizon`` m of arc
    length ahead of ``position``'s projection on the path (its nearest point); the path's last
    point (the goal) when the goal is within ``horizon`` m of ``position`` (straight line) or
    less than ``horizon`` m of path remain. Arena picks the first plan point about
    ``planning_horizon`` m away from the robot; measuring along the path from the projection
    gives the same point on straight stretches and never cuts a corner through a wall.
    """
    path = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    p = np.asarray(position, dtype=np.float64)[:2]
    goal = path[-1]
    if path.shape[0] == 1 or np.hypot(*(goal - p)) <= horizon:
        return goal.copy()
    s0, _ = project_on_path(path, p)
    seg = np.diff(path, axis=0)
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(seg[:, 0], seg[:, 1]))])
    target = s0 + horizon
    if target >= cum[-1]:
        return goal.copy()
    j = int(np.searchsorted(cum, target, side="right")) - 1
    j = min(max(j, 0), seg.shape[0] - 1)
    span = cum[j + 1] - cum[j]
    t = (target - cum[j]) / span if span > 0 else 0.0
    return np.asarray(path[j] + t * seg[j], dtype=np.float64)
