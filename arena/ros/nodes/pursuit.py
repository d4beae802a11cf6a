"""The pure-pursuit rule and state of Arena's example ROS nodes (ROS 1 and ROS 2 share them).

:class:`PursuitNode` takes received messages (rclpy's or genpy's: the same attribute names)
and gives each ``odom`` its command; the nodes in :mod:`arena.ros.nodes.pure_pursuit` (rclpy)
and :mod:`arena.ros.nodes.pure_pursuit_ros1` (rospy) only wire it to their topics.
"""

from __future__ import annotations

import argparse
import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from arena.ros.messages import quaternion_yaw

FloatArray = NDArray[np.float64]


class PursuitParams(NamedTuple):
    """speed m/s, turn rad/s (largest), lookahead m, tolerance m (stop at the plan's end)."""

    speed: float = 0.6
    turn: float = 1.2
    lookahead: float = 0.8
    tolerance: float = 0.2


def pursuit_command(pose: FloatArray, plan: FloatArray,
                    scan: tuple[FloatArray, FloatArray] | None,
                    p: PursuitParams, goal_yaw: float | None = None) -> tuple[float, float]:
    """``(v m/s, omega rad/s)`` toward ``plan`` ``(k, 2)`` from ``pose`` ``[x, y, yaw]``.

    ``scan`` is ``(ranges, angles)`` in the robot frame, or ``None``. At the plan's end the
    robot turns on the spot to ``goal_yaw`` (rad) when one is given.
    """
    if len(plan) == 0:
        return 0.0, 0.0
    xy = pose[:2]
    if float(np.hypot(*(plan[-1] - xy))) < p.tolerance:
        if goal_yaw is None:
            return 0.0, 0.0
        err = (goal_yaw - pose[2] + math.pi) % (2 * math.pi) - math.pi
        return 0.0, float(np.clip(2.0 * err, -p.turn, p.turn)) if abs(err) > 0.05 else 0.0
    dense = densify(plan, 0.05)  # a plan's straight segments may be metres long
    d = np.hypot(dense[:, 0] - xy[0], dense[:, 1] - xy[1])
    start = int(np.argmin(d))
    ahead = np.nonzero(d[start:] >= p.lookahead)[0]
    target = dense[start + ahead[0]] if len(ahead) else dense[-1]
    alpha = math.atan2(target[1] - xy[1], target[0] - xy[0]) - pose[2]
    alpha = (alpha + math.pi) % (2 * math.pi) - math.pi
    if abs(alpha) > 1.0:
        return 0.0, math.copysign(p.turn, alpha)
    v = p.speed * max(0.2, math.cos(alpha))
    if scan is not None:
        r, a = scan
        front = np.isfinite(r) & (np.abs(a) < 0.6)
        near = float(r[front].min()) if front.any() else math.inf
        v *= float(np.clip((near - 0.45) / 0.8, 0.0, 1.0))
        if v <= 0.0:  # blocked ahead: turn toward the plan (people move on; walls get passed)
            return 0.0, math.copysign(0.5 * p.turn, alpha if alpha else 1.0)
    dist = max(float(np.hypot(*(target - xy))), 1e-6)
    w = float(np.clip(2.0 * v * math.sin(alpha) / dist, -p.turn, p.turn))
    return v, w


def densify(path: FloatArray, step: float) -> FloatArray:
    """``path`` ``(k, 2)`` resampled every ``step`` m along its length (ends kept)."""
    if len(path) < 2:
        return np.asarray(path, dtype=np.float64)
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
    s = np.append(np.arange(0.0, arc[-1], step), arc[-1])
    return np.stack([np.interp(s, arc, path[:, 0]), np.interp(s, arc, path[:, 1])], axis=1)


def parse_args(prog: str, argv: list[str]) -> PursuitParams:
    """The nodes' options (``argv`` without the ROS arguments and the program name)."""
    parser = argparse.ArgumentParser(prog=prog)
    parser.add_argument("--speed", type=float, default=0.6, help="m/s, cruise speed")
    parser.add_argument("--turn", type=float, default=1.2, help="rad/s, largest turn rate")
    parser.add_argument("--lookahead", type=float, default=0.8, help="m")
    parser.add_argument("--tolerance", type=float, default=0.2, help="m, stop at the end")
    opts = parser.parse_args(argv)
    return PursuitParams(opts.speed, opts.turn, opts.lookahead, opts.tolerance)


class PursuitNode:
    """What the example node knows (plan, scan, goal heading) and its answer to an ``odom``."""

    def __init__(self, params: PursuitParams) -> None:
        self.params = params
        self.plan: FloatArray = np.zeros((0, 2))
        self.scan: tuple[FloatArray, FloatArray] | None = None
        self.goal_yaw: float | None = None

    def on_plan(self, msg: Any) -> None:
        """``nav_msgs/Path``."""
        self.plan = np.array([[p.pose.position.x, p.pose.position.y] for p in msg.poses])
        self.plan = self.plan.reshape(-1, 2)

    def on_scan(self, msg: Any) -> None:
        """``sensor_msgs/LaserScan`` (beam angles in the robot frame: a forward-facing lidar)."""
        r = np.asarray(msg.ranges, dtype=np.float64)
        self.scan = (r, msg.angle_min + msg.angle_increment * np.arange(len(r)))

    def on_goal(self, msg: Any) -> None:
        """``geometry_msgs/PoseStamped``: the heading to turn to at the end."""
        self.goal_yaw = quaternion_yaw(msg.pose.orientation)

    def command(self, odom: Any) -> tuple[float, float]:
        """``(v m/s, omega rad/s)`` for an ``nav_msgs/Odometry``."""
        p = odom.pose.pose
        pose = np.array([p.position.x, p.position.y, quaternion_yaw(p.orientation)])
        return pursuit_command(pose, self.plan, self.scan, self.params, self.goal_yaw)
