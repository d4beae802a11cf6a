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

import sys

from arena.ros.nodes.pursuit import PursuitNode, parse_args


def main(argv: list[str] | None = None) -> None:
    """Run the node until it is stopped (SIGINT / SIGTERM)."""
    import rclpy
    from geometry_msgs.msg import PoseStamped, Twist
    from nav_msgs.msg import Odometry, Path
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from rclpy.utilities import remove_ros_args
    from sensor_msgs.msg import LaserScan

    args_in = sys.argv if argv is None else argv
    state = PursuitNode(parse_args("arena.ros.nodes.pure_pursuit", remove_ros_args(args_in)[1:]))
    rclpy.init(args=args_in)
    node = rclpy.create_node("pure_pursuit")
    pub = node.create_publisher(Twist, "cmd_vel", 10)

    def on_odom(msg: Odometry) -> None:
        cmd = Twist()
        cmd.linear.x, cmd.angular.z = state.command(msg)
        pub.publish(cmd)

    node.create_subscription(Path, "plan", state.on_plan, 10)
    node.create_subscription(LaserScan, "scan", state.on_scan, 10)
    node.create_subscription(Odometry, "odom", on_odom, 10)
    # the goal is sent when it changes, and kept for late subscribers (transient local)
    node.create_subscription(PoseStamped, "goal_pose", state.on_goal, QoSProfile(
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
