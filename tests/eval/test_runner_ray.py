"""The benchmark runner's ray backend on a local Ray: same results as the process backend.

Skipped where ray is not installed (``pip install 'arena[ray]'``; the ``test`` extra has it).
One local Ray serves most tests (starting one and warming its workers costs seconds).
"""

from __future__ import annotations

import math
import operator
import os
import shutil
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyarrow as pa
import pytest

from arena import cli
from arena.config.schema import ExperimentConfig
from arena.eval import runner
from arena.eval.runner import Job, plan_jobs, run_benchmark
from arena.eval.store import completed, load_results, read_manifest, summarize

# the quick suite at a small scale drops its one-episode scenario stage, as it should
pytestmark = pytest.mark.filterwarnings("ignore:.*drops stage:UserWarning")

ray = pytest.importorskip("ray")

CONTEST = "contestants:\n  - {name: pp, local_planner: pure_pursuit}\n"
#: the packaged quick suite at this scale: a few episodes (one per stage but the scenario).
SCALE = 0.1
VOLATILE = ("wall_time", "record")


def _nan(v: Any) -> Any:
    return "NaN" if isinstance(v, float) and math.isnan(v) else v


def _rows(table: pa.Table) -> list[dict[str, Any]]:
    """Every column but the volatile ones, NaN made comparable."""
    return [{k: _nan(v) for k, v in r.items()}
            for r in table.drop_columns(list(VOLATILE)).to_pylist()]


def _summary(table: pa.Table) -> list[dict[str, Any]]:
    return [{k: _nan(v) for k, v in r.items()} for r in summarize(table)]


@pytest.fixture(scope="module")
def contest(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("ray_contest") / "contest.yaml"
    path.write_text(CONTEST)
    return path


@pytest.fixture(scope="module")
def reference(contest: Path, tmp_path_factory: pytest.TempPathFactory) -> pa.Table:
    """An uninterrupted single-process run of the quick suite."""
    run = run_benchmark("quick", contest, tmp_path_factory.mktemp("ray_ref") / "run",
                        base_cfg=ExperimentConfig(seed=0), scale=SCALE)
    table = load_results(run)
    assert table.num_rows >= 3
    return table


@pytest.fixture(scope="module")
def local_ray() -> Iterator[None]:
    """One quiet local Ray with 2 CPUs for the module; run_benchmark uses it, keeps it up."""
    temp_dir = runner._ray_init(ray, 2, None)
    try:
        yield
    finally:
        ray.shutdown()
        if temp_dir is not None:
            shutil.rmtree(temp_dir, ignore_errors=True)


def test_ray_starts_and_stops_its_own_local_ray(monkeypatch: pytest.MonkeyPatch) -> None:
    if ray.is_initialized():  # pragma: no cover - only when run after the shared session
        pytest.skip("a Ray session is already up")
    made: list[str | None] = []
    init = runner._ray_init

    def spy(*args: Any) -> str | None:
        made.append(init(*args))
        assert ray.is_initialized()
        return made[-1]

    monkeypatch.setattr(runner, "_ray_init", spy)
    runner._execute_ray([], 1, lambda result: None)
    assert len(made) == 1 and made[0] is not None
    assert not ray.is_initialized()  # we started it, so we shut it down
    assert not Path(made[0]).exists()  # and removed its temp dir


@pytest.mark.usefixtures("local_ray")
def test_ray_gives_the_process_results(reference: pa.Table, contest: Path,
                                       tmp_path: Path) -> None:
    seen: list[int] = []
    run = run_benchmark("quick", contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0),
                        scale=SCALE, backend="ray", workers=2,
                        progress=lambda n, total, row: seen.append(n))
    assert seen == list(range(1, reference.num_rows + 1))
    t = load_results(run)
    assert t.column_names == reference.column_names
    assert _rows(t) == _rows(reference)
    assert _summary(t) == _summary(reference)
    assert ray.is_initialized()  # not ours to shut down
    assert set(read_manifest(run)) == {"suite", "contest", "seed", "scale", "worlds",
                                       "simulator", "created", "arena_version"}
    # nothing specific to the ray or process pool


class _Stop(Exception):
    pass


@pytest.mark.usefixtures("local_ray")
@pytest.mark.parametrize(("first", "then"), [("process", "ray"), ("ray", "process")])
def test_resume_across_backends(first: str, then: str, reference: pa.Table, contest: Path,
                                tmp_path: Path) -> None:
    run = tmp_path / "run"

    def stop_after_one(n: int, total: int, row: dict[str, Any]) -> None:
        raise _Stop  # an interrupted run: one episode committed

    with pytest.raises(_Stop):
        run_benchmark("quick", contest, run, base_cfg=ExperimentConfig(seed=0), scale=SCALE,
                      backend=first, workers=2 if first == "ray" else 1,
                      progress=stop_after_one)
    assert len(completed(run)) == 1
    seen: list[int] = []
    run_benchmark("quick", contest, run, base_cfg=ExperimentConfig(seed=0), scale=SCALE,
                  backend=then, workers=2 if then == "ray" else 1, resume=True,
                  progress=lambda n, total, row: seen.append(n))
    assert seen == list(range(2, reference.num_rows + 1))  # only the missing episodes ran
    assert _rows(load_results(run)) == _rows(reference)


class _Unpicklable:
    """Pickles fine; unpickling (in the ray worker) raises ZeroDivisionError."""

    def __reduce__(self) -> tuple[Any, tuple[int, int]]:
        return operator.truediv, (1, 0)


@pytest.mark.usefixtures("local_ray")
def test_ray_task_failure_is_an_error_row(contest: Path) -> None:
    from arena.tasks.suite import load_contest, load_suite

    good = plan_jobs(load_suite("quick", scale_episodes=0.34), load_contest(contest)[0],
                     ExperimentConfig(seed=0))[:1]
    bad = Job("pp", "pure_pursuit", "bypass", "random", 7, {"robot": "jackal",
                                                            "x": _Unpicklable()})
    results: list[tuple[dict[str, Any], Any]] = []
    runner._execute_ray([bad, *good], 2, results.append)
    by = {row["episode"]: (row, record) for row, record in results}
    row, record = by[7]
    assert row["outcome"] == "error" and record is None
    assert row["error"].startswith("RaySystemError: ") and "division by zero" in row["error"]
    assert (row["stage"], row["robot"], row["collisions"]) == ("random", "jackal", 0)
    assert math.isnan(row["path_length"]) and math.isnan(row["time"])
    assert by[0][0]["outcome"] != "error" and by[0][1] is not None


@pytest.mark.usefixtures("local_ray")
def test_cli_bench_backend_ray(reference: pa.Table, contest: Path, tmp_path: Path,
                               monkeypatch: pytest.MonkeyPatch,
                               capsys: pytest.CaptureFixture[str]) -> None:
    run = tmp_path / "run"
    monkeypatch.setattr(sys, "argv", ["arena", "bench", "quick", "--contest", str(contest),
                                      "-o", str(run), "--scale", str(SCALE), "--backend", "ray",
                                      "-j", "2", "--no-progress"])
    with pytest.raises(SystemExit) as ok:
        cli.main()
    out, err = capsys.readouterr()
    assert ok.value.code in (0, None), err
    assert "random" in out and f"run folder: {run}" in out.replace("\n", "")
    assert _rows(load_results(run)) == _rows(reference)


class _ExitOnArrival:
    """Pickles fine; unpickling (in the ray worker) ends that worker: ``os._exit(3)``."""

    def __reduce__(self) -> tuple[Any, tuple[int]]:
        return os._exit, (3,)


class _HangOnArrival:
    """Pickles fine; unpickling (in the ray worker) sleeps for an hour."""

    def __reduce__(self) -> tuple[Any, tuple[int]]:
        return time.sleep, (3600,)


@pytest.mark.usefixtures("local_ray")
def test_ray_dead_or_hung_worker_is_an_error_row(contest: Path) -> None:
    from arena.tasks.suite import load_contest, load_suite

    good = plan_jobs(load_suite("quick", scale_episodes=0.34), load_contest(contest)[0],
                     ExperimentConfig(seed=0))[:1]
    dies = Job("pp", "pure_pursuit", "bypass", "random", 7, {"robot": "jackal",
                                                             "x": _ExitOnArrival()})
    hangs = Job("pp", "pure_pursuit", "bypass", "random", 8, {"robot": "jackal",
                                                              "x": _HangOnArrival()})
    results: list[tuple[dict[str, Any], Any]] = []
    runner._execute_ray([dies, *good], 1, results.append)
    by = {row["episode"]: row for row, _ in results}
    assert sorted(by) == [0, 7]
    assert by[7]["outcome"] == "error"
    assert by[7]["error"].startswith("worker died (WorkerCrashedError")
    assert by[0]["outcome"] != "error"  # the run went on after the death
    results.clear()
    runner._execute_ray([hangs], 1, results.append, timeout=2)
    assert [(row["episode"], row["outcome"], row["error"]) for row, _ in results] == [
        (8, "error", "wall-clock limit 2 s exceeded")]
