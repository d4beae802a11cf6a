"""Episode videos re-simulated from benchmark records."""

from __future__ import annotations

import math
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from arena.config.schema import ExperimentConfig
from arena.eval.io import load_record
from arena.eval.replay import episode_videos, pick_episodes, render_episode_video
from arena.eval.runner import run_benchmark
from arena.eval.store import load_results

SUITE = """\
stages:
  - name: crowd
    episodes: 2
    robot: jackal
    map: empty_room
    tm_robots: random
    tm_obstacles: random
    timeout: 5
    config:
      RANDOM:
        static: {min: 0, max: 1}
        dynamic: {min: 3, max: 3}
"""
CONTEST = """\
contestants:
  - {name: pure_pursuit, local_planner: pure_pursuit}
  - {name: orca, local_planner: orca}
"""


def test_pick_episodes_prefers_people_then_collisions_then_failures():
    nan = math.nan
    table = {
        "contestant": np.array(["a", "b"] * 4),
        "stage": np.array(["s"] * 6 + ["t"] * 2),
        "episode": np.array([0, 0, 1, 1, 2, 2, 0, 0]),
        "collisions": np.array([0, 0, 1, 0, 0, 0, 5, 5]),
        "outcome": np.array(["success", "success", "success", "success",
                             "timeout", "success", "collision", "collision"]),
        # stage t has no people: it comes last despite its collisions
        "min_distance_to_person": np.array([1.0, 1.0, 0.5, 0.6, 2.0, 2.0, nan, nan]),
    }
    assert pick_episodes(table, 4) == [("s", 1), ("s", 2), ("s", 0), ("t", 0)]
    assert pick_episodes(table, 1) == [("s", 1)]
    assert pick_episodes(table, 0) == []


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("replay")
    (d / "suite.yaml").write_text(SUITE)
    (d / "contest.yaml").write_text(CONTEST)
    return run_benchmark(d / "suite.yaml", d / "contest.yaml", d / "run",
                         base_cfg=ExperimentConfig(seed=3))


def test_video_shows_the_recorded_episode(run: Path, tmp_path: Path):
    table = load_results(run)
    rec_path = run / table.column("record")[1].as_py()
    video = render_episode_video(rec_path, tmp_path / "v", caption="x")
    assert video.matches_record and video.caption == "x"
    record = load_record(rec_path)
    frames = iio.imread(video.path, extension=".mp4")
    # every 2nd step plus the last frame
    assert frames.shape[0] == len(range(0, record.steps, 2)) + (record.steps - 1) % 2
    # readable in the report: the run config's width (800 px), even sizes for H.264
    assert frames.shape[2] == 800 and frames.shape[1] % 2 == 0


def test_episode_videos_one_per_contestant(run: Path, tmp_path: Path):
    table = load_results(run)
    videos = episode_videos(run, table, tmp_path, count=1)
    (stage, ep), = pick_episodes(table, 1)
    assert stage == "crowd"
    order = list(dict.fromkeys(table.column("contestant").to_pylist()))
    assert [v.caption.split(" · ")[0] for v in videos] == order
    assert sorted(order) == ["orca", "pure_pursuit"]
    assert all(v.matches_record and f"episode {ep}" in v.caption for v in videos)
    assert all(v.path.is_relative_to(tmp_path) and v.path.stat().st_size > 1000
               for v in videos)
