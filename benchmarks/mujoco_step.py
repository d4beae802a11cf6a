"""mujoco backend step rate (no camera) and world build time.

    NUMBA_NUM_THREADS=1 python benchmarks/mujoco_step.py [--steps 3000]

Step: the ``sim_step`` world (30 x 30 m at 0.05 m/cell with interior walls, 20 placed box
obstacles) with 20 pedestrians walking waypoint loops and one jackal (720-beam lidar, 30 m,
scanning every step) driving a slow circle. Prints steps/s of the full step (pedestrians,
kinematics, placing the bodies, MuJoCo contacts, the lidar's ``mj_multiRay``, snapshot) with a
breakdown. Build: the ``world3d_build`` map (30 x 30 m, 50 obstacles of every model, 20
people): the backend's reset (3-D world, MJCF, compile, first contacts and scan), median.
One core (thread pools pinned to 1). Goals (issue 19): >= 1,000 steps/s, build < 1 s.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from sim_step import walker, world  # noqa: E402  (the benchmark folder is on sys.path)
from world3d_build import scene_inputs  # noqa: E402

from arena.core.rng import derive_rng  # noqa: E402
from arena.core.types import Pose2D  # noqa: E402
from arena.maps.io import save_map  # noqa: E402
from arena.robots.presets import load_robot  # noqa: E402
from arena.scene.episode import Episode, RobotSpawn  # noqa: E402
from arena.sim.mujoco.backend import MujocoBackend  # noqa: E402
from arena.tasks.config import TaskConfig  # noqa: E402
from arena.tasks.generator import TaskGenerator  # noqa: E402


def step_episode() -> Episode:
    """The sim_step world with 20 people instead of 30."""
    jackal = load_robot("jackal")
    with tempfile.TemporaryDirectory() as tmp:
        save_map(world().grid, Path(tmp) / "bench30.yaml")
        task = TaskConfig(
            robots={"type": "random", "min_goal_distance": 5.0, "clearance": 1.5},
            obstacles={"type": "random", "static": 20, "dynamic": 20},
        )
        map_spec = {"type": "file", "path": str(Path(tmp) / "bench30.yaml")}
        ep = TaskGenerator(task, map_spec=map_spec, robots=[jackal], seed=0).episode(0)
    assert len(ep.agents) == 20 and jackal.laser.num_beams == 720
    return ep


def build_episode() -> Episode:
    """world3d_build's 30 x 30 m map with 50 obstacles and 20 people, and a jackal."""
    grid, obstacles, agents = scene_inputs()
    jackal = load_robot("jackal")
    robot = RobotSpawn("robot", jackal, Pose2D(1.5, 1.5, 0.0), Pose2D(28.0, 28.0, 0.0))
    return Episode(0, 0, "build30", grid, tuple(obstacles), (robot,), agents, 60.0)


def main() -> None:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()

    ep = step_episode()
    backend = MujocoBackend()
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

    # the parts: the lidar's ray cast, the contact test, the people's poses
    w = backend.world3d
    bank = backend.engine.sensor_stage.banks["lidar2d"]
    due = np.ones(1, dtype=bool)
    poses = backend.engine.poses
    reps = 500
    t0 = time.perf_counter()
    for _ in range(reps):
        bank.scan(due, poses, None)
    scan_s = (time.perf_counter() - t0) / reps
    t0 = time.perf_counter()
    for _ in range(reps):
        w.collide()
    collide_s = (time.perf_counter() - t0) / reps
    agents = backend.state.agents
    t0 = time.perf_counter()
    for _ in range(reps):
        w.place_people(agents)
    people_s = (time.perf_counter() - t0) / reps

    build = build_episode()
    times = []
    for _ in range(args.repeat):
        b = MujocoBackend()
        t0 = time.perf_counter()
        b.reset(build, None, derive_rng(0, "build"))
        times.append(time.perf_counter() - t0)
    build_s = statistics.median(times)
    model = b.world3d.model

    print("mujoco backend step benchmark (1 core, no camera)")
    print(f"  world: 30x30 m @ 0.05 m, 20 obstacles, 20 pedestrians, jackal 720 beams / 30 m; "
          f"{w.model.ngeom} geoms")
    print(f"  full step:        {steps_per_s:10,.0f} steps/s   ({1e6 / steps_per_s:7.1f} us/step)")
    print(f"  robot in contact: {100 * contacts / args.steps:10.1f} % of steps")
    print(f"  lidar scan:       {1e6 * scan_s:10.1f} us/scan    "
          f"{720 / scan_s:14,.0f} rays/s (mj_multiRay)")
    print(f"  contacts:         {1e6 * collide_s:10.1f} us        (mj_kinematics + mj_collision)")
    print(f"  people poses:     {1e6 * people_s:10.1f} us")
    print(f"  world build:      {build_s:10.3f} s         (reset: 30x30 m, 50 obstacles, "
          f"20 people, {model.ngeom} geoms, median of {args.repeat})")
    for name, value, target, better in (("steps/s", steps_per_s, 1000, "ge"),
                                        ("build s", build_s, 1.0, "lt")):
        ok = value >= target if better == "ge" else value < target
        sign = ">=" if better == "ge" else "<"
        print(f"  target {name} {sign} {target:,}: {'meets' if ok else 'MISSES'}")


if __name__ == "__main__":
    main()
