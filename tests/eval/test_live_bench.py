"""``arena bench --live``: each worker serves its episodes for watching; results unchanged."""

from __future__ import annotations

import math
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from arena.config.schema import ExperimentConfig
from arena.eval.live_bench import LIVE_DIR
from arena.eval.runner import run_benchmark
from arena.eval.store import load_results
from arena.live import LiveClient
from arena.web.store import RunStore
from tests.eval._suites import TWO_STAGES

CONTEST = """\
contestants:
  - {name: pure_pursuit, local_planner: pure_pursuit}
  - {name: dwa, local_planner: dwa}
"""


def _rows(run: Path) -> list[dict[str, Any]]:
    table = load_results(run).drop_columns(["wall_time", "record"])
    return [{k: ("NaN" if isinstance(v, float) and math.isnan(v) else v) for k, v in r.items()}
            for r in table.to_pylist()]


class _Watcher(threading.Thread):
    """Waits for a worker's channel file, connects, and keeps what it is sent."""

    def __init__(self, run: Path) -> None:
        super().__init__(daemon=True)
        self.folder, self.messages, self.channels = run, [], {}
        self.problem: str | None = None

    def run(self) -> None:
        deadline = time.monotonic() + 120
        files: list[Path] = []
        while not files and time.monotonic() < deadline:
            files = sorted((self.folder / LIVE_DIR).glob("worker_*.json"))
            time.sleep(0.01)
        if not files:
            self.problem = "no channel file"
            return
        self.channels = RunStore(self.folder.parent).channels(self.folder.name)
        try:
            with LiveClient.from_info(files[0]) as client:
                paused = False
                for m in client.messages():
                    self.messages.append(m)
                    kinds = {x.get("type") for x in self.messages}
                    if "frame" in kinds and "scene" in kinds and not paused:
                        client.send({"cmd": "pause"})  # refused: benchmarks are watched only
                        paused = True
                    if "error" in kinds:
                        return
        except (OSError, ValueError) as e:
            self.problem = f"{type(e).__name__}: {e}"


def test_watched_bench_changes_no_result(tmp_path):
    (tmp_path / "suite.yaml").write_text(TWO_STAGES)
    (tmp_path / "contest.yaml").write_text(CONTEST)
    suite, contest = tmp_path / "suite.yaml", tmp_path / "contest.yaml"
    plain = run_benchmark(suite, contest, tmp_path / "plain", base_cfg=ExperimentConfig(seed=0),
                          workers=0)
    watcher = _Watcher(tmp_path / "runs" / "watched")
    watcher.start()
    watched = run_benchmark(suite, contest, tmp_path / "runs" / "watched",
                            base_cfg=ExperimentConfig(seed=0), workers=1, live=True)
    watcher.join(30)
    assert watcher.problem is None
    assert _rows(watched) == _rows(plain)
    kinds = [m.get("type") for m in watcher.messages]
    assert "scene" in kinds and "frame" in kinds
    scene = next(m for m in watcher.messages if m.get("type") == "scene")
    assert " · episode " in scene["title"]  # contestant · stage · episode k
    error = next(m for m in watcher.messages if m.get("type") == "error")
    assert "no commands" in error["message"]  # watching only: no pause, goal or teleport
    assert [n.startswith("worker_") for n in watcher.channels] == [True]
    assert not list((watched / LIVE_DIR).glob("*.json"))  # each worker removed its file
    assert RunStore(watched.parent).channels(watched.name) == {}


def test_live_needs_the_process_backend(tmp_path):
    from arena.core.errors import ArenaError

    (tmp_path / "suite.yaml").write_text(TWO_STAGES)
    (tmp_path / "contest.yaml").write_text(CONTEST)
    with pytest.raises(ArenaError, match="process backend"):
        run_benchmark(tmp_path / "suite.yaml", tmp_path / "contest.yaml", tmp_path / "r",
                      backend="ray", live=True)
