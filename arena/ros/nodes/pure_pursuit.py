"""A ROS 2 pure-pursuit controller: follows ``plan`` with ``odom``, answers each ``odom``.

The example external planner of the ``ros2`` local planner (and its test partner)::

    python -m arena.ros.nodes.pure_pursuit [--speed 0.6] [--lookahead 0.8] [--ros-args ...]

It subscribes ``odom`` (nav_msgs/Odometry), ``plan`` (nav_msgs/Path) and ``scan``
(sensor_msgs/LaserScan) in its namespace and publishes one ``cmd_vel`` (geometry_msgs/Twist)
for every ``odom`` it gets, so it keeps pace with a lock-step simulation. The command steers
to the plan's point ``lookahead`` m ahead (curvature ``2 sin α / L``), turns on the spot when
that point is more than 1 rad off, slows near returns ahead in the scan (turning on the spot
when blocked), and within ``tolerance`` m of the plan's end turns to the heading of
``goal_pose`` (PoseStamped).
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

import numpy as np

from arena.ros.nodes.pursuit import PursuitParams, pursuit_command


def main(argv: list[str] | None = None) -> None:
    """Run the node until it is stopped (SIGINT / SIGTERM)."""
    import rclpy
    from geometry_msgs.msg import PoseStamped, Twist
    from nav_msgs.msg import Odometry, Path
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from rclpy.utilities import remove_ros_args
    from sensor_msgs.msg import LaserScan

    args_in = sys.argv if argv is None else argv
    parser = argparse.ArgumentParser(prog="arena.ros.nodes.pure_pursuit")
    parser.add_argument("--speed", type=float, default=0.6, help="m/s, cruise speed")
    parser.add_argument("--turn", type=float, default=1.2, help="rad/s, largest turn rate")
    parser.add_argument("--lookahead", type=float, default=0.8, help="m")
    parser.add_argument("--tolerance", type=float, default=0.2, help="m, stop at the end")
    opts = parser.parse_args(remove_ros_args(args_in)[1:])
    params = PursuitParams(opts.speed, opts.turn, opts.lookahead, opts.tolerance)

    rclpy.init(args=args_in)
    node = rclpy.create_node("pure_pursuit")
    pub = node.create_publisher(Twist, "cmd_vel", 10)
    state: dict[str, Any] = {"plan": np.zeros((0, 2)), "scan": None, "goal_yaw": None}

    def yaw_of(q: Any) -> float:
        return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))

    def on_goal(msg: PoseStamped) -> None:
        state["goal_yaw"] = yaw_of(msg.pose.orientation)

    def on_plan(msg: Path) -> None:
        state["plan"] = np.array([[p.pose.position.x, p.pose.position.y] for p in msg.poses])

    def on_scan(msg: LaserScan) -> None:
        r = np.asarray(msg.ranges, dtype=np.float64)
        a = msg.angle_min + msg.angle_increment * np.arange(len(r))
        state["scan"] = (r, a)

    def on_odom(msg: Odometry) -> None:
        p = msg.pose.pose.position
        pose = np.array([p.x, p.y, yaw_of(msg.pose.pose.orientation)])
        v, w = pursuit_command(pose, state["plan"], state["scan"], params, state["goal_yaw"])
        cmd = Twist()
        cmd.linear.x, cmd.angular.z = v, w
        pub.publish(cmd)

    node.create_subscription(Path, "plan", on_plan, 10)
    node.create_subscription(LaserScan, "scan", on_scan, 10)
    node.create_subscription(Odometry, "odom", on_odom, 10)
    # the goal is sent when it changes, and kept for late subscribers (transient local)
    node.create_subscription(PoseStamped, "goal_pose", on_goal, QoSProfile(
        depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        if rclpy.ok():
            rclpy.try_shutdown()


if __name__ == "__main__":
    main()
