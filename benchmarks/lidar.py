"""Benchmark of :class:`arena.sensors.Lidar2D` on a deterministic jackal-like scenario.

Scenario (seeded): a 30 m × 30 m map at 0.05 m/cell with a border wall and interior walls,
30 pedestrians (circles, r = 0.3 m) and 20 rotated box obstacles (80 segments). The sensor is a
jackal laser: 720 beams over ±2.356 rad, 30 m range. Timings are taken after warm-up on one core
(the kernels are single-threaded) over many different poses.

Run: ``.venv/bin/python benchmarks/lidar.py [--scans N]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from arena.core.geometry import rectangle, transform_points
from arena.maps.grid import OccupancyGrid
from arena.sensors import Lidar2D, LidarSpec

SEED = 20240607
RES = 0.05
SIZE_M = 30.0


def build_scenario(seed: int = SEED) -> dict:
    """Grid, obstacle segments, circles and valid robot poses, all derived from ``seed``."""
    rng = np.random.default_rng(seed)
    n = round(SIZE_M / RES)
    occ = np.zeros((n, n), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    # Interior walls: 12 axis-aligned walls 0.1–0.2 m thick and 3–10 m long, plus two rooms.
    for _ in range(12):
        length = int(rng.uniform(3.0, 10.0) / RES)
        thick = int(rng.integers(2, 5))
        r0, c0 = (int(v) for v in rng.integers(20, n - 20, size=2))
        if rng.random() < 0.5:
            occ[r0 : r0 + thick, c0 : min(c0 + length, n - 2)] = True
        else:
            occ[r0 : min(r0 + length, n - 2), c0 : c0 + thick] = True
    for r0, c0 in ((60, 60), (420, 380)):
        occ[r0 : r0 + 120, c0 : c0 + 3] = True
        occ[r0 : r0 + 3, c0 : c0 + 120] = True
        occ[r0 + 117 : r0 + 120, c0 : c0 + 80] = True
    grid = OccupancyGrid.from_occupied(occ, RES)

    def free(xy: np.ndarray, clearance: float) -> bool:
        return bool(grid.distance_at(xy[None])[0] > clearance + RES)

    boxes, seg_a, seg_b = [], [], []
    while len(boxes) < 20:
        pose = np.array([*rng.uniform(1.5, SIZE_M - 1.5, size=2), rng.uniform(-np.pi, np.pi)])
        if not free(pose[:2], 0.8):
            continue
        poly = transform_points(rectangle(rng.uniform(0.4, 1.0), rng.uniform(0.4, 1.0)), pose)
        boxes.append(pose)
        seg_a.append(poly)
        seg_b.append(np.roll(poly, -1, axis=0))
    box_xy = np.array([b[:2] for b in boxes])

    def clear_of_boxes(xy: np.ndarray, clearance: float) -> bool:
        return bool(np.all(np.linalg.norm(box_xy - xy, axis=1) > 0.75 + clearance))

    circles: list[np.ndarray] = []
    while len(circles) < 30:
        xy = rng.uniform(1.0, SIZE_M - 1.0, size=2)
        if free(xy, 0.4) and clear_of_boxes(xy, 0.35):
            circles.append(xy)
    circles_xy = np.array(circles)
    poses: list[np.ndarray] = []
    while len(poses) < 256:
        xy = rng.uniform(1.0, SIZE_M - 1.0, size=2)
        if (
            free(xy, 0.4)
            and clear_of_boxes(xy, 0.4)
            and np.all(np.linalg.norm(circles_xy - xy, axis=1) > 0.8)
        ):
            poses.append(np.array([*xy, rng.uniform(-np.pi, np.pi)]))
    return {
        "grid": grid,
        "segments_a": np.concatenate(seg_a),
        "segments_b": np.concatenate(seg_b),
        "circles_xy": circles_xy,
        "circles_r": np.full(30, 0.3),
        "poses": np.array(poses),
    }


def jackal_spec(noise_std: float = 0.0) -> LidarSpec:
    """The jackal's laser as in Arena's model_params.yaml."""
    return LidarSpec(
        angle_min=-2.356, angle_max=2.356, num_beams=720, range_max=30.0, noise_std=noise_std
    )


def _time_per_call(fn, n_calls: int) -> float:
    """Best-of-3 mean seconds per call of ``fn(i)``."""
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for i in range(n_calls):
            fn(i)
        best = min(best, (time.perf_counter() - t0) / n_calls)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scans", type=int, default=2000, help="scans per timing round")
    args = parser.parse_args()

    sc = build_scenario()
    spec = jackal_spec()
    t0 = time.perf_counter()
    lidar = Lidar2D(spec)
    t_init = time.perf_counter() - t0
    lidar.bind(sc["grid"], sc["segments_a"], sc["segments_b"])
    poses, cxy, cr = sc["poses"], sc["circles_xy"], sc["circles_r"]
    n_pose = len(poses)
    for i in range(50):  # warm-up (caches, branch predictors)
        lidar.scan(poses[i % n_pose], cxy, cr)

    beams = spec.num_beams
    t_scan = _time_per_call(lambda i: lidar.scan(poses[i % n_pose], cxy, cr), args.scans)
    t_static = _time_per_call(lambda i: lidar.scan(poses[i % n_pose]), args.scans)
    rng = np.random.default_rng(0)
    noisy = Lidar2D(jackal_spec(0.01))
    noisy.bind(sc["grid"], sc["segments_a"], sc["segments_b"])
    t_noise = _time_per_call(
        lambda i: noisy.scan(poses[i % n_pose], cxy, cr, rng=rng), args.scans
    )
    n_many = 4
    t_many = _time_per_call(
        lambda i: lidar.scan_many(poses[(4 * i) % (n_pose - 4) :][:n_many], cxy, cr),
        args.scans // n_many,
    )
    mean_range = float(np.mean([lidar.scan(p, cxy, cr).mean() for p in poses]))

    print("Lidar2D benchmark (jackal: 720 beams, ±2.356 rad, 30 m; 30x30 m map at 0.05 m/cell,")
    print("  interior walls, 30 circles r=0.3 m, 20 boxes = 80 segments; one core)")
    print(f"  construction incl. JIT warm-up / cache load : {t_init * 1e3:9.1f} ms")
    print(f"  mean range over the test poses             : {mean_range:9.2f} m")
    print(f"  scan, full scenario                        : {t_scan * 1e6:9.1f} µs/scan"
          f"   {beams / t_scan / 1e6:6.2f} M rays/s")
    print(f"  scan, walls + boxes only (no circles)      : {t_static * 1e6:9.1f} µs/scan"
          f"   {beams / t_static / 1e6:6.2f} M rays/s")
    print(f"  scan, full scenario + noise (σ=0.01 m)     : {t_noise * 1e6:9.1f} µs/scan"
          f"   {beams / t_noise / 1e6:6.2f} M rays/s")
    print(f"  scan_many, {n_many} robots per call              : {t_many * 1e6:9.1f} µs/call"
          f"  = {t_many / n_many * 1e6:6.1f} µs/robot   "
          f"{n_many * beams / t_many / 1e6:6.2f} M rays/s")


if __name__ == "__main__":
    main()
