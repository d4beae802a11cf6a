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

import argparse
import math
import sys
import time
from typing import Any

import numpy as np

from arena.ros.nodes.pursuit import PursuitParams, pursuit_command
from arena.ros.ros1_env import import_rospy


def _yaw(q: Any) -> float:
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def main(argv: list[str] | None = None) -> None:
    """Run the node until it is stopped (SIGINT / SIGTERM, rospy's shutdown)."""
    rospy = import_rospy()
    from geometry_msgs.msg import PoseStamped, Twist
    from nav_msgs.msg import Odometry, Path
    from sensor_msgs.msg import LaserScan

    args_in = sys.argv if argv is None else argv
    parser = argparse.ArgumentParser(prog="arena.ros.nodes.pure_pursuit_ros1")
    parser.add_argument("--speed", type=float, default=0.6, help="m/s, cruise speed")
    parser.add_argument("--turn", type=float, default=1.2, help="rad/s, largest turn rate")
    parser.add_argument("--lookahead", type=float, default=0.8, help="m")
    parser.add_argument("--tolerance", type=float, default=0.2, help="m, stop at the end")
    opts = parser.parse_args(rospy.myargv(args_in)[1:])
    params = PursuitParams(opts.speed, opts.turn, opts.lookahead, opts.tolerance)

    rospy.init_node("pure_pursuit", argv=args_in)
    pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
    while pub.get_num_connections() == 0 and not rospy.is_shutdown():
        time.sleep(0.01)  # see the module doc: an answer before Arena connects is lost
    state: dict[str, Any] = {"plan": np.zeros((0, 2)), "scan": None, "goal_yaw": None}

    def on_goal(msg: Any) -> None:
        state["goal_yaw"] = _yaw(msg.pose.orientation)

    def on_plan(msg: Any) -> None:
        state["plan"] = np.array([[p.pose.position.x, p.pose.position.y] for p in msg.poses])

    def on_scan(msg: Any) -> None:
        r = np.asarray(msg.ranges, dtype=np.float64)
        a = msg.angle_min + msg.angle_increment * np.arange(len(r))
        state["scan"] = (r, a)

    def on_odom(msg: Any) -> None:
        p = msg.pose.pose
        pose = np.array([p.position.x, p.position.y, _yaw(p.orientation)])
        v, w = pursuit_command(pose, state["plan"], state["scan"], params, state["goal_yaw"])
        cmd = Twist()
        cmd.linear.x, cmd.angular.z = v, w
        pub.publish(cmd)

    rospy.Subscriber("plan", Path, on_plan, queue_size=10, tcp_nodelay=True)
    rospy.Subscriber("scan", LaserScan, on_scan, queue_size=10, tcp_nodelay=True)
    rospy.Subscriber("goal_pose", PoseStamped, on_goal, queue_size=1)
    rospy.Subscriber("odom", Odometry, on_odom, queue_size=10, tcp_nodelay=True)
    rospy.spin()


if __name__ == "__main__":
    main()
