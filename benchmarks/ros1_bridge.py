"""The ROS 1 bridge's speed: lock-step round trips and real-time control with people.

    python benchmarks/ros1_bridge.py [--steps 1200] [--people 50] [--seconds 20]

The ROS 1 twin of ``benchmarks/ros_bridge.py``. Runs in loopback-only network and PID
namespaces (it re-runs itself under ``unshare`` unless ``--here``) with its own ROS master
(``rosmaster --core``), with Arena's example ROS 1 node (``python -m
arena.ros.nodes.pure_pursuit_ros1``) as the external planner:

* lock-step: episodes on an empty 10 × 10 m map without people; each step sends the
  episode's subscribed topics and waits for the node's ``/cmd_vel``. Prints simulated steps per
  second of wall time after the first episode (node start and connection): a full round trip,
  scan and odom out, the node's command back.
* real time: one episode with ``--people`` people, paced to the wall clock at the config's
  10 Hz control rate; prints the achieved steps per second of wall time (10 = held) and the
  control cycle.

Goals (issue 23, stated for ROS 2; the same here): lock-step >= 500 steps/s; real time holds
10 Hz with 50 people. Needs Debian's ROS 1 (``bash tools/install_ros1.sh``).
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

NODE = ["python", "-m", "arena.ros.nodes.pure_pursuit_ros1"]
EMPTY = {"type": "empty", "width": 10, "height": 10}
PORT = 11311


def _config(items: list[str]):
    from arena.config import load_config

    return load_config(None, ["output.video=false", f"map={json.dumps(EMPTY)}", *items])


def lockstep(steps: int) -> None:
    from arena.experiment import run_experiment

    spec = {"type": "ros1", "mode": "lockstep", "launch": NODE}
    # long episodes: after the goal the example node holds still, the steps go on
    episodes = 1 + max(1, steps // 600)
    cfg = _config([f"navigation.local_planner={json.dumps(spec)}", f"episodes={episodes}",
                   "task.obstacles.dynamic=0", "task.obstacles.static=0", "task.timeout=60"])
    with tempfile.TemporaryDirectory() as tmp:
        _, results = run_experiment(cfg, tmp)
    later = results[1:]
    n = sum(r.steps for r in later)
    wall = sum(r.wall_time for r in later)
    print(f"lock-step: {n} steps in {wall:.2f} s = {n / wall:.0f} steps/s "
          f"(first episode, with node start and connection: {results[0].steps} steps in "
          f"{results[0].wall_time:.2f} s); outcomes {[r.outcome for r in results]}")


def realtime(people: int, seconds: float) -> None:
    from arena.experiment import run_experiment

    spec = {"type": "ros1", "mode": "realtime", "launch": NODE}
    cfg = _config([f"navigation.local_planner={json.dumps(spec)}", "episodes=1",
                   f"task.obstacles.dynamic={people}", "task.obstacles.static=0",
                   f"task.timeout={seconds}", "map.width=20", "map.height=20"])
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        _, results = run_experiment(cfg, tmp, realtime=True)
        wall = time.perf_counter() - t0
    r = results[0]
    print(f"real time, {people} people: {r.steps} steps of {cfg.sim.dt:g} s in {wall:.2f} s "
          f"wall = {r.steps / r.wall_time:.2f} steps/s (target {1 / cfg.sim.dt:g}); control "
          f"cycle mean {r.control_ms_mean:.2f} ms, p95 {r.control_ms_p95:.2f} ms, max "
          f"{r.control_ms_max:.2f} ms; outcome {r.outcome} {r.error}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=1200)
    ap.add_argument("--people", type=int, default=50)
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--here", action="store_true",
                    help="use this network namespace and the master at ROS_MASTER_URI")
    args = ap.parse_args()
    if not args.here:
        cmd = ["unshare", "-n", "-p", "--kill-child"]  # the PID namespace ends every node
        if os.geteuid() != 0:
            cmd.insert(1, "-r")
        env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{PORT}", ROS_IP="127.0.0.1")
        env.pop("ROS_HOSTNAME", None)
        script = (f'ip link set lo up && rosmaster --core -p {PORT} >/dev/null 2>&1 & '
                  'sleep 1.5 && exec "$@"')
        sys.exit(subprocess.call([*cmd, "sh", "-c", script, "sh", sys.executable, *sys.argv,
                                  "--here"], env=env))
    from arena.ros.ros1_env import check_master

    check_master()
    lockstep(args.steps)
    realtime(args.people, args.seconds)


if __name__ == "__main__":
    main()
