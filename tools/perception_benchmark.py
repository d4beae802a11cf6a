"""Each classic planner on ground-truth, lidar and RGB-D people: the table of docs/perception.md.

    python tools/perception_benchmark.py [-o runs/perception] [-j 2] [--scale 1]

Runs the packaged ``quick`` suite (31 episodes with people) on the MuJoCo backend with a jackal
carrying the detector's training camera (:data:`~arena.perception.rgbd_data.CAMERA`, sensor
``camera``), every planner of the ``quick`` contest three times: on the ground truth, on lidar
people and on RGB-D people (``perception: {type: ...}`` per contestant). Prints the Markdown
table: success, collisions per episode, time a person spent in the robot's private zone, and
the tracking scores of the perceived runs (MOTA, recall and precision pooled over all
episodes, IDF1 the episodes' mean). Needs ``arena[3d]``.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import yaml

from arena.eval.io import load_record
from arena.eval.metrics.tracking import mot_scores
from arena.eval.store import load_results
from arena.perception.rgbd_data import with_camera
from arena.robots.presets import load_robot
from arena.tasks.datafiles import find_data_file

PLANNERS = ("dwa", "orca", "social_force", "teb")
PERCEPTIONS = ("ground_truth", "lidar", "rgbd")
LABEL = {"ground_truth": "ground truth", "lidar": "lidar", "rgbd": "RGB-D"}


def write_inputs(out: Path) -> tuple[Path, Path]:
    """The camera robot, the suite on it and the contest; returns (suite, contest)."""
    out.mkdir(parents=True, exist_ok=True)
    robot = out / "jackal_rgbd.yaml"
    data = with_camera(load_robot("jackal")).model_dump(mode="json")
    data["name"] = "jackal_rgbd"
    data["description"] = "Clearpath Jackal with the RGB-D people detector's training camera"
    robot.write_text(yaml.safe_dump(data, sort_keys=False))
    suite = yaml.safe_load(find_data_file("suites", "quick").read_text())
    for stage in suite["stages"]:
        stage["robot"] = str(robot)
    suite_path = out / "quick_rgbd.yaml"
    suite_path.write_text(yaml.safe_dump(suite, sort_keys=False))
    contestants = [
        {"name": f"{p}" if q == "ground_truth" else f"{p}_{q}", "local_planner": p,
         "inter_planner": "bypass", "perception": {"type": q}}
        for p in PLANNERS for q in PERCEPTIONS
    ]
    contest = out / "perception_contest.yaml"
    contest.write_text(yaml.safe_dump({"contestants": contestants}, sort_keys=False))
    return suite_path, contest


def pooled(run: Path, rows: list[dict]) -> tuple[float, float, float]:
    """``(MOTA, recall, precision)`` of the tracks over all episodes of ``rows`` together.

    A per-episode MOTA averages badly (an episode that saw one person for a second weighs as
    much as one that saw twenty all the time); pooled, each person-frame counts once.
    """
    fn = fp = sw = gt = matched = hyp = 0
    for r in rows:
        s = mot_scores(load_record(run / r["record"]), 0.5)
        if s is None:
            return math.nan, math.nan, math.nan
        fn, fp, sw = fn + s.misses, fp + s.false_positives, sw + s.id_switches
        gt, matched, hyp = gt + s.ground_truth, matched + s.matches, hyp + s.hypotheses
    return 1 - (fn + fp + sw) / max(gt, 1), matched / max(gt, 1), matched / max(hyp, 1)


def table(run: Path) -> str:
    """The Markdown table of a finished run."""
    rows = load_results(run).to_pylist()
    lines = ["| planner | people from | success | collisions / ep | time in private zone (s) "
             "| MOTA | recall | precision | IDF1 |", "|---|---|---|---|---|---|---|---|---|"]

    def mean(rs: list[dict], key: str) -> float:
        v = np.array([r[key] for r in rs], dtype=np.float64)
        v = v[np.isfinite(v)]
        return float(v.mean()) if v.size else math.nan

    for p in PLANNERS:
        for q in PERCEPTIONS:
            name = p if q == "ground_truth" else f"{p}_{q}"
            rs = [r for r in rows if r["contestant"] == name]
            if not rs:
                continue
            mota, recall, precision = pooled(run, rs)
            idf1 = mean(rs, "tracking_idf1")
            track = ("–",) * 4 if math.isnan(mota) else (
                f"{mota:.2f}", f"{recall:.2f}", f"{precision:.2f}", f"{idf1:.2f}")
            lines.append(f"| {p} | {LABEL[q]} | {100 * mean(rs, 'success'):.0f} % | "
                         f"{mean(rs, 'collisions'):.2f} | {mean(rs, 'time_in_private_zone'):.2f}"
                         f" | {' | '.join(track)} |")
    return "\n".join(lines)


def main() -> None:
    """Write the inputs, run the benchmark, print the table."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("-o", "--out", type=Path, default=Path("runs/perception"))
    ap.add_argument("-j", "--workers", type=int, default=2)
    ap.add_argument("--scale", type=float, default=1.0)
    args = ap.parse_args()
    suite, contest = write_inputs(args.out)
    run = args.out / "run"
    t0 = time.time()
    cmd = [sys.executable, "-m", "arena.cli", "bench", str(suite), "--contest", str(contest),
           "--simulator", "mujoco", "-j", str(args.workers), "--scale", str(args.scale),
           "--no-progress", "--resume" if run.exists() else "-o", str(run)]
    subprocess.run(cmd, check=True)
    print(f"\n{len(PLANNERS) * len(PERCEPTIONS)} contestants, {time.time() - t0:.0f} s "
          f"(-j {args.workers})\n")
    print(table(run))


if __name__ == "__main__":
    main()
