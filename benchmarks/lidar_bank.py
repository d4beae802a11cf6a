"""Rays/s of :class:`arena.sensors.lidar2d.LidarBank`: every lidar of ``W`` worlds per call.

    python benchmarks/lidar_bank.py [--scans 400] [--worlds 1 64]

Each world: the packaged ``small_office`` map, 20 pedestrians (circles, r = 0.2–0.35 m) and one
jackal laser (720 beams over ±2.356 rad, 30 m) on a robot at a seeded free pose; the poses
change every call (a table of 16 pose sets). Prints rays/s (beams cast per second, all worlds
together) for ``W = 1`` and ``W = 64``, serial and on 2 numba threads (dynamic schedule, one
world per chunk), and for ``W = 1`` :meth:`Lidar2D.scan` of the same scenes as a reference.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "2")
# libgomp spins at barriers by default; on shared cores that costs ms per kernel launch.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse  # noqa: E402
import time  # noqa: E402
from types import SimpleNamespace  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402

from arena.maps.io import load_map  # noqa: E402
from arena.maps.sources import resolve_world  # noqa: E402
from arena.robots.presets import load_robot  # noqa: E402
from arena.sensors import Lidar2D  # noqa: E402
from arena.sensors.lidar2d import LidarBank  # noqa: E402

PEDS = 20
POSE_SETS = 16


def scene(num_worlds: int, seed: int = 0):
    """The grid, ``(POSE_SETS, W, 3)`` robot poses and ``(POSE_SETS, W, PEDS, 2)`` circles."""
    grid = load_map(resolve_world("small_office"))
    rng = np.random.default_rng(seed)
    lo = np.asarray(grid.origin)
    hi = lo + np.array([grid.width, grid.height]) * grid.resolution

    def free(n: int, clearance: float) -> np.ndarray:
        out = np.empty((0, 2))
        while len(out) < n:
            xy = rng.uniform(lo, hi, size=(4 * n, 2))
            out = np.concatenate([out, xy[grid.distance_at(xy) > clearance]])
        return out[:n]

    k = POSE_SETS * num_worlds
    poses = np.column_stack([free(k, 0.6), rng.uniform(-np.pi, np.pi, k)])
    peds = free(k * PEDS, 0.4)
    radii = rng.uniform(0.2, 0.35, size=(num_worlds, PEDS))
    return (grid, poses.reshape(POSE_SETS, num_worlds, 3),
            peds.reshape(POSE_SETS, num_worlds, PEDS, 2), radii)


def flat_scene(peds: np.ndarray, radii: np.ndarray) -> SimpleNamespace:
    """One pose set's circles in the engine's flat layout (robots are invisible dots here)."""
    w = len(peds)
    off = np.arange(w + 1, dtype=np.int64) * PEDS
    return SimpleNamespace(
        circ_off=off, circ_xy=np.ascontiguousarray(peds.reshape(-1, 2)),
        circ_r=radii.reshape(-1).copy(), circ_owner=np.full(w * PEDS, -1, dtype=np.int64),
        seg_off=np.zeros(w + 1, dtype=np.int64), seg_a=np.zeros((0, 2)), seg_b=np.zeros((0, 2)),
        seg_owner=np.zeros(0, dtype=np.int64),
    )


def bank_rate(num_worlds: int, scans: int, threads: int) -> float:
    """Rays/s of :meth:`LidarBank.scan` over ``num_worlds`` worlds (serial if ``threads == 1``)."""
    spec = load_robot("jackal").laser
    grid, poses, peds, radii = scene(num_worlds)
    bank = LidarBank()
    for w in range(num_worlds):
        bank.bind_world(w, grid)
    bank.set_sensors(np.arange(num_worlds), np.arange(num_worlds), [spec] * num_worlds)
    scenes = [flat_scene(peds[i], radii) for i in range(POSE_SETS)]
    due = np.ones(num_worlds, dtype=bool)
    numba.set_num_threads(threads)
    parallel = threads > 1
    for i in range(POSE_SETS):  # warm-up (compilation, caches)
        bank.scan(due, poses[i], scenes[i], parallel=parallel)
    t0 = time.perf_counter()
    for k in range(scans):
        i = k % POSE_SETS
        bank.scan(due, poses[i], scenes[i], parallel=parallel)
    dt = time.perf_counter() - t0
    return scans * num_worlds * spec.num_beams / dt


def lidar2d_rate(scans: int) -> float:
    """Rays/s of :meth:`Lidar2D.scan` on the ``W = 1`` scenes (the single-world path)."""
    spec = load_robot("jackal").laser
    grid, poses, peds, radii = scene(1)
    lidar = Lidar2D(spec)
    lidar.bind(grid)
    for i in range(POSE_SETS):
        lidar.scan(poses[i, 0], peds[i, 0], radii[0])
    t0 = time.perf_counter()
    for k in range(scans):
        i = k % POSE_SETS
        lidar.scan(poses[i, 0], peds[i, 0], radii[0])
    return scans * spec.num_beams / (time.perf_counter() - t0)


def main() -> None:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--scans", type=int, default=400, help="calls per figure")
    ap.add_argument("--worlds", type=int, nargs="+", default=[1, 64])
    args = ap.parse_args()
    print(f"numba threads available: {numba.config.NUMBA_NUM_THREADS}")
    for w in args.worlds:
        scans = max(args.scans // w, 20) if w > 1 else args.scans * 4
        for threads in (1, 2):
            if threads > numba.config.NUMBA_NUM_THREADS:
                continue
            rate = bank_rate(w, scans, threads)
            print(f"LidarBank  W = {w:3d}, {threads} thread(s): {rate / 1e6:7.2f} M rays/s")
    if 1 in args.worlds:
        rate = lidar2d_rate(args.scans * 4)
        print(f"Lidar2D    W =   1, 1 thread   : {rate / 1e6:7.2f} M rays/s")


if __name__ == "__main__":
    main()
