"""The ROS bridges' speed: lock-step round trips and real-time control with people.

    python benchmarks/ros_bridge.py [--ros 2|1] [--steps 1200] [--people 50] [--seconds 20]

Runs in loopback-only network and PID namespaces (it re-runs itself under ``unshare`` unless
``--here``; the PID namespace ends every node it started), ROS 2 with
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, ROS 1 with its own ``rosmaster --core``, and
Arena's example node (``python -m arena.ros.nodes.local_planner``, ROS 1:
``local_planner_ros1``; Arena's ``pure_pursuit`` behind ROS) as the external planner:

* lock-step: episodes on an empty 10 × 10 m map without people; each step sends the
  episode's subscribed topics and waits for the node's ``/cmd_vel``. Prints simulated steps per
  second of wall time after the first episode (node start and discovery): a full round trip,
  scan and odom out, the node's command back.
* real time: one episode with ``--people`` people on a 20 × 20 m map, paced to the wall clock
  at the config's 10 Hz control rate; prints the achieved steps per second of wall time
  (10 = held) and the control cycle (the stack's call, which takes the latest command).

Goals (issue 23): lock-step >= 500 steps/s; real time holds 10 Hz with 50 people.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

NODES = {"2": "arena.ros.nodes.local_planner", "1": "arena.ros.nodes.local_planner_ros1"}
EMPTY = {"type": "empty", "width": 10, "height": 10}
MASTER_PORT = 11311


def _run(ros: str, mode: str, items: list[str], realtime: bool = False):
    from arena.config import load_config
    from arena.experiment import run_experiment

    spec = {"type": f"ros{ros}", "mode": mode, "launch": ["python", "-m", NODES[ros]]}
    cfg = load_config(None, ["output.video=false", f"map={json.dumps(EMPTY)}",
                             f"navigation.local_planner={json.dumps(spec)}", *items])
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        _, results = run_experiment(cfg, tmp, realtime=realtime)
        return cfg, results, time.perf_counter() - t0


def lockstep(ros: str, steps: int) -> None:
    # episodes end at the goal (~120 steps); the first one pays for the node's start
    # 20 x 20 m, 15 m goals: long episodes, so the per-episode set-up (reset, map) is small
    episodes = 1 + max(1, steps // 150)
    _, results, _ = _run(ros, "lockstep", [
        f"episodes={episodes}", "task.obstacles.dynamic=0", "task.obstacles.static=0",
        "task.timeout=60", "map.width=20", "map.height=20", "task.robots.goal_distance=15"])
    later = results[1:]
    n = sum(r.steps for r in later)
    wall = sum(r.wall_time for r in later)
    trip = float(np.mean([r.control_ms_mean for r in later]))
    print(f"ROS {ros} lock-step: {n} steps in {wall:.2f} s = {n / wall:.0f} steps/s with each "
          f"episode's set-up; round trip (topics out, command back) {trip:.2f} ms = "
          f"{1e3 / trip:.0f} per s (first episode, with node start and discovery: "
          f"{results[0].steps} steps in {results[0].wall_time:.2f} s); success "
          f"{sum(r.outcome == 'success' for r in results)}/{len(results)}")


def realtime(ros: str, people: int, seconds: float) -> None:
    cfg, results, wall = _run(ros, "realtime", [
        "episodes=1", f"task.obstacles.dynamic={people}", "task.obstacles.static=0",
        f"task.timeout={seconds}", "map.width=20", "map.height=20"], realtime=True)
    r = results[0]
    print(f"ROS {ros} real time, {people} people: {r.steps} steps of {cfg.sim.dt:g} s in "
          f"{wall:.2f} s wall = {r.steps / r.wall_time:.2f} steps/s (target "
          f"{1 / cfg.sim.dt:g}); control cycle mean {r.control_ms_mean:.2f} ms, p95 "
          f"{r.control_ms_p95:.2f} ms, max {r.control_ms_max:.2f} ms; outcome {r.outcome}")


def _isolated(ros: str) -> int:
    """This script again, in its own network and PID namespaces (ROS 1: with a master)."""
    cmd = ["unshare", "-n", "-p", "--fork", "--kill-child"]
    if os.geteuid() != 0:
        cmd.insert(1, "-r")
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    script = 'ip link set lo up && exec "$@"'
    if ros == "1":
        env.update(ROS_MASTER_URI=f"http://127.0.0.1:{MASTER_PORT}", ROS_IP="127.0.0.1")
        env.pop("ROS_HOSTNAME", None)
        script = (f"ip link set lo up && rosmaster --core -p {MASTER_PORT} >/dev/null 2>&1 & "
                  'sleep 1.5 && exec "$@"')
    return subprocess.call([*cmd, "sh", "-c", script, "sh", sys.executable, *sys.argv,
                            "--here"], env=env)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--ros", choices=("2", "1"), default="2")
    ap.add_argument("--steps", type=int, default=1200)
    ap.add_argument("--people", type=int, default=50)
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--here", action="store_true",
                    help="use this network namespace (ROS 1: the master at ROS_MASTER_URI)")
    args = ap.parse_args()
    if not args.here:
        sys.exit(_isolated(args.ros))
    if args.ros == "1":
        from arena.ros.ros1_env import check_master

        check_master()
    lockstep(args.ros, args.steps)
    realtime(args.ros, args.people, args.seconds)


if __name__ == "__main__":
    main()
