"""Arena's side of the ROS 1 bridge tests, run inside a loopback-only network namespace.

Started by :func:`tests.ros.ros1_kit.run_isolated` with ``ROS_MASTER_URI`` set: starts a ROS
master (``rosmaster --core``) and the test's node (:mod:`tests.ros.ros1_peer`), runs one case
and prints its result as JSON on the last stdout line; stops both in any case.

Cases:
    ``roundtrip``: a hand-made scene and two frames through a lock-step
    :class:`~arena.ros.link.RosLink` to the ``probe`` node; reports what was sent, what the node
    received and what came back.
    ``episode OUT [EPISODES]``: ``arena ros1 run`` in lock-step, launching that node.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

import numpy as np

from arena.core.errors import ConfigError
from arena.live.frame import LiveFrame, LiveScene
from arena.maps.grid import OccupancyGrid
from arena.ros.link import LinkOptions, RosLink
from arena.ros.ros1 import Ros1Transport
from arena.ros.ros1_env import check_master, master_uri
from tests.ros.scenes import sample_frame, sample_scene

PEER = Path(__file__).with_name("ros1_peer.py")
#: s to wait for the master, a reply, the node's exit.
WAIT_S = 20.0


def scene() -> LiveScene:
    """The sample scene with one robot, on a map whose last row ends in an unknown cell."""
    base = sample_scene(1)
    data = base.grid.data.copy()
    data[3, 5] = -1
    return replace(base, grid=OccupancyGrid(data, base.grid.resolution, base.grid.origin))


def frame(step: int) -> LiveFrame:
    """Step ``step``: the robot at x = 0.5 + step, ranges ``[1.0 + step, ..., 1.4 + step]``."""
    base = sample_frame(step, 1)
    ranges = 1.0 + step + 0.1 * np.arange(5, dtype=np.float64)
    return replace(base, poses=np.array([[0.5 + step, 2.0, 0.5]]),
                   twists=np.array([[0.25, 0.0, 0.0]]), scan=ranges,
                   lidar_scans=({"laser": ranges},))


def wait_until(done: Callable[[], bool], poll: Callable[[float], None], what: str) -> None:
    end = time.monotonic() + WAIT_S
    while not done():
        if time.monotonic() > end:
            raise TimeoutError(f"no {what} within {WAIT_S:g} s")
        poll(0.05)


def graph() -> dict[str, list[str]]:
    """The master's view: for each node, the topics it publishes, subscribes and serves."""
    import rosgraph

    pubs, subs, srvs = rosgraph.Master("/scenario").getSystemState()
    out: dict[str, list[str]] = {}
    for kind, table in (("pub", pubs), ("sub", subs), ("srv", srvs)):
        for name, nodes in table:
            for node in nodes:
                out.setdefault(node, []).append(f"{kind} {name}")
    return {node: sorted(v) for node, v in out.items()}


def roundtrip() -> dict[str, Any]:
    peer = subprocess.Popen([sys.executable, str(PEER), "probe"], stdout=subprocess.PIPE,
                            text=True)
    link = RosLink(Ros1Transport, LinkOptions(timeout=WAIT_S, startup_timeout=WAIT_S))
    try:
        link.scene(scene())
        link.frame(frame(1))
        first = link.command().tolist()
        goals: list[Any] = []
        resets = [0]

        def arrived() -> bool:
            goals.extend(link.take_goals())
            resets[0] += link.take_resets()
            return bool(goals) and resets[0] > 0

        wait_until(arrived, link.transport.poll, "goal and reset")
        link.frame(frame(2))
        second = link.command().tolist()
        out, _ = peer.communicate(timeout=WAIT_S)
    finally:
        link.close()
        peer.kill()
    closed = graph()
    # a second link of the process: the same node, its own publishers again
    again = RosLink(Ros1Transport, LinkOptions(namespace="/second"))
    again.scene(scene())
    reopened = graph()
    # a third of the same namespace: the reset service goes to the latest open link
    twin = RosLink(Ros1Transport, LinkOptions(namespace="/second"))
    served = reset_calls("/second/arena/reset", twin, again)
    twin.close()
    served += reset_calls("/second/arena/reset", again)
    again.close()
    return {"commands": [first, second], "goals": [[g.x, g.y, g.theta] for g in goals],
            "resets": resets[0], "peer": json.loads(out.strip().splitlines()[-1]),
            "graph_closed": closed.get("/arena", []), "graph_reopened": reopened.get("/arena", []),
            "served": served, "graph_last": graph().get("/arena", [])}


def reset_calls(service: str, *links: RosLink) -> list[int]:
    """Call ``service`` once; the resets each of ``links`` counted."""
    import rospy
    from std_srvs.srv import Trigger

    rospy.wait_for_service(service, timeout=WAIT_S)
    rospy.ServiceProxy(service, Trigger)()
    return [link.take_resets() for link in links]


def episode(out: str, episodes: str = "2") -> dict[str, Any]:
    """``arena ros1 run`` in lock-step, its ``--launch`` starting the shipped ROS 1 node
    (Arena's pure pursuit at 0.6 m/s); the episodes' summary rows."""
    import csv

    argv = [sys.executable, "-c", "from arena.cli import main; main()", "ros1", "run",
            "map.type=empty", "map.width=10", "map.height=10", "output.video=false",
            "task.obstacles.static=0", "task.obstacles.dynamic=4", "task.timeout=40",
            "task.robots.goal_distance=6", "--mode", "lockstep", "--timeout", "10",
            "--launch", "python -m arena.ros.nodes.local_planner_ros1 --params "
            "'{\"max_speed\": 0.6}'", "-n", episodes,
            "-o", out]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=WAIT_S * 3, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"arena ros1 run failed: {done.stderr[-2000:]}{done.stdout[-2000:]}")
    with (Path(out) / "summary.csv").open() as f:
        rows = [{k: row[k] for k in ("outcome", "steps", "collisions", "final_goal_distance",
                                     "error")} for row in csv.DictReader(f)]
    return {"rows": rows}


CASES: dict[str, Callable[..., dict[str, Any]]] = {
    "roundtrip": roundtrip, "episode": episode}


def main() -> None:
    case = sys.argv[1]
    port = urlparse(master_uri()).port or 11311
    master = subprocess.Popen(["rosmaster", "--core", "-p", str(port)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        end = time.monotonic() + WAIT_S
        while True:
            try:
                check_master(timeout=0.5)
                break
            except ConfigError:
                if time.monotonic() > end or master.poll() is not None:
                    raise
                time.sleep(0.05)
        result = CASES[case](*sys.argv[2:])
    finally:
        master.terminate()
        try:
            master.wait(3)
        except subprocess.TimeoutExpired:
            master.kill()
    print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
