"""Local planners side by side: compute time per control cycle, success, collisions, time to goal.

For every registered local planner that drives a jackal, runs ``--episodes`` seeded episodes on

  (a) ``static``:  generated indoor maps (rosnav_indoor, a new map per episode) with 5 random
                   shelves/boxes and no people,
  (b) ``canteen``: generated canteens (a new map per episode) with 10 walking people,

and prints one table row per planner and world: success rate, episodes with a collision, mean
collisions, mean time to goal over successful episodes, and the navigation stack's compute time
per control cycle (mean over all cycles, and the median over episodes of each episode's
95th percentile; global + intermediate + local planner).
Episodes are the same for every planner (same seeds). Episodes run in ``--workers`` processes;
results do not depend on the worker count.

    python benchmarks/planners.py [--episodes 30] [--workers 2] [--planners dwa,teb]
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

import arena.plugins  # noqa: F401
from arena.config.loader import load_config
from arena.nav.local_planners.base import LOCAL_PLANNERS

WORLDS: dict[str, list[str]] = {
    "static": [
        "map.type=rosnav_indoor",
        "map.width=20",
        "map.height=20",
        "task.obstacles.static=5",
        "task.obstacles.dynamic=0",
        "task.robots.min_goal_distance=10",
        "task.modules=[{type: dynamic_map, episodes_per_map: 1}]",
    ],
    "canteen": [
        "map.type=canteen",
        "task.obstacles.static=0",
        "task.obstacles.dynamic=10",
        "task.robots.min_goal_distance=10",
        "task.modules=[{type: dynamic_map, episodes_per_map: 1}]",
    ],
}
COMMON = [
    "robot=jackal",
    "seed=7",
    "task.timeout=60",
    "task.goal_tolerance_angle=null",
    "output.video=false",
]


@dataclass
class Row:
    """One episode's figures."""

    outcome: str
    collisions: int
    time: float
    steps: int
    cycle_ms_mean: float
    cycle_ms_p95: float


def run_one(planner: str, world: str, index: int) -> Row:
    """Episode ``index`` of ``world`` with ``planner`` (in a worker process)."""
    from arena.experiment import run_episode
    from arena.sim.backend import BACKENDS
    from arena.tasks.generator import TaskGenerator

    cfg = load_config(None, [*COMMON, *WORLDS[world], f"navigation.local_planner.type={planner}"])
    gen = TaskGenerator.from_config(cfg)
    episode = gen.episode(index)
    backend = BACKENDS.build(cfg.sim.backend)
    res = run_episode(cfg, episode, backend, None, runtime=gen.runtime(episode))
    return Row(res.outcome, res.collisions, res.time, res.steps, res.control_ms_mean,
               res.control_ms_p95)


def main() -> None:
    """Run every planner on both worlds and print the table."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=30)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--planners", default="", help="comma-separated subset (default: all)")
    args = ap.parse_args()
    names = [n for n in LOCAL_PLANNERS.names() if "diff_drive" in LOCAL_PLANNERS.get(n).supports]
    if args.planners:
        names = [n for n in names if n in args.planners.split(",")]
    print(f"local planners, jackal, {args.episodes} episodes per world, {args.workers} workers")
    head = (f"{'planner':14s} {'world':8s} {'success':>8s} {'coll.ep':>8s} {'coll/ep':>8s} "
            f"{'t_goal s':>9s} {'cycle ms':>9s} {'p95 ms':>7s} {'wall s':>7s}")
    print(head)
    print("-" * len(head))
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        for name in names:
            for world in WORLDS:
                t0 = time.perf_counter()
                rows = list(
                    pool.map(
                        run_one,
                        [name] * args.episodes,
                        [world] * args.episodes,
                        range(args.episodes),
                    )
                )
                wall = time.perf_counter() - t0
                ok = [r for r in rows if r.outcome == "success"]
                steps = np.array([max(r.steps, 1) for r in rows], dtype=float)
                cycle = float(np.average([r.cycle_ms_mean for r in rows], weights=steps))
                p95 = float(np.median([r.cycle_ms_p95 for r in rows]))
                t_goal = np.mean([r.time for r in ok]) if ok else float("nan")
                print(
                    f"{name:14s} {world:8s} {100 * len(ok) / len(rows):7.0f}% "
                    f"{sum(r.collisions > 0 for r in rows):8d} "
                    f"{np.mean([r.collisions for r in rows]):8.2f} {t_goal:9.1f} "
                    f"{cycle:9.2f} {p95:7.2f} {wall:7.1f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
