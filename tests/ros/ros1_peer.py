"""The test's own rospy node, run by :mod:`tests.ros.ros1_scenario` (one node per process).

``probe``: subscribes to Arena's topics, then sends a goal, calls ``/arena/reset`` and answers
each new ``/odom`` with a ``cmd_vel`` that encodes it (``vx`` = the odometry's x, ``wz`` = its
stamp in s), subscribes ``/map`` and ``/goal_pose`` late (latched topics) and prints what it
received as JSON.

Usage: ``python ros1_peer.py probe`` with ``ROS_MASTER_URI`` set; it exits once done. (The
episode case is answered by Arena's shipped node,
:mod:`arena.ros.nodes.local_planner_ros1`.)
"""

from __future__ import annotations

import json
import math
import sys
import threading
import time
from typing import Any

import numpy as np

from arena.ros.ros1_env import import_rospy

rospy = import_rospy()
from geometry_msgs.msg import PoseStamped, Twist  # noqa: E402 (after import_rospy's path)
from nav_msgs.msg import OccupancyGrid, Odometry, Path  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import LaserScan, PointCloud2  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402
from visualization_msgs.msg import MarkerArray  # noqa: E402

#: s every wait of the probe may take.
WAIT_S = 20.0


def _secs(stamp: Any) -> float:
    return float(stamp.secs + stamp.nsecs * 1e-9)


def _yaw(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Inbox:
    """The latest message of each topic, filled by rospy's threads."""

    def __init__(self) -> None:
        self.cond = threading.Condition()
        self.latest: dict[str, Any] = {}
        self.count: dict[str, int] = {}

    def callback(self, topic: str) -> Any:
        def on_message(msg: Any) -> None:
            with self.cond:
                self.latest[topic] = msg
                self.count[topic] = self.count.get(topic, 0) + 1
                self.cond.notify_all()
        return on_message

    def wait(self, ready: Any, timeout: float = WAIT_S) -> None:
        """Wait until ``ready()`` (called under the lock) holds, or fail."""
        with self.cond:
            if not self.cond.wait_for(ready, timeout):
                raise TimeoutError(f"waited {timeout:g} s; have {sorted(self.latest)}")


def _wait_connected(pub: Any, timeout: float = WAIT_S) -> None:
    end = time.monotonic() + timeout
    while pub.get_num_connections() == 0:
        if time.monotonic() > end:
            raise TimeoutError(f"no subscriber on {pub.resolved_name}")
        time.sleep(0.01)


def probe() -> dict[str, Any]:
    inbox = Inbox()
    types = {"/scan": LaserScan, "/tf": TFMessage, "/tf_static": TFMessage, "/odom": Odometry,
             "/clock": Clock, "/plan": Path, "/people/states": PointCloud2,
             "/people/markers": MarkerArray}
    subs = [rospy.Subscriber(t, cls, inbox.callback(t), queue_size=10, tcp_nodelay=True)
            for t, cls in types.items()]
    cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=10)
    goal = rospy.Publisher("/goal_pose", PoseStamped, queue_size=1, latch=True)
    inbox.wait(lambda: set(types) <= set(inbox.latest))
    _wait_connected(cmd)
    _wait_connected(goal)
    g = PoseStamped()
    g.header.frame_id = "map"
    g.pose.position.x, g.pose.position.y = 3.0, -1.0
    g.pose.orientation.z, g.pose.orientation.w = math.sin(0.25), math.cos(0.25)
    goal.publish(g)
    rospy.wait_for_service("/arena/reset", timeout=WAIT_S)
    reset = rospy.ServiceProxy("/arena/reset", Trigger)()
    # answer each new odometry (a repeat of a frame has the same stamp: answered once)
    answered: list[float] = []
    end = time.monotonic() + WAIT_S
    while time.monotonic() < end and (not answered or answered[-1] < 0.2 - 1e-9):
        with inbox.cond:
            inbox.cond.wait_for(lambda: _secs(inbox.latest["/odom"].header.stamp)
                                not in answered, 0.1)
            odom = inbox.latest["/odom"]
        t = _secs(odom.header.stamp)
        if t in answered:
            continue
        answered.append(t)
        reply = Twist()
        reply.linear.x, reply.angular.z = odom.pose.pose.position.x, t
        cmd.publish(reply)
    late = rospy.Subscriber("/map", OccupancyGrid, inbox.callback("/map"), queue_size=1)
    goals: list[list[Any]] = []  # the latched goals of both publishers (Arena's and ours)
    late_goal = rospy.Subscriber("/goal_pose", PoseStamped, lambda m: goals.append(
        [m._connection_header["callerid"], m.pose.position.x, m.pose.position.y]))
    inbox.wait(lambda: "/map" in inbox.latest)
    end = time.monotonic() + WAIT_S
    while len(goals) < 2 and time.monotonic() < end:
        time.sleep(0.01)
    with inbox.cond:
        got = dict(inbox.latest)
    for s in [*subs, late, late_goal]:
        s.unregister()
    scan, odom, grid = got["/scan"], got["/odom"], got["/map"]
    tf = got["/tf"].transforms[0]
    cloud = got["/people/states"]
    people = np.frombuffer(bytes(cloud.data), dtype=np.float32).reshape(cloud.width, -1)
    markers = got["/people/markers"].markers
    return {
        "scan": {"ranges": list(scan.ranges), "frame_id": scan.header.frame_id,
                 "stamp": _secs(scan.header.stamp), "angle_min": scan.angle_min,
                 "angle_increment": scan.angle_increment, "range_max": scan.range_max},
        "tf_static": sorted([t.header.frame_id, t.child_frame_id, t.transform.translation.x]
                            for t in got["/tf_static"].transforms),
        "tf": [tf.header.frame_id, tf.child_frame_id, tf.transform.translation.x,
               tf.transform.translation.y, _yaw(tf.transform.rotation)],
        "odom": [odom.header.frame_id, odom.child_frame_id, odom.pose.pose.position.x,
                 odom.twist.twist.linear.x, _secs(odom.header.stamp)],
        "clock": _secs(got["/clock"].clock),
        "plan": [[p.pose.position.x, p.pose.position.y] for p in got["/plan"].poses],
        "people": {"names": [f.name for f in cloud.fields], "xy": people[:, :2].tolist()},
        "markers": [[m.ns, m.id, m.type, m.action] for m in markers],
        "map": {"width": grid.info.width, "height": grid.info.height,
                "resolution": grid.info.resolution,
                "origin": [grid.info.origin.position.x, grid.info.origin.position.y],
                "data": list(grid.data)},
        "reset": [reset.success, reset.message],
        "goals": sorted(goals),
        "answered": answered,
    }


if __name__ == "__main__":
    role = sys.argv[1]
    rospy.init_node(f"test_{role}", disable_signals=True)
    print(json.dumps(probe()), flush=True)
