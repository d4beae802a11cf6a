"""Frame rendering: ms per frame of :class:`arena.render.FrameRenderer`, and with H.264 encoding.

Scenario (seeded): a 30 m × 30 m map at 0.05 m/cell with one table, a jackal with a 360-beam
laser scan, 30 pedestrians, a global path, a goal, a title, the legend and a status line;
``--frames`` different states, each rendered once after one warm-up frame. Prints the median
and 95th percentile per frame, then the time per frame of rendering and writing an MP4 (what a
video costs), for each ``--width`` (default 800 px, the video default, and 480 px).

Run: ``.venv/bin/python benchmarks/render_frames.py [--frames 30] [--width 800 480]``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from arena.core.geometry import rectangle
from arena.maps.grid import OccupancyGrid
from arena.render import FrameRenderer, Overlay, VideoWriter
from arena.scene.state import AgentStates, Collisions, Obstacle, RobotStates, SimState, StaticWorld
from arena.sensors.spec import LidarSpec


def main() -> None:
    """Render the scenario's frames and print the timings."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--width", type=int, nargs="+", default=[800, 480])
    args = ap.parse_args()
    grid = OccupancyGrid.empty(30.0, 30.0, 0.05)
    table = Obstacle("t", "table", np.array([8.0, 20.0, 0.3]), rectangle(1.6, 0.9))
    world = StaticWorld.build(grid, (table,))
    spec = LidarSpec(angle_min=-np.pi, angle_max=np.pi, num_beams=360, range_max=8.0)
    rng = np.random.default_rng(0)
    states = []
    for k in range(args.frames):
        robots = RobotStates(("r",), ("jackal",), np.array([[5 + 0.1 * k, 5.0, 0.2]]),
                             np.zeros((1, 3)), np.zeros((1, 3)), np.array([0.36]),
                             (rectangle(0.5, 0.43),), (rng.uniform(0.5, 8.0, 360),))
        agents = AgentStates(np.arange(30), rng.uniform(2, 28, (30, 2)), np.zeros((30, 2)),
                             rng.uniform(-3, 3, 30), np.full(30, 0.3), np.arange(30) % 3,
                             np.arange(30) % 4)
        states.append(SimState(0.1 * k, k, robots, agents, Collisions.none(1)))
    overlay = Overlay(paths=[np.array([[5.0, 5.0], [25.0, 25.0]])],
                      goals=np.array([[25.0, 25.0, 0.5]]), text="outcome: running")
    for width in args.width:
        renderer = FrameRenderer(world, lidar_specs=[spec], width_px=width, title="speed",
                                 legend=True)
        renderer.render(states[0], overlay)  # warm-up: static background, fonts
        times = []
        for s in states:
            t0 = time.perf_counter()
            renderer.render(s, overlay)
            times.append(time.perf_counter() - t0)
        ms = 1e3 * np.asarray(times)
        h, w, _ = renderer.shape
        print(f"FrameRenderer, 30 m map, 30 people, 360-beam scan, {w}×{h} px: "
              f"median {np.median(ms):.1f} ms/frame, p95 {np.percentile(ms, 95):.1f} ms "
              f"({args.frames} frames)")
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            with VideoWriter(Path(tmp) / "v.mp4", fps=10) as video:
                for s in states:
                    video.append(renderer.render(s, overlay))
            per = 1e3 * (time.perf_counter() - t0) / len(states)
            size = (Path(tmp) / "v.mp4").stat().st_size / len(states) / 1e3
        print(f"  rendered and written to H.264 MP4: {per:.1f} ms/frame, {size:.1f} kB/frame")


if __name__ == "__main__":
    main()
