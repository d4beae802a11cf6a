"""native2d (the engine, one world) step rate: a jackal (720 beams) among 30 people, 20 obstacles.

    python benchmarks/sim_step.py [--steps 5000]

The world: a 30 x 30 m map at 0.05 m/cell with interior walls, 20 placed box obstacles, 30
pedestrians walking waypoint loops (``waypoint_walker``), one jackal driving a slow circle. One
core (thread pools pinned to 1). Prints steps/s for the full step (pedestrians, kinematics,
collisions, lidar, snapshot) and lidar rays/s, with a per-stage breakdown.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from arena.core.rng import derive_rng  # noqa: E402
from arena.crowd.models.walker import WaypointWalker  # noqa: E402
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig  # noqa: E402
from arena.maps.grid import OccupancyGrid  # noqa: E402
from arena.maps.io import save_map  # noqa: E402
from arena.maps.sources import MapResult  # noqa: E402
from arena.robots.presets import load_robot  # noqa: E402
from arena.sensors.lidar2d import Lidar2D  # noqa: E402
from arena.sim.native2d import Native2DBackend  # noqa: E402
from arena.tasks.config import TaskConfig  # noqa: E402
from arena.tasks.generator import TaskGenerator  # noqa: E402


def world() -> MapResult:
    """30 x 30 m with walls around and a few interior walls with gaps."""
    res = 0.05
    n = round(30 / res)
    occ = np.zeros((n, n), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    occ[200:204, 0:250] = True
    occ[200:204, 320:600] = True
    occ[400:600, 300:304] = True
    occ[0:120, 420:424] = True
    return MapResult("bench30", OccupancyGrid.from_occupied(occ, res))


def walker() -> CrowdSimulator:
    """People walking their waypoints (the crowd models have their own benchmark)."""
    return CrowdSimulator(WaypointWalker(), PedestrianConfig(social_states=False))


def main() -> None:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=5000)
    args = ap.parse_args()

    jackal = load_robot("jackal")
    with tempfile.TemporaryDirectory() as tmp:
        save_map(world().grid, Path(tmp) / "bench30.yaml")
        task = TaskConfig(
            # The robot drives a circle of radius 1.33 m (0.4 m/s, 0.3 rad/s): start it with
            # 1.5 m of free space around its body so the benchmark measures free driving.
            robots={"type": "random", "min_goal_distance": 5.0, "clearance": 1.5},
            obstacles={"type": "random", "static": 20, "dynamic": 30},
        )
        map_spec = {"type": "file", "path": str(Path(tmp) / "bench30.yaml")}
        ep = TaskGenerator(task, map_spec=map_spec, robots=[jackal], seed=0).episode(0)
    assert len(ep.obstacles) == 20 and len(ep.agents) == 30
    assert jackal.laser.num_beams == 720 and jackal.laser.range_max == 30.0

    backend = Native2DBackend()
    cmd = np.array([[0.4, 0.0, 0.3]])
    dt = 0.1
    backend.reset(ep, walker(), derive_rng(0, "sim"))
    for _ in range(200):  # warm-up (JIT, caches)
        backend.step(cmd, dt)

    backend.reset(ep, walker(), derive_rng(0, "sim"))
    contacts = 0
    t0 = time.perf_counter()
    for _ in range(args.steps):
        contacts += bool(backend.step(cmd, dt).collisions.any[0])
    elapsed = time.perf_counter() - t0
    steps_per_s = args.steps / elapsed

    # Lidar alone, same world and pose stream.
    st = backend.state
    lidar = Lidar2D(jackal.laser)
    w = backend.world
    lidar.bind(w.grid, w.segments_a, w.segments_b)
    poses = np.array([st.robots.poses[0]] * 200)
    poses[:, 2] += np.linspace(0, 2 * np.pi, 200)
    t0 = time.perf_counter()
    reps = 10
    for _ in range(reps):
        for p in poses:
            lidar.scan(p, st.agents.positions, st.agents.radii)
    lidar_s = (time.perf_counter() - t0) / (reps * len(poses))
    rays_per_s = jackal.laser.num_beams / lidar_s

    # Pedestrians alone.
    crowd = walker()
    crowd.reset(ep.agents, backend.world, derive_rng(0, "w"))
    t0 = time.perf_counter()
    for _ in range(2000):
        crowd.step(st.robots, dt)
    crowd_s = (time.perf_counter() - t0) / 2000

    print("native2d step benchmark (1 core)")
    print("  world: 30x30 m @ 0.05 m, 20 obstacles, 30 pedestrians, jackal 720 beams / 30 m")
    print(f"  full step:        {steps_per_s:10,.0f} steps/s   ({1e6 / steps_per_s:7.1f} us/step)")
    print(f"  robot in contact: {100 * contacts / args.steps:10.1f} % of steps")
    print(f"  lidar scan:       {1e6 * lidar_s:10.1f} us/scan    {rays_per_s:14,.0f} rays/s")
    print(f"  pedestrians step: {1e6 * crowd_s:10.1f} us/step")
    target = 5000
    verdict = "meets" if steps_per_s >= target else "MISSES"
    print(f"  target >= {target:,} steps/s: {verdict}")


if __name__ == "__main__":
    main()
