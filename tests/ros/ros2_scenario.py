"""Scenarios of the ROS 2 bridge tests, each run by tests/ros/sandbox.py in its own network
and PID namespaces (loopback only). Usage, from the repository:
``python -m tests.ros.ros2_scenario CASE OUT_DIR``; the last line printed is the JSON result.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

EMPTY = 'map={"type": "empty", "width": 10, "height": 10}'
#: No people, so the example node's plain pursuit reaches its goal.
NO_PEOPLE = ["task.obstacles.dynamic=0", "task.obstacles.static=0"]


def _arena(*args: str, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "arena.cli", *args], capture_output=True,
                          text=True, timeout=timeout, check=False)


def _outcomes(out: Path) -> list[str]:
    lines = (out / "summary.csv").read_text().splitlines()
    col = lines[0].split(",").index("outcome")
    return [ln.split(",")[col] for ln in lines[1:]]


def episode(out: Path) -> dict:
    """arena ros2 run, lock-step, with the example node launched: it reaches its goals."""
    done = _arena("ros2", "run", EMPTY, *NO_PEOPLE, "episodes=2", "--mode", "lockstep",
                  "--launch", "python -m arena.ros.nodes.local_planner", "-o", str(out / "run"))
    return {"rc": done.returncode, "stderr": done.stderr[-2000:],
            "outcomes": _outcomes(out / "run") if done.returncode == 0 else []}


def silent(out: Path) -> dict:
    """No node answers: each episode ends as error after the timeout, the run goes on."""
    spec = {"type": "ros2", "timeout": 0.5, "startup_timeout": 1.0}
    done = _arena("run", EMPTY, *NO_PEOPLE, "episodes=2", "output.video=false",
                  f"navigation.local_planner={json.dumps(spec)}", "-o", str(out / "run"))
    errors = []
    if done.returncode == 0:
        summary = json.loads((out / "run" / "episode_000" / "episode.json").read_text())
        errors.append(summary["error"])
    return {"rc": done.returncode, "stderr": done.stderr[-2000:],
            "outcomes": _outcomes(out / "run") if done.returncode == 0 else [],
            "errors": errors}


SUITE = """
stages:
  - name: room
    episodes: 4
    robot: jackal
    map: empty_room
    tm_robots: random
    tm_obstacles: random
    config:
      RANDOM:
        static: {min: 0, max: 0}
        dynamic: {min: 0, max: 0}
"""
CONTEST = """
contestants:
  - name: ros_pursuit
    local_planner: ros2
    params: {mode: lockstep, namespace: auto,
             launch: [python, -m, arena.ros.nodes.local_planner]}
"""


def bench(out: Path) -> dict:
    """arena bench with a ROS 2 contestant on two workers, each with its own node."""
    (out / "suite.yaml").write_text(SUITE)
    (out / "contest.yaml").write_text(CONTEST)
    done = _arena("bench", str(out / "suite.yaml"), "--contest", str(out / "contest.yaml"),
                  "--workers", "2", "-o", str(out / "bench"), timeout=240)
    rows = [json.loads(f.read_text())
            for f in sorted((out / "bench" / "episodes").glob("*/*/*.json"))]
    return {"rc": done.returncode, "stderr": done.stderr[-2000:],
            "outcomes": [r.get("outcome") for r in rows],
            "contestants": sorted({r.get("contestant", "") for r in rows})}


def topics(out: Path) -> dict:
    """A peer node hears the link's topics and talks back (values checked by the test)."""
    import rclpy
    from geometry_msgs.msg import PoseStamped, Twist
    from nav_msgs.msg import OccupancyGrid, Odometry
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from sensor_msgs.msg import LaserScan
    from std_srvs.srv import Trigger
    from tf2_msgs.msg import TFMessage

    from arena.core.types import Pose2D
    from arena.ros.link import LinkOptions, RosLink
    from arena.ros.ros2 import Ros2Transport
    from tests.ros.scenes import sample_frame, sample_scene

    link = RosLink(Ros2Transport, LinkOptions())
    got: dict[str, list] = {"cmd": [], "goal": [], "reset": []}
    peer = rclpy.create_node("peer")
    heard: dict[str, list] = {"scan": [], "tf": [], "odom": [], "map": []}
    peer.create_subscription(LaserScan, "/scan", lambda m: heard["scan"].append(m), 10)
    peer.create_subscription(TFMessage, "/tf", lambda m: heard["tf"].append(m), 10)
    peer.create_subscription(Odometry, "/odom", lambda m: heard["odom"].append(m), 10)
    scene = sample_scene(robots=1)
    link.scene(scene)
    deadline = time.monotonic() + 20
    frame = sample_frame(0, robots=1)
    while not heard["odom"] and time.monotonic() < deadline:  # discovery, then one frame
        link.frame(frame)
        rclpy.spin_once(peer, timeout_sec=0.05)
        link.transport.poll(0.0)
    # a late subscriber still gets the latched map
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    peer.create_subscription(OccupancyGrid, "/map", lambda m: heard["map"].append(m), latched)
    cmd_pub = peer.create_publisher(Twist, "/cmd_vel", 10)
    goal_pub = peer.create_publisher(PoseStamped, "/goal_pose", 10)
    reset = peer.create_client(Trigger, "/arena/reset")
    twist = Twist()
    twist.linear.x, twist.angular.z = 0.4, -0.2
    goal = PoseStamped()
    goal.pose.position.x, goal.pose.position.y = 3.0, 4.0
    goal.pose.orientation.z, goal.pose.orientation.w = np.sin(0.25), np.cos(0.25)
    future = None
    while time.monotonic() < deadline and not (heard["map"] and got["cmd"] and got["goal"]
                                               and got["reset"]):
        cmd_pub.publish(twist)
        goal_pub.publish(goal)
        if future is None and reset.service_is_ready():
            future = reset.call_async(Trigger.Request())
        rclpy.spin_once(peer, timeout_sec=0.02)
        link.transport.poll(0.02)
        got["goal"] += [g.as_array().tolist() for g in link.take_goals()]
        resets = link.take_resets()
        got["reset"] += [resets] if resets else []
        if link._inbox.command is not None:
            got["cmd"].append(link._inbox.command.tolist())
    scan, tf = heard["scan"][-1], heard["tf"][-1]
    link.close()
    return {
        "scan": np.asarray(scan.ranges).tolist(), "scan_frame": scan.header.frame_id,
        "expected_scan": np.asarray(frame.lidar_scans[0]["laser"], dtype=np.float32).tolist(),
        "tf": [(t.header.frame_id, t.child_frame_id, t.transform.translation.x)
               for t in tf.transforms],
        "pose": frame.poses[0].tolist(),
        "odom_stamp": heard["odom"][-1].header.stamp.nanosec,
        "map": [heard["map"][-1].info.width, heard["map"][-1].info.height] if heard["map"] else [],
        "map_expected": [scene.grid.width, scene.grid.height],
        "cmd": got["cmd"][:1], "goal": got["goal"][:1], "reset": len(got["reset"]),
        "goal_expected": Pose2D(3.0, 4.0, 0.5).as_array().tolist(),
    }


if __name__ == "__main__":
    case, out_dir = sys.argv[1], Path(sys.argv[2])
    cases = {"episode": episode, "silent": silent, "topics": topics, "bench": bench}
    print(json.dumps(cases[case](out_dir)))
