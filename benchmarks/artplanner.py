"""Benchmark of ArtPlanner (``artplanner``): planning time on 20 x 20 m maps, and a figure.

Cases (seeded): the terrain course of :func:`arena.maps.terrain.terrain_course` (20 x 20 m,
0.1 m cells, seed 0) inflated by a Go1's 0.347 m, from the ground to the plateau, with its
height map (the learned motion cost on) and without (a flat PRM); a flat 20 x 20 m map with
20 % random blocked cells at 0.05 m (inflated by nothing, as benchmarks/planners_global.py),
corner to corner. A* on the same maps for scale. Times are best-of-N wall times after a warm-up
call (numba compilation), one core; the first call of a plan on a new height map also computes
its standable mask (reported apart).

Run: ``.venv/bin/python benchmarks/artplanner.py [--repeats N] [--figure PATH]``; the figure
shows the course's heights, the roadmap edges the network rejected, and both planners' paths.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from arena.core.geometry import polyline_length
from arena.core.types import Pose2D
from arena.learn.planners.artplanner import ArtPlanner
from arena.maps.grid import OccupancyGrid
from arena.maps.terrain import terrain_course
from arena.nav.global_planners import GLOBAL_PLANNERS

GO1_RADIUS = 0.347


def _best_ms(fn: Callable[[], object], repeats: int) -> float:
    fn()
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best * 1e3


def _figure(path: str, grid: OccupancyGrid, planner: ArtPlanner, art: np.ndarray,
            astar: np.ndarray) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    assert planner.terrain is not None and planner.last_roadmap is not None
    hm = planner.terrain
    fig, ax = plt.subplots(figsize=(7, 6.2))
    x0, y0, x1, y1 = hm.bounds
    im = ax.imshow(hm.heights, origin="lower", extent=(x0, x1, y0, y1), cmap="terrain")
    fig.colorbar(im, ax=ax, label="ground height (m)")
    ax.contour(grid.occupied, levels=[0.5], colors="k", linewidths=0.6,
               extent=(x0, x1, y0, y1), origin="lower")
    rm = planner.last_roadmap
    ax.plot(*rm.nodes.T, ".", ms=1.0, color="0.3", label=f"roadmap nodes ({len(rm.nodes)})")
    ax.plot(*astar.T, "-", color="tab:red", lw=1.6, label="A* (ignores height)")
    ax.plot(*art.T, "-o", color="tab:blue", ms=3, lw=2.0, label="artplanner")
    ax.plot(*art[0], "s", color="k", ms=7)
    ax.plot(*art[-1], "*", color="k", ms=12)
    ax.set_title(f"artplanner on the terrain course (seed 0): {rm.rejected} of "
                 f"{len(rm.edges) + rm.rejected} edges rejected", fontsize=9)
    ax.legend(loc="upper right", fontsize=7)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"figure: {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per case (best kept)")
    parser.add_argument("--figure", default=None, help="write the terrain figure (PNG) here")
    args = parser.parse_args()

    world = terrain_course(None, np.random.default_rng(0))
    course = world.grid.inflate(GO1_RADIUS)
    px0, py0, px1, py1 = world.features["plateau"]
    start, goal = Pose2D(1.5, 1.5), Pose2D((px0 + px1) / 2, (py0 + py1) / 2)
    rng = np.random.default_rng(0)
    occ = rng.random((400, 400)) < 0.2
    occ[:5, :5] = occ[-5:, -5:] = False
    random_map = OccupancyGrid.from_occupied(occ, 0.05)
    corner = (Pose2D(0.15, 0.15), Pose2D(19.85, 19.85))

    print(f"Planning on 20 x 20 m maps: ms per plan (best of {args.repeats}, after warm-up)")
    print(f"  {'map':<34}{'planner':<24}{'ms/plan':>9}{'length m':>10}{'nodes':>7}")
    terrain_planner = ArtPlanner(terrain=world.heights)
    t0 = time.perf_counter()
    terrain_planner.plan(course, start, goal)
    first = (time.perf_counter() - t0) * 1e3
    cases = [
        ("terrain course, 0.1 m, heights", "artplanner", terrain_planner, course, start, goal),
        ("terrain course, 0.1 m, flat", "artplanner (flat PRM)", ArtPlanner(), course, start,
         goal),
        ("terrain course, 0.1 m", "astar", GLOBAL_PLANNERS.build({"type": "astar"}), course,
         start, goal),
        ("random 20 %, 0.05 m", "artplanner (flat PRM)", ArtPlanner(), random_map, *corner),
        ("random 20 %, 0.05 m", "astar", GLOBAL_PLANNERS.build({"type": "astar"}), random_map,
         *corner),
    ]
    paths = {}
    for label, name, planner, grid, s, g in cases:
        def once(p: Any = planner, m: OccupancyGrid = grid, a: Pose2D = s,
                 b: Pose2D = g) -> object:
            return p.plan(m, a, b)

        ms = _best_ms(once, args.repeats)
        path = planner.plan(grid, s, g)
        paths[(label, name)] = path
        rm = getattr(planner, "last_roadmap", None)
        nodes = str(len(rm.nodes)) if rm is not None else "-"
        print(f"  {label:<34}{name:<24}{ms:>9.1f}{polyline_length(path):>10.2f}{nodes:>7}")
    print(f"  first plan on the course (numba compilation or cache load, standable mask): "
          f"{first:.0f} ms")
    if args.figure:
        terrain_planner.plan(course, start, goal)
        _figure(args.figure, course, terrain_planner,
                paths[("terrain course, 0.1 m, heights", "artplanner")],
                paths[("terrain course, 0.1 m", "astar")])


if __name__ == "__main__":
    main()
