"""An Arena local planner as a ROS 2 (rclpy) node, answering each ``odom`` with a ``cmd_vel``.

    python -m arena.ros.nodes.local_planner [--planner pure_pursuit] [--robot jackal]
        [--params '{"max_speed": 0.8}'] [--dt 0.1] [--ros-args ...]

It subscribes ``odom`` (nav_msgs/Odometry), ``plan`` (nav_msgs/Path), ``scan``
(sensor_msgs/LaserScan) and ``goal_pose`` (PoseStamped, transient local) in its namespace and
publishes one ``cmd_vel`` (geometry_msgs/Twist) for every ``odom`` it gets, so it keeps pace
with a lock-step simulation. The command is the planner's (:class:`~arena.ros.nodes.
planner_node.PlannerNode`).
"""

from __future__ import annotations

import sys

from arena.ros.nodes.planner_node import PlannerNode, parse_args


def main(argv: list[str] | None = None) -> None:
    """Run the node until it is stopped (SIGINT / SIGTERM)."""
    import rclpy
    from geometry_msgs.msg import PoseStamped, Twist
    from nav_msgs.msg import Odometry, Path
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from rclpy.utilities import remove_ros_args
    from sensor_msgs.msg import LaserScan

    args_in = sys.argv if argv is None else argv
    core = PlannerNode(parse_args("arena.ros.nodes.local_planner", remove_ros_args(args_in)[1:]))
    rclpy.init(args=args_in)
    node = rclpy.create_node("arena_local_planner")
    pub = node.create_publisher(Twist, "cmd_vel", 10)

    def on_odom(msg: Odometry) -> None:
        cmd, out = core.command(msg), Twist()
        out.linear.x, out.linear.y, out.angular.z = (float(c) for c in cmd)
        pub.publish(out)

    node.create_subscription(Path, "plan", core.on_plan, 10)
    node.create_subscription(LaserScan, "scan", core.on_scan, 10)
    node.create_subscription(Odometry, "odom", on_odom, 10)
    # the goal is sent when it changes, and kept for late subscribers (transient local)
    node.create_subscription(PoseStamped, "goal_pose", core.on_goal, QoSProfile(
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
