"""The navigation stack with ArtPlanner as its global planner, behind DWA (2-D simulator).

1. **barn**: the held-out barn suite (``arena bench barn``'s episodes, jackal, stage seed 911),
   DWA behind ``artplanner`` (flat: a PRM on the occupancy grid) and behind ``astar``. A contest
   file names only local planners, so the global planner comes from the base config, as
   ``arena run navigation.global_planner=artplanner`` would set it.
2. **terrain**: the terrain course (seed 0, saved as a world folder with its ``heights.npz``),
   no obstacles or people, a Go1 from the ground to the plateau, DWA behind ``artplanner``
   with the height map and behind ``astar``. The 2-D simulator ignores height (the robot
   drives through the cliff as through air); what tells the planners apart is whether the
   driven trajectory is walkable for the quadruped under the stepping model that labelled
   ArtPlanner's training data (each 0.5 m of trajectory rated as an edge).

Run: ``.venv/bin/python benchmarks/artplanner_nav.py [--episodes N] [--workers W]``.
Prints success rate, collisions per episode, mean time to goal (successes) and, for the
terrain runs, the share of trajectories walkable throughout.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from arena.config.loader import load_config
from arena.eval.runner import Job, plan_jobs, run_job
from arena.learn.artplanner.model import ARTPLANNER_WEIGHTS, MotionCostModel
from arena.learn.artplanner.stepping import stepping_labels, track_points
from arena.maps.terrain import HEIGHTS_FILE, HeightMap, save_terrain_world, terrain_course
from arena.tasks.suite import ContestFile, Suite, load_suite

GLOBAL = ("artplanner", "astar")


def _run(job: Job) -> tuple[dict[str, Any], np.ndarray | None]:
    row, record = run_job(job)
    keep = {k: row[k] for k in ("outcome", "collisions", "time_to_goal", "error")}
    return keep, None if record is None else np.asarray(record.pose[:, :2])


def _walkable(xy: np.ndarray, hm: HeightMap, model: MotionCostModel) -> bool:
    """Whether every 0.5 m of the trajectory is feasible under the stepping model."""
    steps = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
    if steps[-1] < 0.5:
        return True
    marks = np.interp(np.arange(0.0, steps[-1], 0.5), steps, np.arange(len(xy)))
    pts = np.stack([np.interp(marks, np.arange(len(xy)), xy[:, k]) for k in (0, 1)], axis=1)
    s = model.stepping
    ok, _ = stepping_labels(hm.at(track_points(pts[:-1], pts[1:], s)),
                            np.hypot(*np.diff(pts, axis=0).T), s)
    return bool(ok.all())


def _table(title: str, results: dict[str, list[tuple[dict[str, Any], np.ndarray | None]]],
           hm: HeightMap | None = None) -> None:
    model = MotionCostModel.load(ARTPLANNER_WEIGHTS)
    print(title)
    head = f"  {'global + local':<20}{'episodes':>9}{'success':>9}{'coll/ep':>9}{'time s':>8}"
    print(head + (f"{'walkable':>10}" if hm is not None else ""))
    for name, rows in results.items():
        ok = [r for r, _ in rows if r["outcome"] == "success"]
        errors = [r["error"] for r, _ in rows if r["error"]]
        t = np.mean([r["time_to_goal"] for r in ok]) if ok else math.nan
        line = (f"  {name:<20}{len(rows):>9}{len(ok) / len(rows):>9.0%}"
                f"{np.mean([r['collisions'] for r, _ in rows]):>9.2f}{t:>8.1f}")
        if hm is not None:
            walk = [_walkable(xy, hm, model) for _, xy in rows if xy is not None]
            line += f"{np.mean(walk):>10.0%}"
        print(line + (f"  errors: {errors[:2]}" if errors else ""))


def _jobs(suite: Suite, global_planner: dict[str, Any]) -> list[Job]:
    contest = ContestFile.model_validate(
        {"contestants": [{"name": f"{global_planner['type']}_dwa", "local_planner": "dwa"}]})
    block = json.dumps(global_planner)
    base = load_config(None, [f"navigation.global_planner={block}"])
    return plan_jobs(suite, contest, base)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=50,
                        help="barn episodes (of 50; 0: terrain only)")
    parser.add_argument("--terrain-episodes", type=int, default=10)
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args()

    with ProcessPoolExecutor(args.workers) as pool:
        if args.episodes > 0:
            barn = load_suite("barn", scale_episodes=args.episodes / 50)
            results = {f"{g} + dwa": list(pool.map(_run, _jobs(barn, {"type": g})))
                       for g in GLOBAL}
            _table(f"barn suite (jackal, {args.episodes} episodes, stage seed 911)", results)

        with tempfile.TemporaryDirectory() as tmp:
            world = terrain_course(None, np.random.default_rng(0))
            folder = Path(tmp) / "terrain_course"
            save_terrain_world(world, folder)
            px0, py0, px1, py1 = world.features["plateau"]
            scenario = {"robots": [{"start": [1.5, 1.5, 0.0],
                                    "goal": [(px0 + px1) / 2, (py0 + py1) / 2, 0.0]}],
                        "obstacles": {"static": [], "interactive": [], "dynamic": []}}
            (folder / "scenario.json").write_text(json.dumps(scenario))
            none = {"min": 0, "max": 0}  # no obstacles or people: the terrain alone
            stage = {"name": "terrain", "episodes": args.terrain_episodes, "seed": 5,
                     "robot": "go1", "map": str(folder), "timeout": 90,
                     "config": {"RANDOM": {"static": none, "interactive": none,
                                           "dynamic": none}},
                     "task": {"robots": {"type": "scenario",
                                         "file": str(folder / "scenario.json")}}}
            (folder / "suite.yaml").write_text(json.dumps({"stages": [stage]}))
            suite = load_suite(folder / "suite.yaml")
            heights = str(folder / "map" / HEIGHTS_FILE)
            blocks = {"artplanner": {"type": "artplanner", "height_map": heights},
                      "astar": {"type": "astar"}}
            results = {f"{g} + dwa": list(pool.map(_run, _jobs(suite, blocks[g])))
                       for g in GLOBAL}
            _table("terrain course (go1, ground to plateau; the 2-D simulator ignores height)",
                   results, world.heights)


if __name__ == "__main__":
    main()
