"""One canteen episode driven three times: aggressive, polite and sideways intermediate planners.

Runs the same seeded episode (same canteen, start, goal and people) once per intermediate
planner, then writes the three videos side by side into one MP4 plus a still of the moment
the robot is closest to a person, so the behaviours near people can be compared:

    python tools/make_intermediate_video.py [-o docs/videos] [--index 0] [--seed 3]
"""

from __future__ import annotations

import argparse
import csv
import tempfile
from pathlib import Path

import imageio.v3 as iio
import numpy as np

import arena.plugins  # noqa: F401
from arena.config.loader import load_config
from arena.experiment import run_episode
from arena.render import save_png
from arena.render.video import VideoWriter
from arena.sim.backend import BACKENDS
from arena.tasks.generator import TaskGenerator

PLANNERS = ("aggressive", "polite", "sideways")


def overrides(planner: str, seed: int) -> list[str]:
    """The experiment: a jackal crossing a generated canteen with 14 people."""
    return [
        "robot=jackal",
        f"seed={seed}",
        "map.type=canteen",
        "task.obstacles.static=0",
        "task.obstacles.dynamic=14",
        "task.robots.min_goal_distance=12",
        "task.timeout=60",
        "task.goal_tolerance_angle=null",
        f"navigation.intermediate_planner.type={planner}",
        "output.width_px=560",
        "output.frame_every=2",
        f"name={planner}",
    ]


def closest_approach(folder: Path) -> tuple[int, float]:
    """Step at which the robot came closest to a person, and that distance (m, centres)."""
    robot = {
        int(r["step"]): (float(r["x"]), float(r["y"])) for r in _rows(folder / "trajectory.csv")
    }
    best = (0, np.inf)
    for r in _rows(folder / "agents.csv"):
        step = int(r["step"])
        rx, ry = robot[step]
        d = float(np.hypot(float(r["x"]) - rx, float(r["y"]) - ry))
        if d < best[1]:
            best = (step, d)
    return best


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


def main() -> None:
    """Run the three planners and compose the video."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("-o", "--out", type=Path, default=Path("docs/videos"))
    ap.add_argument("--index", type=int, default=0)
    ap.add_argument("--seed", type=int, default=3)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    videos, summary = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for planner in PLANNERS:
            cfg = load_config(None, overrides(planner, args.seed))
            gen = TaskGenerator.from_config(cfg)
            ep = gen.episode(args.index)
            folder = Path(tmp) / planner
            res = run_episode(
                cfg, ep, BACKENDS.build(cfg.sim.backend), folder, video=True,
                runtime=gen.runtime(ep),
            )
            _, dist = closest_approach(folder)
            summary.append((planner, res.outcome, res.time, res.collisions, dist))
            videos.append(iio.imread(res.files["video"]))
        n = max(len(v) for v in videos)
        frames = [np.concatenate([v[min(i, len(v) - 1)] for v in videos], axis=1)
                  for i in range(n)]
        path = args.out / "intermediate_planners_canteen.mp4"
        with VideoWriter(path, fps=5.0) as w:  # frame_every=2 at dt = 0.1 s: real time
            for f in frames:
                w.append(f)
        still = args.out.parent / "images" / "intermediate_planners_canteen.png"
        still.parent.mkdir(parents=True, exist_ok=True)
        save_png(frames[min(n - 1, max(80, n // 3))], still)
    for planner, outcome, t, coll, dist in summary:
        print(f"{planner:10s} {outcome:8s} {t:5.1f} s  {coll} collision(s)  "
              f"closest person {dist:.2f} m (centres)")
    print(f"video: {path}\nstill: {still}")


if __name__ == "__main__":
    main()
