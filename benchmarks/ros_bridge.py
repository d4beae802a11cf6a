"""The ROS 2 bridge's speed: lock-step round trips and real-time control with people.

    python benchmarks/ros_bridge.py [--steps 1000] [--people 50] [--seconds 20]

Runs in a loopback-only network namespace (it re-runs itself under ``unshare -n`` unless
``--here``) with ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, with Arena's example node
(``python -m arena.ros.nodes.pure_pursuit``) as the external planner:

* lock-step: episodes on an empty 10 × 10 m map without people; each step sends the
  episode's topics (only those subscribed, and ``/odom`` always) and waits for the node's
  ``/cmd_vel``. Prints simulated steps per second of wall time, after the first episode
  (node start and discovery) — a full round trip: scan and odom out, the node's command back.
* real time: one episode with ``--people`` people, paced to the wall clock at the config's
  10 Hz control rate; prints the achieved steps per second of wall time (10 = held), the
  control cycle (the stack's call, which takes the node's latest command) and how many
  people messages went out.

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

NODE = ["python", "-m", "arena.ros.nodes.pure_pursuit"]
EMPTY = {"type": "empty", "width": 10, "height": 10}


def _config(items: list[str]):
    from arena.config import load_config

    return load_config(None, ["output.video=false", f"map={json.dumps(EMPTY)}", *items])


def lockstep(steps: int) -> None:
    from arena.experiment import run_experiment

    spec = {"type": "ros2", "mode": "lockstep", "launch": NODE}
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
          f"(first episode, with node start and discovery: {results[0].steps} steps in "
          f"{results[0].wall_time:.2f} s); outcomes {[r.outcome for r in results]}")


def realtime(people: int, seconds: float) -> None:
    from arena.experiment import run_experiment

    spec = {"type": "ros2", "mode": "realtime", "launch": NODE}
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
          f"{r.control_ms_max:.2f} ms; outcome {r.outcome}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=1200)
    ap.add_argument("--people", type=int, default=50)
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--here", action="store_true", help="do not enter a network namespace")
    args = ap.parse_args()
    if not args.here:
        cmd = ["unshare", "-n"] if os.geteuid() == 0 else ["unshare", "-rn"]
        env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
        sys.exit(subprocess.call([*cmd, "sh", "-c", 'ip link set lo up && exec "$@"', "sh",
                                  sys.executable, *sys.argv, "--here"], env=env))
    lockstep(args.steps)
    realtime(args.people, args.seconds)


if __name__ == "__main__":
    main()
