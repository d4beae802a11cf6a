"""3-D world build time: a 30 x 30 m map with 50 obstacles, 20 people and a jackal.

    python benchmarks/world3d_build.py [--repeat 5]

The map: 30 x 30 m at 0.05 m/cell (600 x 600 cells) with walls around and interior walls with
doors; 50 obstacles of every library model on a grid; 20 pedestrians; one jackal. Prints the
median time of building the scene (wall boxes, obstacle models, figures), writing its MJCF and
SDF, and compiling the MJCF with MuJoCo (if installed), and the wall box counts of the
packaged worlds and of a generated 240 x 240 map. Goal (issue 19): the whole build < 1 s.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import arena.plugins  # noqa: F401
from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.maps.generators import MAP_GENERATORS
from arena.maps.grid import OccupancyGrid
from arena.maps.io import load_map
from arena.maps.obstacles import make_obstacle, obstacle_models
from arena.maps.sources import packaged_worlds, resolve_world
from arena.robots.presets import load_robot
from arena.scene.episode import AgentSpawn
from arena.scene.state import Obstacle
from arena.sim.mujoco.mjcf import compile_model, import_mujoco, to_mjcf
from arena.sim.mujoco.sdf import to_sdf
from arena.sim.mujoco.walls import merge_boxes
from arena.sim.mujoco.world import build_world


def scene_inputs() -> tuple[OccupancyGrid, list[Obstacle], AgentSpawn]:
    """The 30 x 30 m map, 50 obstacles and 20 people."""
    n = 600
    occ = np.zeros((n, n), dtype=bool)
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    for k in (150, 300, 450):  # interior walls with two 1.5 m doors each
        occ[k : k + 4, :] = True
        occ[k : k + 4, 100:130] = occ[k : k + 4, 400:430] = False
    grid = OccupancyGrid.from_occupied(occ, 0.05)
    models = sorted(obstacle_models())
    rng = np.random.default_rng(0)
    obstacles = [make_obstacle(f"o{i}", models[i % len(models)],
                               [3 + 2.6 * (i % 10), 2 + 5.5 * (i // 10) + 1.2, rng.uniform(-3, 3)])
                 for i in range(50)]
    m = 20
    agents = AgentSpawn(rng.uniform(2, 28, (m, 2)), np.full(m, 0.3), np.full(m, 1.2),
                        rng.uniform(2, 28, (m, 2, 2)), np.full(m, 2), np.zeros(m, np.int64),
                        rng.integers(0, 2, m))
    return grid, obstacles, agents


def main() -> None:
    """Time the build and print the box counts."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    grid, obstacles, agents = scene_inputs()
    jackal = load_robot("jackal")
    try:
        import_mujoco()
        have_mujoco = True
    except ConfigError:
        have_mujoco = False
    times: dict[str, list[float]] = {"scene": [], "mjcf": [], "sdf": [], "compile": []}
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        scene = build_world(grid, obstacles, robots=[("jackal", jackal, [1.5, 1.5, 0.0])],
                            agents=agents)
        t1 = time.perf_counter()
        xml = to_mjcf(scene)
        t2 = time.perf_counter()
        to_sdf(scene)
        t3 = time.perf_counter()
        if have_mujoco:
            compile_model(xml)
        t4 = time.perf_counter()
        for key, dt in zip(times, (t1 - t0, t2 - t1, t3 - t2, t4 - t3), strict=True):
            times[key].append(dt)
    med = {k: float(np.median(v)) * 1e3 for k, v in times.items()}
    geoms = sum(len(b.geoms) for b in scene.bodies)
    print(f"30 x 30 m map (600 x 600 cells), 50 obstacles, 20 people, 1 robot: "
          f"{scene.wall_boxes} wall boxes, {geoms} geoms")
    print(f"  build scene {med['scene']:.1f} ms, MJCF {med['mjcf']:.1f} ms, "
          f"SDF {med['sdf']:.1f} ms, MuJoCo compile "
          + (f"{med['compile']:.1f} ms" if have_mujoco else "(mujoco not installed)"))
    total = med["scene"] + med["mjcf"] + med["compile"]
    print(f"  build + MJCF + compile: {total:.1f} ms (goal < 1000 ms, median of {args.repeat})")
    print("wall boxes (occupied cells -> boxes):")
    for w in packaged_worlds():
        g = load_map(resolve_world(w))
        print(f"  {w:22} {g.width} x {g.height} cells: {int(g.occupied.sum()):7,} -> "
              f"{len(merge_boxes(g.occupied))}")
    for kind in ("rosnav_indoor", "barn", "rosnav_outdoor"):
        spec = {"type": kind, "width": 12, "height": 12, "resolution": 0.05}
        g = MAP_GENERATORS.build(spec, source="benchmark").build(derive_rng(0, "map")).grid
        print(f"  {kind + ' (generated)':22} {g.width} x {g.height} cells: "
              f"{int(g.occupied.sum()):7,} -> {len(merge_boxes(g.occupied))}")


if __name__ == "__main__":
    main()
