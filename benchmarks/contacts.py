"""Contact tests: µs per robot for one world, robot rows/s for 64 worlds, serial and threaded.

    python benchmarks/contacts.py [--reps 20000] [--threads 2] [--worlds 64]

The world: a 30 x 30 m map at 0.05 m/cell with border and interior walls, 20 placed box
obstacles and 30 pedestrians (r = 0.3 m), a jackal footprint (rectangle) moving 0.04 m per step
(0.4 m/s at 10 Hz: the wall test sweeps the move). Prints:

- W = 1, one robot: ``ContactBank.test`` (all four tests, sweep on) and the one-robot wrappers
  (``hits_grid`` + ``first_obstacle_hit`` + ``first_agent_hit``), µs per robot;
- W = 64 worlds x 1 robot (``--worlds``; one shared grid, per-world obstacles and pedestrians):
  robot rows/s through ``ContactBank.test``, serial and over ``--threads`` numba threads.

Threads wait passively (``OMP_WAIT_POLICY=PASSIVE``, as the engine's benchmarks): spinning
threads on a busy 2-core host make the threaded call 50 times slower.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse
import time

import numba
import numpy as np

from arena.core.geometry import rectangle
from arena.maps.grid import OccupancyGrid
from arena.robots.presets import load_robot
from arena.scene.state import Obstacle, StaticWorld
from arena.sim.contacts import (
    ContactBank,
    Footprint,
    ObstacleIndex,
    first_agent_hit,
    first_obstacle_hit,
    hits_grid,
)

RES = 0.05


def grid() -> OccupancyGrid:
    """30 x 30 m with walls around and a few interior walls with gaps."""
    n = round(30 / RES)
    occ = np.zeros((n, n), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    occ[200:204, 0:250] = True
    occ[200:204, 320:600] = True
    occ[400:600, 300:304] = True
    occ[0:120, 420:424] = True
    return OccupancyGrid.from_occupied(occ, RES)


def world(g: OccupancyGrid, rng: np.random.Generator) -> tuple[StaticWorld, np.ndarray]:
    """20 random boxes on ``g`` and 30 pedestrian positions ``(30, 2)`` m."""
    obstacles = tuple(
        Obstacle(
            f"box{k}",
            "box",
            np.array([*rng.uniform(2, 28, 2), rng.uniform(-np.pi, np.pi)]),
            rectangle(*rng.uniform(0.3, 1.2, 2)),
        )
        for k in range(20)
    )
    return StaticWorld.build(g, obstacles), rng.uniform(2, 28, (30, 2))


def moves(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` poses ``(n, 3)`` and the poses 0.04 m behind them."""
    poses = np.c_[rng.uniform(1.5, 28.5, (n, 2)), rng.uniform(-np.pi, np.pi, n)]
    back = 0.04 * np.c_[np.cos(poses[:, 2]), np.sin(poses[:, 2]), np.zeros(n)]
    return poses, poses - back


def main() -> None:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--reps", type=int, default=20000, help="one-robot calls timed")
    ap.add_argument("--threads", type=int, default=2, help="numba threads, parallel run")
    ap.add_argument("--worlds", type=int, nargs="+", default=[64], help="W, one robot each")
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    jackal = load_robot("jackal")
    fp = Footprint.make(jackal.footprint_polygon(), jackal.circumscribed_radius)
    g = grid()
    g.distance  # noqa: B018  (the distance map is built once, outside the timings)

    # -- W = 1 -----------------------------------------------------------------------------
    w0, agents = world(g, rng)
    radii = np.full(len(agents), 0.3)
    bank = ContactBank()
    bank.bind_world(0, w0)
    bank.set_robots(np.zeros(1, np.int64), [fp])
    poses, previous = moves(rng, args.reps)
    off = np.array([0, len(agents)])
    for k in range(200):  # warm-up (JIT)
        bank.test(poses[k : k + 1], previous[k : k + 1], off, agents, radii)
    contacts = 0
    t0 = time.perf_counter()
    for k in range(args.reps):
        flags = bank.test(poses[k : k + 1], previous[k : k + 1], off, agents, radii)
        contacts += bool(flags[0][0] or flags[1][0] >= 0 or flags[2][0] >= 0)
    bank_us = 1e6 * (time.perf_counter() - t0) / args.reps

    index = ObstacleIndex.build(w0)
    for p in poses[:200]:  # warm-up (JIT: the grid's read-only arrays are their own types)
        hits_grid(g, fp, p)
        first_obstacle_hit(index, fp, p)
        first_agent_hit(fp, p, agents, radii)
    t0 = time.perf_counter()
    for p in poses:
        hits_grid(g, fp, p)
        first_obstacle_hit(index, fp, p)
        first_agent_hit(fp, p, agents, radii)
    wrappers_us = 1e6 * (time.perf_counter() - t0) / args.reps

    # -- W worlds x 1 robot ---------------------------------------------------------------------
    threads = numba.get_num_threads()
    rates: dict[tuple[int, str], float] = {}
    for n_worlds in args.worlds:
        many = ContactBank()
        ped = []
        for w in range(n_worlds):
            wd, a = world(g, rng)
            many.bind_world(w, wd)
            ped.append(a)
        many.set_robots(np.arange(n_worlds, dtype=np.int64), [fp] * n_worlds)
        ag_pos = np.concatenate(ped)
        ag_r = np.full(len(ag_pos), 0.3)
        ag_off = np.arange(0, len(ag_pos) + 1, 30, dtype=np.int64)
        steps = max(args.reps // n_worlds, 50)
        batches = [moves(rng, n_worlds) for _ in range(steps)]
        nthreads = min(args.threads, threads)
        for label, parallel, k in (("serial", False, 1), (f"{nthreads} threads", True, nthreads)):
            numba.set_num_threads(k)
            for p, q in batches[:20]:  # warm-up
                many.test(p, q, ag_off, ag_pos, ag_r, parallel=parallel)
            t0 = time.perf_counter()
            for p, q in batches:
                many.test(p, q, ag_off, ag_pos, ag_r, parallel=parallel)
            rates[n_worlds, label] = steps * n_worlds / (time.perf_counter() - t0)
        numba.set_num_threads(threads)

    print("contact tests benchmark")
    print("  world: 30x30 m @ 0.05 m, 20 obstacles, 30 pedestrians, jackal footprint, sweep on")
    share = 100 * contacts / args.reps
    print(f"  W = 1, ContactBank.test:     {bank_us:8.2f} us/robot   ({share:.1f} % in contact)")
    print(f"  W = 1, one-robot wrappers:   {wrappers_us:8.2f} us/robot   (grid+obstacle+agent)")
    for (n_worlds, label), rate in rates.items():
        print(f"  W = {n_worlds:4d} x 1 robot, {label:10s} {rate:12,.0f} rows/s")


if __name__ == "__main__":
    main()
