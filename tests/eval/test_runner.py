"""Benchmark runner and results store: determinism across workers, resume, errors, CLI."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pytest

from arena import cli
from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError
from arena.eval.io import load_record
from arena.eval.metrics import METRICS
from arena.eval.runner import run_benchmark
from arena.eval.store import commit_episode, completed, load_results, read_manifest, summarize
from arena.nav.local_planners.base import LOCAL_PLANNERS
from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner
from tests.eval._suites import TWO_STAGES

# the quick suite at a small scale drops its one-episode scenario stage, as it should
pytestmark = pytest.mark.filterwarnings("ignore:.*drops stage:UserWarning")

SUITE = TWO_STAGES
CONTEST = """\
contestants:
  - {name: pure_pursuit, local_planner: pure_pursuit}
  - {name: dwa, local_planner: dwa}
"""
VOLATILE = ("wall_time", "record")


class _BoomPlanner(PurePursuitPlanner):
    """Raises a plain Python exception after one simulated second."""

    def compute(self, obs):  # type: ignore[no-untyped-def]
        if obs.time > 1.0:
            raise RuntimeError("boom from the test planner")
        return super().compute(obs)


class _NaNPlanner(PurePursuitPlanner):
    """Returns a NaN command."""

    def compute(self, obs):  # type: ignore[no-untyped-def]
        return np.full(3, np.nan)


@pytest.fixture
def failing_planners(monkeypatch: pytest.MonkeyPatch) -> None:
    """Register the failing planners for one test only (other tests list every planner)."""
    monkeypatch.setattr(LOCAL_PLANNERS, "_entries", dict(LOCAL_PLANNERS._entries))
    LOCAL_PLANNERS.add("test_runner_boom", _BoomPlanner)
    LOCAL_PLANNERS.add("test_runner_nan", _NaNPlanner)


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    d = tmp_path_factory.mktemp("bench")
    (d / "suite.yaml").write_text(SUITE)
    (d / "contest.yaml").write_text(CONTEST)
    return d / "suite.yaml", d / "contest.yaml"


@pytest.fixture(scope="module")
def reference(files: tuple[Path, Path], tmp_path_factory: pytest.TempPathFactory) -> pa.Table:
    """An uninterrupted run in this process."""
    suite, contest = files
    run = run_benchmark(suite, contest, tmp_path_factory.mktemp("ref") / "run",
                        base_cfg=ExperimentConfig(seed=0), workers=0)
    return load_results(run)


def _rows(table: pa.Table) -> list[dict[str, Any]]:
    """Rows without the volatile columns, NaN made comparable."""
    out = []
    for r in table.drop_columns(list(VOLATILE)).to_pylist():
        out.append({k: ("NaN" if isinstance(v, float) and math.isnan(v) else v)
                    for k, v in r.items()})
    return out


def test_results_table_layout(reference: pa.Table) -> None:
    t = reference
    assert t.num_rows == 8
    names = t.column_names
    assert names[:9] == ["contestant", "local_planner", "inter_planner", "stage", "episode",
                         "seed", "map", "robot", "outcome"]
    assert names[-6:] == ["time", "path_length", "collisions", "wall_time", "error", "record"]
    for m in METRICS.names():
        typ = pa.int64() if m == "collisions" else pa.float64()
        assert t.schema.field(m).type == typ
        assert names.count(m) == 1
    keys = list(zip(t["contestant"].to_pylist(), t["stage"].to_pylist(),
                    t["episode"].to_pylist(), strict=True))
    assert keys == sorted(keys) and len(set(keys)) == 8
    assert set(t["contestant"].to_pylist()) == {"pure_pursuit", "dwa"}
    assert set(t["inter_planner"].to_pylist()) == {"bypass"}
    assert set(t["robot"].to_pylist()) == {"jackal", "burger"}
    assert "error" not in t["outcome"].to_pylist()


def test_record_and_row_files(reference: pa.Table, files: tuple[Path, Path],
                              tmp_path: Path) -> None:
    suite, contest = files
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0))
    t = load_results(run)
    rel = t["record"].to_pylist()[0]
    record = load_record(run / rel)
    assert record.meta.outcome == t["outcome"].to_pylist()[0]
    assert (run / rel).with_suffix(".json").is_file()
    assert not list(run.rglob("*.tmp"))
    manifest = read_manifest(run)
    assert manifest["seed"] == 0 and manifest["scale"] == 1.0
    assert manifest["suite"] == str(suite.resolve())
    assert len(completed(run)) == 8


def test_workers_do_not_change_results(reference: pa.Table, files: tuple[Path, Path],
                                       tmp_path: Path) -> None:
    suite, contest = files
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0),
                        workers=2)
    assert _rows(load_results(run)) == _rows(reference)


def test_kill_and_resume(reference: pa.Table, files: tuple[Path, Path], tmp_path: Path) -> None:
    # The bench process is SIGKILLed by its own progress callback right after the third commit:
    # the same point on every machine (a parent polling the run folder raced the episodes).
    suite, contest = files
    run = tmp_path / "run"
    script = (
        "import os, signal, sys\n"
        "from arena.config.schema import ExperimentConfig\n"
        "from arena.eval.runner import run_benchmark\n"
        "def die(n, total, row):\n"
        "    if n == 3:\n"
        "        os.kill(os.getpid(), signal.SIGKILL)\n"
        "run_benchmark(sys.argv[1], sys.argv[2], sys.argv[3], base_cfg=ExperimentConfig(seed=0),"
        " progress=die)\n"
    )
    log = tmp_path / "stderr.txt"  # a file, not a pipe: a worker it left behind cannot hold it
    with log.open("w") as err:
        proc = subprocess.run([sys.executable, "-c", script, str(suite), str(contest), str(run)],
                              stdout=subprocess.DEVNULL, stderr=err, check=False)
    assert proc.returncode == -signal.SIGKILL, log.read_text()
    done = len(completed(run))
    assert done == 3, f"{done} episodes committed before the kill"
    assert not list(run.rglob("*.tmp"))
    progress: list[int] = []
    run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=0), resume=True,
                  progress=lambda n, total, row: progress.append(n))
    assert progress == list(range(done + 1, 9))  # only the missing episodes ran
    t = load_results(run)
    assert t.num_rows == 8
    assert _rows(t) == _rows(reference)


def test_resume_with_other_settings_is_an_error(files: tuple[Path, Path],
                                                tmp_path: Path) -> None:
    suite, contest = files
    run = tmp_path / "run"
    (run / "episodes").mkdir(parents=True)
    run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=0), scale=0.5)
    with pytest.raises(ArenaError, match=r"run\.json.*'seed'.*0.*7"):
        run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=7), resume=True,
                      scale=0.5)
    with pytest.raises(ArenaError, match=r"'scale'"):
        run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=0), resume=True)
    with pytest.raises(ArenaError, match=r"'suite'"):
        run_benchmark("quick", contest, run, base_cfg=ExperimentConfig(seed=0), resume=True,
                      scale=0.5)
    with pytest.raises(ArenaError, match="already holds a run"):
        run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=0), scale=0.5)
    with pytest.raises(ArenaError, match="no run manifest"):
        run_benchmark(suite, contest, tmp_path / "none", resume=True)


@pytest.mark.usefixtures("failing_planners")
def test_planner_exception_is_an_error_episode(files: tuple[Path, Path], tmp_path: Path) -> None:
    suite, _ = files
    contest = tmp_path / "contest.yaml"
    contest.write_text(
        "contestants:\n"
        "  - {name: boom, local_planner: test_runner_boom}\n"
        "  - {name: nan, local_planner: test_runner_nan}\n"
        "  - {name: pp, local_planner: pure_pursuit}\n"
    )
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0),
                        scale=0.5, workers=0)  # in this process: the planners registered here
    rows = load_results(run).to_pylist()
    by = {c: [r for r in rows if r["contestant"] == c] for c in ("boom", "nan", "pp")}
    assert [len(v) for v in by.values()] == [2, 2, 2]
    for r in by["boom"]:
        assert r["outcome"] == "error"
        assert "RuntimeError: boom from the test planner" in r["error"]
    for r in by["nan"]:
        assert r["outcome"] == "error" and "invalid command" in r["error"]
        assert r["record"]  # run_episode's own error path keeps the record
    for r in by["pp"]:
        assert r["outcome"] != "error" and r["error"] == ""
        assert not math.isnan(r["path_length"])
    summary = {(s["contestant"], s["stage"]): s for s in summarize(load_results(run))}
    assert summary[("boom", "open")]["errors"] == 1


def test_store_ignores_uncommitted_files(tmp_path: Path) -> None:
    run = tmp_path / "run"
    row = {"contestant": "c", "local_planner": "x", "inter_planner": "bypass", "stage": "s",
           "episode": 3, "seed": 1, "map": "m", "robot": "r", "outcome": "error", "time": 1.0,
           "path_length": 0.0, "collisions": 0, "wall_time": 0.1, "error": "E: x", "m1": 0.5}
    commit_episode(run, row, None)
    folder = run / "episodes" / "c" / "s"
    (folder / "0004.parquet").write_bytes(b"orphan record, no row")
    (folder / ".0005.json.abc.tmp").write_text("{}")
    assert completed(run) == {("c", "s", 3)}
    t = load_results(run)
    assert t.num_rows == 1 and t["m1"].to_pylist() == [0.5] and t["record"].to_pylist() == [""]
    assert json.loads((folder / "0003.json").read_text())["episode"] == 3
    with pytest.raises(ArenaError, match="contestant name"):
        commit_episode(run, {**row, "contestant": "a/b"}, None)


def test_ray_backend_without_ray_is_a_clear_error(files: tuple[Path, Path], tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    suite, contest = files
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` fails, installed or not
    with pytest.raises(ArenaError, match="ray package"):
        run_benchmark(suite, contest, tmp_path / "run", backend="ray")


def test_cli_bench(files: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                   capsys: pytest.CaptureFixture[str]) -> None:
    suite, contest = files
    run = tmp_path / "run"

    def call(*args: str) -> tuple[int, str, str]:
        monkeypatch.setattr(sys, "argv", ["arena", "bench", *args])
        code = 0
        try:
            cli.main()
        except SystemExit as e:
            code = int(e.code or 0)
        out = capsys.readouterr()
        return code, out.out, out.err

    monkeypatch.setattr(cli.console, "width", 200)
    code, out, err = call(str(suite), "--contest", str(contest), "-o", str(run), "--scale",
                          "0.5", "--no-progress", "--report")
    assert code == 0, err
    assert "pure_pursuit" in out and "dwa" in out and "crowd" in out
    assert "mean over all episodes" in out and "success per stage" in out
    # the caption names the personal-space radius the metrics used (MetricParams' default)
    assert "no body gap to a person below 1.2 m" in " ".join(out.split())
    assert f"run folder: {run}" in out.replace("\n", "")
    assert f"html:  {run / 'report' / 'report.html'}" in out
    assert (run / "report" / "report.html").is_file()
    assert load_results(run).num_rows == 4
    code, out, err = call(str(suite), "--resume", str(run), "--no-progress")  # the run's settings
    assert code == 0, err
    code, out, err = call(str(suite), "--resume", str(run), "--seed", "5")
    assert code == 2 and "seed" in err and "Traceback" not in err


def test_cli_report(reference: pa.Table, files: tuple[Path, Path], tmp_path: Path,
                    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    suite, contest = files
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0),
                        scale=0.5)
    monkeypatch.setattr(sys, "argv", ["arena", "report", str(run)])
    with pytest.raises(SystemExit) as ok:
        cli.main()
    assert ok.value.code in (0, None)
    out = capsys.readouterr().out
    html = (run / "report" / "report.html").read_text()
    assert "report.html" in out and 'src="http' not in html
    assert "pure_pursuit" in html and "data:image/png;base64," in html
    # one re-simulated episode per contestant, by default
    assert html.count("data:video/mp4;base64,") == 2 and "episode " in html
    assert (run / "report" / "summary.tex").read_text().count("\\toprule") == 2  # all, stages
    monkeypatch.setattr(sys, "argv", ["arena", "report", str(tmp_path)])
    with pytest.raises(SystemExit) as e:
        cli.main()
    assert e.value.code == 2 and "not a benchmark run folder" in capsys.readouterr().err
