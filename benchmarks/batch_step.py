"""Batched simulator rate: ``N`` jackal worlds (720 beams, 30 m) with 20 pedestrians each.

    python benchmarks/batch_step.py [--steps 300] [--worlds 1 16 64] [--env-only | --sim-only]

Each world: a 20 x 20 m map at 0.05 m/cell with walls around and interior walls with gaps, a few
placed obstacles, 20 pedestrians walking waypoints under the batched social force, one jackal
driving a slow circle; ``dt = 0.1`` s (so the 10 Hz lidar scans every step). Prints world-steps/s
for numba thread counts 2 and 1, and a per-stage breakdown (crowd, kinematics, contacts, lidar,
snapshot) measured by calling the stages one by one (``BatchSim.step`` itself runs crowd,
contacts and lidar fused in one kernel, so the full step costs less than the stages' sum).

Then the same world as :class:`~arena.learn.batched.BatchedSocialNavEnv` (default observation:
lidar + goal + last action; discrete actions; random actions, autoreset included): env steps/s
summed over the ``N`` worlds.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "2")
# libgomp spins at barriers by default; on shared cores that costs ms per kernel launch.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402

from arena.maps.grid import OccupancyGrid  # noqa: E402
from arena.maps.io import save_map  # noqa: E402
from arena.robots.presets import load_robot  # noqa: E402
from arena.scene.episode import Episode  # noqa: E402
from arena.sim.batch import BatchSim  # noqa: E402
from arena.tasks.config import TaskConfig  # noqa: E402
from arena.tasks.generator import TaskGenerator  # noqa: E402


def _occupancy() -> np.ndarray:
    """The 20 x 20 m benchmark map at 0.05 m/cell (walls around, interior walls with gaps)."""
    size = 400
    occ = np.zeros((size, size), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    occ[130:134, 0:160] = True
    occ[130:134, 220:400] = True
    occ[260:400, 200:204] = True
    return occ


def episodes(n: int, peds: int = 20, obstacles: int = 5) -> list[Episode]:
    """``n`` episodes (seeds 0..n-1) in the 20 x 20 m benchmark world."""
    res = 0.05
    occ = _occupancy()
    jackal = load_robot("jackal")
    with tempfile.TemporaryDirectory() as tmp:
        save_map(OccupancyGrid.from_occupied(occ, res), Path(tmp) / "bench20.yaml")
        task = TaskConfig(
            robots={"type": "random", "min_goal_distance": 5.0, "clearance": 1.5},
            obstacles={"type": "random", "static": obstacles, "dynamic": peds},
        )
        gen = TaskGenerator(
            task, map_spec={"type": "file", "path": str(Path(tmp) / "bench20.yaml")},
            robots=[jackal], seed=0,
        )
        return [gen.episode(i) for i in range(n)]


def _rate(sim: BatchSim, eps: list[Episode], steps: int) -> tuple[float, dict[str, float]]:
    n = sim.num_worlds
    cmd = np.tile([0.4, 0.0, 0.3], (n, 1))
    dt = 0.1
    sim.reset(eps, np.random.default_rng(0))
    for _ in range(20):
        sim.step(cmd, dt)
    sim.reset(eps, np.random.default_rng(0))
    t0 = time.perf_counter()
    for _ in range(steps):
        sim.step(cmd, dt)
    full = (time.perf_counter() - t0) / steps
    # Stage by stage (same calls as step() makes).
    stages = dict.fromkeys(("crowd", "kinematics", "contacts", "lidar", "snapshot"), 0.0)
    due = np.ones(n, dtype=bool)
    for _ in range(steps):
        t = time.perf_counter()
        sim._crowd(dt)
        t1 = time.perf_counter()
        p, _, _ = sim._kinematics(cmd, dt)
        t2 = time.perf_counter()
        old = sim._poses
        sim._poses = p
        sim._contacts(sweep=True, previous=old)
        t3 = time.perf_counter()
        sim._scan(due)
        t4 = time.perf_counter()
        sim._snapshot()
        t5 = time.perf_counter()
        for k, v in zip(stages, (t1 - t, t2 - t1, t3 - t2, t4 - t3, t5 - t4), strict=True):
            stages[k] += v / steps
    return full, stages


def _env_rate(n: int, map_path: str, steps: int) -> float:
    from arena.learn.batched import BatchedSocialNavEnv

    env = BatchedSocialNavEnv(
        None,
        [
            f"map={{type: file, path: {map_path}}}",
            "robot=jackal",
            "task.robots={type: random, min_goal_distance: 5.0, clearance: 1.5}",
            "task.obstacles={type: random, static: 5, dynamic: 20}",
            "sim.dt=0.1",
        ],
        num_envs=n,
    )
    env.reset(seed=0)
    acts = np.random.default_rng(0).integers(env.single_action_space.n, size=(steps + 20, n))
    for a in acts[:20]:
        env.step(a)
    t0 = time.perf_counter()
    for a in acts[20:]:
        env.step(a)
    return n * steps / (time.perf_counter() - t0)


def main() -> None:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--worlds", type=int, nargs="+", default=[1, 16, 64])
    ap.add_argument("--sim-only", action="store_true")
    ap.add_argument("--env-only", action="store_true")
    args = ap.parse_args()
    max_threads = numba.config.NUMBA_NUM_THREADS
    if not args.env_only:
        _sim(args, max_threads)
    if not args.sim_only:
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "bench20.yaml"
            save_map(OccupancyGrid.from_occupied(_occupancy(), 0.05), path)
            print("BatchedSocialNavEnv: same world, random discrete actions, autoreset")
            for threads in sorted({min(2, max_threads), 1}, reverse=True):
                numba.set_num_threads(threads)
                for n in args.worlds:
                    rate = _env_rate(n, str(path), args.steps)
                    print(f"  threads {threads}  N {n:3d}: {rate:10,.0f} env steps/s")
    print("  target: >= 20,000 steps/s for N = 16 and 64 on 2 threads")


def _sim(args: argparse.Namespace, max_threads: int) -> None:
    eps_all = episodes(max(args.worlds))
    print("batch step benchmark: 20x20 m @ 0.05 m, 20 pedestrians, 5 obstacles, jackal 720 beams")
    for threads in sorted({min(2, max_threads), 1}, reverse=True):
        numba.set_num_threads(threads)
        for n in args.worlds:
            sim = BatchSim(n)
            full, st = _rate(sim, eps_all[:n], args.steps)
            rate = n / full
            parts = "  ".join(f"{k} {1e6 * v / n:6.1f}" for k, v in st.items())
            print(
                f"  threads {threads}  N {n:3d}: {rate:10,.0f} world-steps/s "
                f"({1e6 * full:8.1f} us/step)   per world-step us: {parts}"
            )


if __name__ == "__main__":
    main()
