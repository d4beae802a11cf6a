"""An Arena local planner as a ROS 1 (rospy) node, answering each ``odom`` with a ``cmd_vel``.

    python -m arena.ros.nodes.local_planner_ros1 [--planner pure_pursuit] [--robot jackal]
        [--params '{...}'] [--dt 0.1] [__ns:=/ns]

The ROS 1 twin of :mod:`arena.ros.nodes.local_planner` (the same core,
:class:`~arena.ros.nodes.planner_node.PlannerNode`). It answers only once Arena has connected
to its ``cmd_vel``: rospy drops a message published before a subscriber connects, and a
lock-step simulation would wait for that lost answer. Every subscription asks for
``tcp_nodelay``, so no reply waits for Nagle's algorithm.
"""

from __future__ import annotations

import sys
import time
from typing import Any

from arena.ros.nodes.planner_node import PlannerNode, parse_args
from arena.ros.ros1_env import import_rospy


def main(argv: list[str] | None = None) -> None:
    """Run the node until it is stopped (SIGINT / SIGTERM, rospy's shutdown)."""
    rospy = import_rospy()
    from geometry_msgs.msg import PoseStamped, Twist
    from nav_msgs.msg import Odometry, Path
    from sensor_msgs.msg import LaserScan

    args_in = sys.argv if argv is None else argv
    core = PlannerNode(parse_args("arena.ros.nodes.local_planner_ros1",
                                  rospy.myargv(args_in)[1:]))
    rospy.init_node("arena_local_planner", argv=args_in)
    pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
    while pub.get_num_connections() == 0 and not rospy.is_shutdown():
        time.sleep(0.01)  # see the module doc: an answer before Arena connects is lost

    def on_odom(msg: Any) -> None:
        cmd, out = core.command(msg), Twist()
        out.linear.x, out.linear.y, out.angular.z = (float(c) for c in cmd)
        pub.publish(out)

    rospy.Subscriber("plan", Path, core.on_plan, queue_size=10, tcp_nodelay=True)
    rospy.Subscriber("scan", LaserScan, core.on_scan, queue_size=10, tcp_nodelay=True)
    rospy.Subscriber("goal_pose", PoseStamped, core.on_goal, queue_size=1)
    rospy.Subscriber("odom", Odometry, on_odom, queue_size=10, tcp_nodelay=True)
    rospy.spin()


if __name__ == "__main__":
    main()
