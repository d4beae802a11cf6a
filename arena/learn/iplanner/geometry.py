"""What training and the planner share: the camera, the network input, the spline, the cost.

- :data:`CAMERA`: the depth camera the network is trained for (80 × 48 px, 88° × 60° field of
  view, 0.35 m up, 0.15 rad down). A robot runs the network on a camera of the same field of
  view and mount whose image is a whole multiple of 80 × 48 (every n-th pixel is used).
- :func:`depth_input`: a depth image ``(H, W)`` m → the network's ``(1, 48, 80)`` input in
  [0, 1] (no return and anything beyond :data:`MAX_DEPTH` read as :data:`MAX_DEPTH`).
- :func:`goal_features`: a goal in the robot frame → ``[x, y] / GOAL_SCALE, cos, sin`` of its
  bearing.
- :func:`spline_matrix` / :func:`trajectory`: the cubic Hermite spline (tangents by central
  differences, as iPlanner's ``CubicSplineTorch``) from the robot's origin through the ``K``
  waypoints, sampled ``SAMPLES_PER_SEGMENT`` times per segment. With a uniform parameter the
  spline is linear in the points, so it is one constant matrix for numpy and torch alike.
- :func:`obstacle_cost`: the cost of a signed wall distance (m), zero beyond ``safe_distance``,
  1 where the robot's bounding disc touches a wall.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.sensors.spec3d import RgbdSpec

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]

CAMERA = RgbdSpec(width=80, height=48, fovy=60.0, near=0.1, far=8.0, update_rate=10.0,
                  mount=(0.2, 0.0, 0.35, 0.0, 0.15))
"""The training camera: 80 × 48 px, 60° vertical (88° horizontal) field of view, 0.35 m above
the floor 0.2 m ahead of the base origin, pitched 0.15 rad down (sees the floor from 0.45 m)."""

INPUT_SHAPE = (CAMERA.height, CAMERA.width)
"""``(rows, columns)`` of the network's depth input."""

MAX_DEPTH = 6.0
"""m; depth beyond it (and no return) reads as this: the planner looks 4 m ahead at most."""

GOAL_SCALE = 4.0
"""m; goal coordinates are divided by it (training goals lie 0.5–4 m away)."""

WAYPOINTS = 5
"""``K``, waypoints per plan (iPlanner's ``knodes``)."""

SAMPLES_PER_SEGMENT = 10
"""Trajectory points per spline segment (iPlanner samples its spline at step 0.1)."""


class CostParams(BaseModel):
    """The obstacle cost of a trajectory point with signed wall distance ``d`` (m).

    ``cost(d) = (max(safe_distance - d, 0) / (safe_distance - robot_radius))²``: 0 beyond
    ``safe_distance``, 1 where the robot's bounding disc touches the wall, growing into it.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    robot_radius: float = Field(0.267, gt=0, description="m, bounding disc (a jackal's)")
    safe_distance: float = Field(0.55, gt=0, description="m, wall distance of zero cost")
    fear_threshold: float = Field(
        1.0, gt=0, description="cost above which a trajectory counts as colliding (1: touching)"
    )
    fear_distance: float = Field(
        2.0, gt=0, description="m of arc length along which the collision label looks"
    )


def obstacle_cost(distance: ArrayLike, params: CostParams) -> F64:
    """:class:`CostParams`' cost of signed wall distances (m), any shape."""
    d = np.asarray(distance, dtype=np.float64)
    span = params.safe_distance - params.robot_radius
    return np.square(np.maximum(params.safe_distance - d, 0.0) / span)


def depth_input(depth: ArrayLike, shape: tuple[int, int] = INPUT_SHAPE) -> F32:
    """The network input ``(1, rows, cols)`` float32 in [0, 1] of a depth image ``(H, W)`` (m).

    ``H, W`` must be whole multiples of ``shape``: every n-th pixel (the block's centre, as
    :func:`arena.perception.rgbd_data.shrink_depth`) is used. Raises ``ValueError`` otherwise.
    """
    d = np.asarray(depth, dtype=np.float32)
    rows, cols = shape
    if d.ndim != 2 or d.shape[0] % rows or d.shape[1] % cols \
            or d.shape[0] // rows != d.shape[1] // cols:
        raise ValueError(f"depth image {d.shape} is not a whole multiple of {shape}")
    n = d.shape[0] // rows
    if n > 1:
        d = d[n // 2 :: n, n // 2 :: n]
    d = np.where((d > 0) & np.isfinite(d), np.minimum(d, MAX_DEPTH), MAX_DEPTH)
    return (d / np.float32(MAX_DEPTH)).astype(np.float32)[None]


def goal_features(goal: ArrayLike) -> F32:
    """``(..., 4)`` features ``[x / GOAL_SCALE, y / GOAL_SCALE, cos b, sin b]`` of goals.

    ``goal``: ``(..., 2)`` m, robot frame; ``b`` is its bearing.
    """
    g = np.asarray(goal, dtype=np.float64)
    b = np.arctan2(g[..., 1], g[..., 0])
    return np.stack([g[..., 0] / GOAL_SCALE, g[..., 1] / GOAL_SCALE, np.cos(b), np.sin(b)],
                    axis=-1).astype(np.float32)


@lru_cache(maxsize=8)
def spline_matrix(k: int = WAYPOINTS, per_segment: int = SAMPLES_PER_SEGMENT) -> F64:
    """``(k · per_segment + 1, k + 1)``: trajectory points = this @ ``[origin, wp_1 … wp_k]``.

    Cubic Hermite segments between consecutive points, tangents ``m_0 = p_1 - p_0``,
    ``m_i = (p_{i+1} - p_{i-1}) / 2``, ``m_k = p_k - p_{k-1}`` (unit parameter per segment).
    Read-only.
    """
    n = k + 1
    eye = np.eye(n)
    tangents = np.empty((n, n))
    tangents[0] = eye[1] - eye[0]
    tangents[-1] = eye[-1] - eye[-2]
    for i in range(1, n - 1):
        tangents[i] = (eye[i + 1] - eye[i - 1]) / 2
    rows = [eye[0]]
    for seg in range(k):
        for j in range(1, per_segment + 1):
            t = j / per_segment
            h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
            h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
            rows.append(h00 * eye[seg] + h10 * tangents[seg] + h01 * eye[seg + 1]
                        + h11 * tangents[seg + 1])
    m = np.array(rows)
    m.setflags(write=False)
    return m


def trajectory(waypoints: ArrayLike, per_segment: int = SAMPLES_PER_SEGMENT) -> F64:
    """The spline ``(..., k · per_segment + 1, 2)`` from the origin through ``(..., k, 2)``."""
    wp = np.asarray(waypoints, dtype=np.float64)
    pts = np.concatenate([np.zeros((*wp.shape[:-2], 1, 2)), wp], axis=-2)
    out: F64 = spline_matrix(wp.shape[-2], per_segment) @ pts
    return out


def arc_length(points: ArrayLike) -> F64:
    """``(..., n)`` cumulative arc length (m) along points ``(..., n, 2)``, 0 at the first."""
    p = np.asarray(points, dtype=np.float64)
    seg = np.linalg.norm(np.diff(p, axis=-2), axis=-1)
    return np.concatenate([np.zeros((*seg.shape[:-1], 1)), np.cumsum(seg, axis=-1)], axis=-1)


def horizontal_fov() -> float:
    """rad, the training camera's horizontal field of view."""
    fx, _, cx, _ = CAMERA.intrinsics()
    return 2.0 * math.atan((cx + 0.5) / fx)
