"""Perception speed on one core: the lidar and RGB-D people detectors and the tracker.

    python benchmarks/perception.py [--people 20] [--frames 2000] [--no-rgbd]

Detector: 720-beam jackal scans of 20 walking people (seen as legs) on generated indoor maps,
the time of :meth:`LidarPeopleDetector.detect` per scan. Tracker: ``--people`` people walking
straight lines at 1.2 m/s through a 20 x 20 m area, detected every 0.1 s with 5 cm noise; its
time per frame (predict, associate, update, birth and death) and its MOTA / MOTP / IDF1.
RGB-D detector (needs ``arena[3d]``): 320 x 240 frames of the training camera on the MuJoCo
backend among 20 people, the time of :meth:`RgbdPeopleDetector.detect` per frame (shrinking,
the network, clustering). Goals (issue 20): lidar detector + tracker <= 1 ms per 720-beam scan
with 20 people; RGB-D detector >= 30 frames/s at 320 x 240.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from arena.config import load_config  # noqa: E402
from arena.perception.lidar_data import labelled_frames  # noqa: E402
from arena.perception.lidar_detector import LidarPeopleDetector  # noqa: E402
from arena.perception.mot import MotAccumulator  # noqa: E402
from arena.perception.tracker import Tracker  # noqa: E402


def main() -> None:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--people", type=int, default=20)
    ap.add_argument("--frames", type=int, default=2000)
    ap.add_argument("--rgbd", action=argparse.BooleanOptionalAction, default=True,
                    help="also time the RGB-D detector (needs the 3-D extra)")
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    n = args.people
    start = rng.uniform(-10, 10, (n, 2))
    heading = rng.uniform(-np.pi, np.pi, n)
    vel = 1.2 * np.stack([np.cos(heading), np.sin(heading)], axis=1)
    frames = []
    for k in range(args.frames):
        free = start + vel * (k * 0.1) + 10.0
        truth = free % 20.0 - 10.0  # wrap around: a person leaving comes back as a new one
        laps = np.floor(free / 20.0).astype(np.int64)
        ids = np.arange(n) + n * (1000 * laps[:, 0] + laps[:, 1])
        frames.append((k * 0.1, ids, truth, truth + rng.normal(0, 0.05, truth.shape)))
    tracker = Tracker()
    for t, _, _, det in frames[:50]:  # warm-up
        tracker.update(t, det)
    tracker.reset()
    acc = MotAccumulator(0.5)
    elapsed = 0.0
    for t, ids, truth, det in frames:
        t0 = time.perf_counter()
        tracks = tracker.update(t, det)
        elapsed += time.perf_counter() - t0
        acc.add_frame(ids, truth, tracks.ids, tracks.positions)
    per = elapsed / len(frames)
    s = acc.scores()
    cfg = load_config(None, ["map={type: rosnav_indoor}", "task.obstacles.static=3",
                             "task.obstacles.dynamic=20", "sim.backend.pedestrian_body=legs"])
    scans = list(labelled_frames(cfg, episodes=2, steps=200, every=5))
    det = LidarPeopleDetector()
    for f in scans[:5]:
        det.detect(f.ranges, f.angles, f.range_max)
    t0 = time.perf_counter()
    for f in scans:
        det.detect(f.ranges, f.angles, f.range_max)
    per_scan = (time.perf_counter() - t0) / len(scans)
    print(f"lidar people detector, {len(scans)} scans (720 beams, 20 people as legs)")
    print(f"  detect:  {1e6 * per_scan:8.1f} us/scan")
    print(f"tracker, {n} people, {len(frames)} frames (one core)")
    print(f"  update:  {1e6 * per:8.1f} us/frame")
    print(f"  MOTA {s.mota:.3f}  MOTP {s.motp:.3f} m  IDF1 {s.idf1:.3f}  id switches "
          f"{s.id_switches}")
    total = 1e3 * (per + per_scan)
    print(f"detector + tracker: {total:.2f} ms per scan (goal <= 1 ms): "
          f"{'meets' if total <= 1.0 else 'MISSES'}")
    if args.rgbd:
        rgbd()


def rgbd() -> None:
    """Time the RGB-D people detector on rendered frames."""
    from arena.perception.rgbd_data import camera_frames
    from arena.perception.rgbd_detector import RgbdPeopleDetector

    cfg = load_config(None, ["map={type: canteen}", "task.obstacles.static=0",
                             "task.obstacles.dynamic=20", "sim.backend.type=mujoco"])
    frames = list(camera_frames(cfg, episodes=2, steps=100, every=2))
    det = RgbdPeopleDetector()
    for frame, spec, *_ in frames[:5]:
        det.detect(frame, spec)
    t0 = time.perf_counter()
    for frame, spec, *_ in frames:
        det.detect(frame, spec)
    per = (time.perf_counter() - t0) / len(frames)
    w, h = frames[0][1].width, frames[0][1].height
    print(f"RGB-D people detector, {len(frames)} frames ({w} x {h}, 20 people)")
    print(f"  detect:  {1e3 * per:8.2f} ms/frame = {1 / per:.0f} frames/s (goal >= 30): "
          f"{'meets' if per <= 1 / 30 else 'MISSES'}")


if __name__ == "__main__":
    main()
