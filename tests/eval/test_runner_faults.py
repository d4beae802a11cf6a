"""Faults cost one episode: dying workers, hung planners, a killed parent (process backend).

The faulty planner (:mod:`tests.eval.fault_planners`) must be known to the benchmark's worker
processes, which are fresh interpreters: it reaches them as a third-party plugin, through an
entry point of a throw-away distribution on ``sys.path`` (spawned workers inherit the parent's
``sys.path``; a subprocess gets it through ``PYTHONPATH``).
"""

from __future__ import annotations

import math
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pyarrow as pa
import pytest

from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError
from arena.eval import workers
from arena.eval.runner import run_benchmark
from arena.eval.store import completed, load_results
from arena.nav.local_planners.base import LOCAL_PLANNERS
from tests.eval._suites import TWO_STAGES
from tests.eval.fault_planners import EXIT_CODE

ROOT = Path(__file__).resolve().parents[2]
SUITE = TWO_STAGES
#: At this scale the suite has one episode per stage.
SCALE = 0.5
HEALTHY = "  - {name: pp, local_planner: pure_pursuit}\n"
VOLATILE = ("wall_time", "record")
#: Generous bound on waits for other processes (start-up on a loaded machine included).
BOUND_S = 120.0


def _fault(name: str, fault: str, at: float = 0.0, touch: Path | None = None) -> str:
    extra = f", touch: '{touch}'" if touch is not None else ""
    return (f"  - {{name: {name}, local_planner: test_fault, "
            f"params: {{fault: {fault}, at: {at}{extra}}}}}\n")


def _rows(table: pa.Table) -> list[dict[str, Any]]:
    out = []
    for r in table.drop_columns(list(VOLATILE)).to_pylist():
        out.append({k: ("NaN" if isinstance(v, float) and math.isnan(v) else v)
                    for k, v in r.items()})
    return out


@pytest.fixture
def fault_plugin(tmp_path_factory: pytest.TempPathFactory,
                 monkeypatch: pytest.MonkeyPatch) -> Path:
    """Install ``test_fault`` (an entry point) for this test and its workers; return its dir."""
    site = tmp_path_factory.mktemp("site")
    dist = site / "arena_test_faults-0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: arena-test-faults\n"
                                   "Version: 0\n")
    (dist / "entry_points.txt").write_text(
        "[arena.local_planners]\ntest_fault = tests.eval.fault_planners:FaultPlanner\n")
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(LOCAL_PLANNERS, "_entries", dict(LOCAL_PLANNERS._entries))
    monkeypatch.setattr(LOCAL_PLANNERS, "_entry_points_loaded", False)
    return site


@pytest.fixture(scope="module")
def suite(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("faults") / "suite.yaml"
    path.write_text(SUITE)
    return path


@pytest.fixture(scope="module")
def healthy(suite: Path, tmp_path_factory: pytest.TempPathFactory) -> list[dict[str, Any]]:
    """The healthy contestant's rows of an in-process run without faults."""
    d = tmp_path_factory.mktemp("healthy")
    (d / "contest.yaml").write_text("contestants:\n" + HEALTHY)
    run = run_benchmark(suite, d / "contest.yaml", d / "run", base_cfg=ExperimentConfig(seed=0),
                        scale=SCALE, workers=0)
    rows = _rows(load_results(run))
    assert len(rows) == 2 and all(r["outcome"] != "error" for r in rows)
    return rows


def _contest(tmp_path: Path, *lines: str) -> Path:
    path = tmp_path / "contest.yaml"
    path.write_text("contestants:\n" + "".join(lines))
    return path


@pytest.mark.usefixtures("fault_plugin")
@pytest.mark.parametrize(("fault", "reason"), [
    ("exit", f"worker died (exit code {EXIT_CODE})"),
    ("segfault", "worker died (exit code -11: SIGSEGV)"),
])
def test_a_dying_worker_costs_its_episode_only(fault: str, reason: str, suite: Path,
                                               healthy: list[dict[str, Any]],
                                               tmp_path: Path) -> None:
    contest = _contest(tmp_path, _fault("crash", fault), HEALTHY)  # the crashes come first
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0),
                        scale=SCALE, workers=2)
    rows = _rows(load_results(run))
    crash = [r for r in rows if r["contestant"] == "crash"]
    assert [(r["stage"], r["outcome"], r["error"]) for r in crash] == [
        ("crowd", "error", reason), ("open", "error", reason)]
    assert all(r["path_length"] == "NaN" and r["seed"] is None for r in crash)
    assert [r for r in rows if r["contestant"] == "pp"] == healthy  # same rows as without faults
    assert not mp.active_children()  # every worker reaped


@pytest.mark.usefixtures("fault_plugin")
def test_resume_after_worker_deaths(suite: Path, healthy: list[dict[str, Any]],
                                    tmp_path: Path) -> None:
    contest = _contest(tmp_path, _fault("crash", "exit"), HEALTHY)
    run = tmp_path / "run"

    class Stop(Exception):
        pass

    def stop(n: int, total: int, row: dict[str, Any]) -> None:
        raise Stop  # an interrupted run: one episode committed, the workers killed

    with pytest.raises(Stop):
        run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=0), scale=SCALE,
                      workers=1, progress=stop)
    assert not mp.active_children()
    assert completed(run) == {("crash", "open", 0)}
    seen: list[int] = []
    run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=0), scale=SCALE,
                  workers=1, resume=True, progress=lambda n, total, row: seen.append(n))
    assert seen == [2, 3, 4]  # the rest ran, a second worker death included
    rows = _rows(load_results(run))
    assert [r["outcome"] for r in rows if r["contestant"] == "crash"] == ["error", "error"]
    assert [r for r in rows if r["contestant"] == "pp"] == healthy


@pytest.mark.usefixtures("fault_plugin")
def test_a_hung_planner_hits_the_wall_clock_limit(suite: Path, tmp_path: Path) -> None:
    contest = _contest(tmp_path, _fault("hang", "hang", at=0.5))
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0),
                        scale=SCALE, workers=1, episode_timeout=2)
    rows = load_results(run).to_pylist()
    assert [(r["stage"], r["outcome"], r["error"]) for r in rows] == [
        ("crowd", "error", "wall-clock limit 2 s exceeded"),
        ("open", "error", "wall-clock limit 2 s exceeded"),  # the run went on after the first
    ]
    assert not mp.active_children()


@pytest.mark.usefixtures("fault_plugin")
def test_a_raising_plugin_is_an_error_row_in_a_worker(suite: Path, tmp_path: Path) -> None:
    contest = _contest(tmp_path, _fault("boom", "raise", at=0.5))
    run = run_benchmark(suite, contest, tmp_path / "run", base_cfg=ExperimentConfig(seed=0),
                        scale=SCALE, workers=1)
    rows = load_results(run).to_pylist()
    assert [r["outcome"] for r in rows] == ["error", "error"]
    for r in rows:
        assert r["error"].startswith("RuntimeError: fault planner raised on purpose (at ")
        assert r["record"]  # the episode's record up to the fault is kept


def _children(pid: int) -> list[int]:
    """Pids of the processes whose parent is ``pid`` (Linux ``/proc``)."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def _alive(pid: int) -> bool:
    """``pid`` runs (a zombie waiting for a reaper counts as gone)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


def _wait_for(condition: Any, what: str, bound: float = BOUND_S) -> None:
    deadline = time.monotonic() + bound
    while not condition():
        assert time.monotonic() < deadline, f"gave up waiting for {what} after {bound:g} s"
        time.sleep(0.1)


#: Process parents and states are read from /proc: Linux, where CI runs (and where the kill
#: with the parent, PR_SET_PDEATHSIG, lives).
NEEDS_PROC = pytest.mark.skipif(not Path("/proc/self/stat").is_file(),
                                reason="reads process parents and states from Linux /proc")


@NEEDS_PROC
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_workers_exit_with_a_killed_parent(sig: signal.Signals, fault_plugin: Path,
                                           suite: Path, tmp_path: Path) -> None:
    hung = tmp_path / "hung"  # where each worker leaves its pid once it hangs
    hung.mkdir()
    contest = _contest(tmp_path, _fault("hang", "hang", touch=hung))  # both workers, forever
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(fault_plugin), str(ROOT)])}
    proc = subprocess.Popen(
        [sys.executable, "-m", "arena.cli", "bench", str(suite), "--contest", str(contest),
         "-o", str(tmp_path / "run"), "--scale", str(SCALE), "-j", "2", "--no-progress",
         "--episode-timeout", "0"],
        cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )
    pids: list[int] = []
    try:
        def two_hung_workers() -> bool:
            pids[:] = [int(p.name) for p in hung.iterdir()]
            return len(pids) == 2 or proc.poll() is not None

        _wait_for(two_hung_workers, "both workers to run a hung episode")
        assert proc.poll() is None, "the bench ended on its own"
        assert set(pids) <= set(_children(proc.pid))  # they are the bench's workers
        proc.send_signal(sig)
        proc.wait(BOUND_S)
        _wait_for(lambda: not any(_alive(p) for p in pids), "the workers to exit", bound=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(BOUND_S)
        for p in pids:  # whatever is left of a failed test
            if _alive(p):
                os.kill(p, signal.SIGKILL)


@NEEDS_PROC
def test_watchdog_alone_ends_an_orphaned_worker(tmp_path: Path) -> None:
    """The portable fallback (no PR_SET_PDEATHSIG): the worker's watchdog sees the new ppid."""
    armed = tmp_path / "armed"  # the grandchild writes its pid there once its watchdog runs
    grandchild = (
        "import os, time; from pathlib import Path; from arena.eval import workers; "
        "workers._exit_with_parent(os.getppid(), pdeathsig=False); "
        f"Path({str(armed)!r}).write_text(str(os.getpid())); time.sleep(3600)"
    )
    middle = (
        "import subprocess, sys, time; "
        f"subprocess.Popen([sys.executable, '-c', {grandchild!r}]); time.sleep(3600)"
    )
    proc = subprocess.Popen([sys.executable, "-c", middle], cwd=ROOT)
    pid = 0
    try:
        _wait_for(lambda: (armed.is_file() and armed.read_text() != "")
                  or proc.poll() is not None, "the grandchild to arm its watchdog")
        pid = int(armed.read_text())
        proc.kill()
        proc.wait(BOUND_S)
        _wait_for(lambda: not _alive(pid), "the orphaned worker to exit", bound=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(BOUND_S)
        if pid and _alive(pid):
            os.kill(pid, signal.SIGKILL)


def test_exit_description() -> None:
    assert workers.exit_description(3) == "exit code 3"
    assert workers.exit_description(-11) == "exit code -11: SIGSEGV"
    assert workers.exit_description(-9) == "exit code -9: SIGKILL (out of memory?)"
    assert workers.exit_description(None) == "exit code unknown"


def _pool(jobs: list[Any], fn: Any, **kwargs: Any) -> list[Any]:
    results: list[Any] = []
    workers.run_jobs(jobs, fn, results.append, lambda job, msg: ("error", job, msg), **kwargs)
    return results


def test_pool_turns_a_raising_job_or_one_that_does_not_pickle_into_its_error() -> None:
    results = _pool([4.0, -1.0, lambda: 0, 9.0], math.sqrt, workers=1)
    assert results[:1] + results[2:] == [2.0, ("error", -1.0, "ValueError: math domain error"),
                                         3.0]
    assert results[1][0] == "error" and results[1][2].startswith("job not sent: ")
    assert not mp.active_children()


def test_pool_stops_when_a_worker_cannot_start(monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.raises(ArenaError, match=r"died while starting \(exit code 5\).*workers 0"):
        _pool([1.0], math.sqrt, workers=1, initializer=os._exit, initargs=(5,))
    monkeypatch.setattr(workers, "STARTUP_TIMEOUT", 0.5)
    with pytest.raises(ArenaError, match=r"did not start within 0\.5 s"):
        _pool([1.0], math.sqrt, workers=1, initializer=time.sleep, initargs=(3600,))
    assert not mp.active_children()


def test_workers_run_their_numeric_libraries_on_one_thread_each(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    monkeypatch.setenv("NUMBA_NUM_THREADS", "3")  # what the user set stays
    before = dict(os.environ)
    names = ["OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "NUMBA_NUM_THREADS"]
    got = _pool(names, os.getenv, workers=1)
    assert got[0] == "1" and got[2] == "3"
    assert got[1] == os.environ.get("OMP_NUM_THREADS", "1")
    assert dict(os.environ) == before  # set for the worker only
