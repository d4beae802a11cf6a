"""Benchmark of the grid global planners (astar, dijkstra, theta_star) and the costmap layers.

Scenarios (seeded): random maps with 20 % occupied cells at 0.05 m/cell, 200 × 200 and
1000 × 1000 cells, planning corner to corner; plus an open room of the same sizes (borders
only), where Dijkstra expands everything and Theta* checks the longest lines of sight. Each
planner runs with its defaults (A* and Dijkstra: clearance cost and smoothing on). Timings are
best-of-N wall times after a warm-up call (JIT compilation / cache load), one core.

Run: ``.venv/bin/python benchmarks/planners_global.py [--repeats N]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from arena.core.geometry import polyline_length
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.costmap import GlobalCostmap, LocalCostmap
from arena.nav.global_planners import GLOBAL_PLANNERS

RES = 0.05
SEED = 0


def _random_map(n: int, density: float) -> OccupancyGrid:
    rng = np.random.default_rng(SEED)
    occ = rng.random((n, n)) < density
    occ[:5, :5] = occ[-5:, -5:] = False
    return OccupancyGrid.from_occupied(occ, RES)


def _best_ms(fn, repeats: int) -> float:
    fn()  # warm-up
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per case (best kept)")
    args = parser.parse_args()

    print(f"Global planners: ms per plan (best of {args.repeats}, after warm-up), 0.05 m/cell")
    print(f"  {'map':<26}{'planner':<12}{'ms/plan':>10}{'length m':>11}{'waypoints':>11}")
    for n in (200, 1000):
        maps = {
            f"{n}x{n} random 20 %": _random_map(n, 0.2),
            f"{n}x{n} open room": OccupancyGrid.empty(n * RES, n * RES, RES),
        }
        side = n * RES
        start, goal = Pose2D(0.1 + RES, 0.1 + RES), Pose2D(side - 0.1 - RES, side - 0.1 - RES)
        for label, grid in maps.items():
            for name in ("astar", "dijkstra", "theta_star"):
                planner = GLOBAL_PLANNERS.build({"type": name})
                ms = _best_ms(
                    lambda p=planner, g=grid, s=start, t=goal: p.plan(g, s, t), args.repeats
                )
                path = planner.plan(grid, start, goal)
                print(f"  {label:<26}{name:<12}{ms:>10.1f}{polyline_length(path):>11.2f}"
                      f"{len(path):>11d}")

    print("Costmaps: ms per update")
    grid = _random_map(1000, 0.02)
    peds = np.random.default_rng(1).uniform(5, 45, (30, 2))
    vels = np.random.default_rng(2).normal(0, 0.8, (30, 2))
    gcm = GlobalCostmap(grid)
    ms = _best_ms(lambda: gcm.update(ped_positions=peds, ped_velocities=vels), args.repeats)
    print(f"  global 1000x1000, 30 pedestrians            {ms:9.1f} ms")
    lcm = LocalCostmap(grid, 6.0, 6.0)
    angles = np.linspace(-2.356, 2.356, 720)
    ranges = np.random.default_rng(3).uniform(0.5, 4.0, 720)
    ms = _best_ms(
        lambda: lcm.update([25.0, 25.0, 0.3], scan_ranges=ranges, scan_angles=angles,
                           range_max=30.0, ped_positions=peds, ped_velocities=vels),
        args.repeats * 4,
    )
    print(f"  local 6x6 m window, 720-beam scan, 30 peds  {ms:9.2f} ms")


if __name__ == "__main__":
    main()
