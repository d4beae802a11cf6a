"""Shared helpers of the sampling / optimisation local planners (DWA, MPC, social force, ORCA).

- :class:`PathTracker`: forward-only projection of the robot onto the global path, arc-length
  lookup, and distances of many points to the nearby part of the path.
- :func:`robot_frame_path`: path points in the robot frame.
- :func:`cluster_points`: a handful of representative laser points, nearest first.
- :func:`free_distance`: how far a disc can move straight before touching a laser point.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.types import wrap_angle_scalar
from arena.nav.local_planners.base import LocalObservation, limit_command
from arena.robots.limits import VelocityLimits


class PathTracker:
    """Tracks progress along a polyline path; the projection never moves backwards.

    Args:
        window: m, how far beyond the last projection the next projection may jump.
    """

    def __init__(self, window: float = 3.0) -> None:
        self.window = window
        self.reset()

    def reset(self) -> None:
        """Forget the path and the progress along it."""
        self.path: NDArray[np.float64] = np.zeros((2, 2))
        self.cum: NDArray[np.float64] = np.zeros(2)
        self._known = False
        self.seg = 0

    @staticmethod
    def normalise(path: NDArray[np.float64], goal_xy: NDArray[np.float64]) -> NDArray[np.float64]:
        """``(k ≥ 2, 2)`` float path; an empty path becomes the goal, a single point is doubled."""
        p = np.asarray(path, dtype=np.float64).reshape(-1, 2)
        if len(p) == 0:
            p = np.asarray(goal_xy, dtype=np.float64).reshape(1, 2)
        if len(p) == 1:
            p = np.vstack([p, p])
        return p

    @property
    def total(self) -> float:
        """Path length (m)."""
        return float(self.cum[-1])

    def track(self, path: NDArray[np.float64], xy: NDArray[np.float64]) -> float:
        """Project ``xy`` (m, world) onto ``path``; return the arc length (m) of the projection."""
        if not self._known or self.path.shape != path.shape or not np.array_equal(self.path, path):
            self.path = path.copy()
            self.cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0),
                                                                       axis=1))])
            self.seg = 0
            self._known = True
        cum, n_seg = self.cum, len(path) - 1
        i1 = int(np.searchsorted(cum, cum[self.seg] + self.window, side="right"))
        i1 = min(max(i1, self.seg + 1), n_seg)
        a = path[self.seg:i1]
        ab = path[self.seg + 1:i1 + 1] - a
        len2 = np.einsum("ij,ij->i", ab, ab)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.einsum("ij,ij->i", xy - a, ab) / len2
        t = np.clip(np.nan_to_num(t, nan=0.0, posinf=0.0, neginf=0.0), 0.0, 1.0)
        d = np.linalg.norm(a + t[:, None] * ab - xy, axis=1)
        j = int(np.argmin(d))
        self.seg += j
        return float(cum[self.seg] + t[j] * math.sqrt(len2[j]))

    def point_at(self, s: float | NDArray[np.float64]) -> NDArray[np.float64]:
        """Path point(s) (m, world) at arc length(s) ``s``, clamped to the path: ``(..., 2)``."""
        s_arr = np.clip(np.asarray(s, dtype=np.float64), 0.0, self.total)
        i = np.clip(np.searchsorted(self.cum, s_arr, side="right") - 1, 0, len(self.path) - 2)
        seg = self.cum[i + 1] - self.cum[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(seg > 0, (s_arr - self.cum[i]) / seg, 0.0)
        return self.path[i] + t[..., None] * (self.path[i + 1] - self.path[i])

    def tangent_at(self, s: float) -> float:
        """Heading (rad, world) of the path at arc length ``s`` (of the last segment at the end)."""
        i = int(np.clip(np.searchsorted(self.cum, s, side="right") - 1, 0, len(self.path) - 2))
        # Skip zero-length segments.
        for j in list(range(i, len(self.path) - 1)) + list(range(i - 1, -1, -1)):
            d = self.path[j + 1] - self.path[j]
            if d[0] != 0.0 or d[1] != 0.0:
                return math.atan2(d[1], d[0])
        return 0.0

    def distance_to_path(
        self, pts: NDArray[np.float64], s0: float, s1: float
    ) -> NDArray[np.float64]:
        """Distance (m) of each of ``pts`` ``(n, 2)`` (world) to the path.

        Only the part between arc lengths ``s0`` and ``s1`` (m) is considered.
        """
        return self.project(pts, s0, s1)[0]

    def project(
        self, pts: NDArray[np.float64], s0: float, s1: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Distance (m) of each of ``pts`` ``(n, 2)`` (world) to the path, and arc length (m).

        Only the part between arc lengths ``s0`` and ``s1`` is considered; the second array is
        the arc length of each point's closest path point.
        """
        i0 = int(np.clip(np.searchsorted(self.cum, s0, side="right") - 1, 0, len(self.path) - 2))
        i1 = int(np.clip(np.searchsorted(self.cum, s1, side="right"), i0 + 1, len(self.path) - 1))
        a = self.path[i0:i1]
        ab = self.path[i0 + 1:i1 + 1] - a
        len2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-18)
        rel = pts[:, None, :] - a[None, :, :]
        t = np.clip(np.einsum("nkj,kj->nk", rel, ab) / len2, 0.0, 1.0)
        diff = rel - t[..., None] * ab[None, :, :]
        d2 = np.einsum("nkj,nkj->nk", diff, diff)
        j = np.argmin(d2, axis=1)
        rows = np.arange(len(pts))
        s_proj = self.cum[i0 + j] + t[rows, j] * np.sqrt(len2[j])
        return np.sqrt(d2[rows, j]), s_proj


def to_robot_frame(pts: NDArray[np.float64], pose: NDArray[np.float64]) -> NDArray[np.float64]:
    """World points ``(..., 2)`` (m) expressed in the frame of ``pose`` ``[x, y, theta]``."""
    c, s = math.cos(float(pose[2])), math.sin(float(pose[2]))
    d = np.asarray(pts, dtype=np.float64) - pose[:2]
    return np.stack([c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]], axis=-1)


def cluster_points(
    points: NDArray[np.float64], count: int, radius: float, reach: float
) -> NDArray[np.float64]:
    """Up to ``count`` representatives of ``points`` ``(m, 2)`` (robot frame, m), nearest first.

    Greedy: take the nearest remaining point within ``reach`` (m), drop every point within
    ``radius`` (m) of it, repeat. Deterministic.
    """
    if len(points) == 0:
        return np.zeros((0, 2))
    d = np.hypot(points[:, 0], points[:, 1])
    keep = d <= reach
    pts, d = points[keep], d[keep]
    order = np.argsort(d, kind="stable")
    pts = pts[order]
    out: list[NDArray[np.float64]] = []
    alive = np.ones(len(pts), dtype=bool)
    r2 = radius * radius
    while len(out) < count:
        idx = np.flatnonzero(alive)
        if len(idx) == 0:
            break
        p = pts[idx[0]]
        out.append(p)
        rel = pts[idx] - p
        alive[idx[np.einsum("ij,ij->i", rel, rel) <= r2]] = False
    return np.array(out).reshape(-1, 2)


def free_distance(
    points: NDArray[np.float64], direction: NDArray[np.float64], radius: float
) -> float:
    """Distance (m) a disc of ``radius`` (m) at the origin can move straight before a contact.

    Moving along the unit ``direction`` until it touches one of ``points`` ``(m, 2)``; 0 if a
    point ahead already lies inside it, ``inf`` if nothing is in the way.
    """
    if len(points) == 0:
        return math.inf
    along = points @ direction
    lateral = np.abs(points[:, 0] * direction[1] - points[:, 1] * direction[0])
    inside = np.hypot(points[:, 0], points[:, 1]) < radius
    if np.any(inside & (along >= 0)):
        return 0.0
    ahead = (along > 0) & (lateral < radius)
    if not np.any(ahead):
        return math.inf
    gap = along[ahead] - np.sqrt(np.maximum(radius * radius - lateral[ahead] ** 2, 0.0))
    return float(max(np.min(gap), 0.0))


class TrackingParams(BaseModel):
    """Path-tracking and goal parameters shared by the reactive planners (social force, ORCA)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    stop_distance: float = Field(
        0.1, ge=0, description="m, gap to a laser return ahead at which the robot stops"
    )
    decel_fraction: float = Field(
        0.8, gt=0, le=1, description="share of the acceleration limit used for braking"
    )
    heading_gain: float = Field(2.0, gt=0, description="1/s, yaw rate per rad of error")
    rotate_threshold: float = Field(
        1.0, gt=0, description="rad, heading error beyond which diff drives turn in place"
    )
    goal_tolerance: float = Field(
        0.05, gt=0, description="m, distance to the path end at which the planner stops"
    )
    goal_yaw_tolerance: float = Field(
        0.05, gt=0, description="rad, heading error accepted when aligning at the goal"
    )


def finish_command(
    cmd: NDArray[np.float64], twist: NDArray[np.float64], lim: VelocityLimits, dt: float,
    car: bool,
) -> NDArray[np.float64]:
    """``cmd`` (``(3,)`` body twist) inside the acceleration window and the velocity box.

    Car-like robots also keep ``|omega| ≤ min(|vx| / min_turning_radius, omega_max)``;
    non-holonomic robots get ``vy = 0``. Every local planner's last step.
    """
    out = limit_command(cmd, twist, lim, dt)
    if not lim.holonomic:
        out[1] = 0.0
    if car:
        r = lim.min_turning_radius
        w_max = min(abs(out[0]) / r, lim.omega_max) if r > 0 else 0.0
        out[2] = float(np.clip(out[2], -w_max, w_max))
    return out


def at_goal(obs: LocalObservation, d_end: float, goal_tolerance: float) -> bool:
    """Whether a planner is in its goal phase (brake, then align the heading if asked).

    True within the planner's own ``goal_tolerance`` (m) of the path end; and, when the stack
    asks for a goal heading and the robot can turn on the spot, already within 0.8 × the stack's
    ``goal_xy_tolerance``: turning there meets the goal, while chasing the last centimetres at a
    wrong heading made DWA circle around the goal for seconds.
    """
    if d_end <= goal_tolerance:
        return True
    xy = obs.goal_xy_tolerance
    car = obs.drive == "ackermann" or obs.limits.min_turning_radius > 0
    return (obs.goal_yaw_tolerance is not None and xy is not None and not car
            and d_end <= 0.8 * xy)


def goal_command(
    obs: LocalObservation, heading_gain: float, yaw_tolerance: float
) -> NDArray[np.float64]:
    """Braking command at the goal, turning on the spot to the goal heading when asked.

    The stack asks through ``obs.goal_yaw_tolerance``; car-like robots cannot turn on the spot.

    Args:
        obs: the observation.
        heading_gain: 1/s, yaw rate per radian of heading error.
        yaw_tolerance: rad; the planner aligns to ``min(yaw_tolerance, stack tolerance / 2)``.
    """
    lim = obs.limits
    car = obs.drive == "ackermann" or lim.min_turning_radius > 0
    cmd = np.zeros(3)
    want = obs.goal_yaw_tolerance
    if want is not None and not car:
        tol = min(yaw_tolerance, want / 2)
        err = wrap_angle_scalar(obs.goal_pose.theta - float(np.asarray(obs.pose)[2]))
        if abs(err) > tol:
            cmd[2] = heading_gain * err
    twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
    return finish_command(cmd, twist, lim, float(obs.dt), car)
