"""Any Arena local planner as a ROS node: the core that ROS 1 and ROS 2 nodes share.

:class:`PlannerNode` keeps what the node has received (plan, scan, goal; rclpy's or genpy's
messages: the same attribute names) and answers each ``nav_msgs/Odometry`` with the command of
an Arena local planner (``--planner``, default ``pure_pursuit``) for a robot preset
(``--robot``, default ``jackal``): the observation is built from the messages as the
navigation stack builds it in a run. The nodes :mod:`arena.ros.nodes.local_planner` (rclpy)
and :mod:`arena.ros.nodes.local_planner_ros1` (rospy) only wire it to their topics; they are
the example external planners of the ``ros2`` / ``ros1`` local planners and their tests'
partners, and show how to put a planner behind ROS.
"""

from __future__ import annotations

import argparse
import json
from types import SimpleNamespace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.core.types import Pose2D
from arena.ros.messages import quaternion_yaw, received_pose

FloatArray = NDArray[np.float64]
#: Heading error (rad) accepted at the goal (inside the default task's 0.52 rad).
GOAL_YAW_TOLERANCE = 0.3
#: Distance (m) to the goal accepted as arrived (inside the default task's 0.3 m radius).
GOAL_XY_TOLERANCE = 0.2


def parse_args(prog: str, argv: list[str]) -> argparse.Namespace:
    """The node's options (``argv`` without the ROS arguments and the program name)."""
    parser = argparse.ArgumentParser(prog=prog, description=__doc__.splitlines()[0])
    parser.add_argument("--planner", default="pure_pursuit", help="an Arena local planner")
    parser.add_argument("--params", default="{}", help="its parameters as JSON")
    parser.add_argument("--robot", default="jackal", help="robot preset (limits, radius)")
    parser.add_argument("--sensor", default="laser", help="the robot's lidar that /scan is")
    parser.add_argument("--dt", type=float, default=0.1, help="s, control period")
    return parser.parse_args(argv)


class PlannerNode:
    """An Arena local planner fed from ROS messages (see the module doc).

    Args:
        options: :func:`parse_args`'s result.

    Raises:
        ConfigError: an unknown planner or robot, or bad parameters (one line).
    """

    def __init__(self, options: argparse.Namespace) -> None:
        import arena.plugins  # noqa: F401  (fills the registries)
        from arena.nav.local_planners.base import LOCAL_PLANNERS
        from arena.robots.presets import load_robot

        self.robot = load_robot(options.robot)
        self.planner = LOCAL_PLANNERS.build(
            {"type": options.planner, **json.loads(options.params)}, path="--planner")
        self.limits = self.robot.limits()
        self.sensor = self.robot.lidar(options.sensor, path="--sensor")
        self.dt = float(options.dt)
        self.plan: FloatArray = np.zeros((0, 2))
        self.scan: FloatArray | None = None
        self.goal: Pose2D | None = None

    def on_plan(self, msg: Any) -> None:
        """``nav_msgs/Path``."""
        self.plan = np.array([[p.pose.position.x, p.pose.position.y]
                              for p in msg.poses]).reshape(-1, 2)

    def on_scan(self, msg: Any) -> None:
        """``sensor_msgs/LaserScan`` of the robot's ``--sensor`` lidar."""
        self.scan = np.asarray(msg.ranges, dtype=np.float64)

    def on_goal(self, msg: Any) -> None:
        """``geometry_msgs/PoseStamped``: a new goal; the planner starts afresh."""
        self.goal = received_pose(msg.pose)
        self.planner.reset()

    def command(self, odom: Any) -> FloatArray:
        """``[vx m/s, vy m/s, omega rad/s]`` for an ``nav_msgs/Odometry``."""
        from arena.nav.local_planners.base import LocalObservation
        from arena.sensors.spec import lidar_geometry

        if self.goal is None or not len(self.plan):
            return np.zeros(3)
        p, v = odom.pose.pose, odom.twist.twist
        angles, origin = lidar_geometry(self.sensor)
        ranges = self.scan if self.scan is not None and len(self.scan) == len(angles) \
            else np.full(len(angles), np.inf)
        obs = LocalObservation(
            pose=np.array([p.position.x, p.position.y, quaternion_yaw(p.orientation)]),
            twist=np.array([v.linear.x, v.linear.y, v.angular.z]), goal=self.goal,
            path=self.plan, limits=self.limits, robot_radius=self.robot.radius, dt=self.dt,
            scan_ranges=ranges, scan_angles=angles, scan_origin=origin,
            time=_seconds(odom.header.stamp),
            kinematics=self.robot.kinematics_type, goal_yaw_tolerance=GOAL_YAW_TOLERANCE,
            goal_xy_tolerance=GOAL_XY_TOLERANCE)
        return np.asarray(self.planner.compute(obs), dtype=np.float64)


def _seconds(stamp: Any) -> float:
    """A received stamp in s: ROS 2's ``sec`` / ``nanosec`` or ROS 1's ``secs`` / ``nsecs``."""
    if hasattr(stamp, "sec"):
        return float(stamp.sec) + 1e-9 * float(stamp.nanosec)
    return float(stamp.secs) + 1e-9 * float(stamp.nsecs)


def as_message(fields: Any) -> Any:
    """A :mod:`arena.ros.messages` field dict as an attribute-style message (tests, no ROS)."""
    if isinstance(fields, dict):
        return SimpleNamespace(**{k: as_message(v) for k, v in fields.items()})
    if isinstance(fields, list):
        return [as_message(v) for v in fields]
    return fields
