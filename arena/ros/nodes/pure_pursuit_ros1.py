"""A ROS 1 (rospy) pure-pursuit controller: follows ``plan`` with ``odom``, answers each ``odom``.

The example external planner of the ``ros1`` local planner (and its test partner); the rule is
the ROS 2 node's (:mod:`arena.ros.nodes.pure_pursuit`, :func:`~arena.ros.nodes.pursuit.
pursuit_command`)::

    python -m arena.ros.nodes.pure_pursuit_ros1 [--speed 0.6] [--lookahead 0.8] [__ns:=/ns]

It subscribes ``odom`` (nav_msgs/Odometry), ``plan`` (nav_msgs/Path), ``scan``
(sensor_msgs/LaserScan) and the latched ``goal_pose`` (PoseStamped) in its namespace and
publishes one ``cmd_vel`` (geometry_msgs/Twist) for every ``odom`` it gets, so it keeps pace
with a lock-step simulation. It answers only once Arena has connected to its ``cmd_vel``:
rospy drops a message published before a subscriber connects, and a lock-step simulation
would wait for that lost answer until its timeout. Every subscription asks for
``tcp_nodelay``, so no reply waits for Nagle's algorithm.
"""

from __future__ import annotations

import sys
import time
from typing import Any

from arena.ros.nodes.pursuit import PursuitNode, parse_args
from arena.ros.ros1_env import import_rospy


def main(argv: list[str] | None = None) -> None:
    """Run the node until it is stopped (SIGINT / SIGTERM, rospy's shutdown)."""
    rospy = import_rospy()
    from geometry_msgs.msg import PoseStamped, Twist
    from nav_msgs.msg import Odometry, Path
    from sensor_msgs.msg import LaserScan

    args_in = sys.argv if argv is None else argv
    state = PursuitNode(parse_args("arena.ros.nodes.pure_pursuit_ros1",
                                   rospy.myargv(args_in)[1:]))
    rospy.init_node("pure_pursuit", argv=args_in)
    pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
    while pub.get_num_connections() == 0 and not rospy.is_shutdown():
        time.sleep(0.01)  # see the module doc: an answer before Arena connects is lost

    def on_odom(msg: Any) -> None:
        cmd = Twist()
        cmd.linear.x, cmd.angular.z = state.command(msg)
        pub.publish(cmd)

    rospy.Subscriber("plan", Path, state.on_plan, queue_size=10, tcp_nodelay=True)
    rospy.Subscriber("scan", LaserScan, state.on_scan, queue_size=10, tcp_nodelay=True)
    rospy.Subscriber("goal_pose", PoseStamped, state.on_goal, queue_size=1)
    rospy.Subscriber("odom", Odometry, on_odom, queue_size=10, tcp_nodelay=True)
    rospy.spin()


if __name__ == "__main__":
    main()
