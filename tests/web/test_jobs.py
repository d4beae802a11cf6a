"""The runs manager: ``arena run`` and ``arena bench`` jobs started, watched, cancelled, resumed
and read back after a restart, through :class:`JobManager` and through the API.

Jobs are real detached processes: every test's finalizer kills their process groups. Waits are
bounded but generous (a loaded two-core CI machine); nothing asserts on timing.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import time

import pytest
from fastapi.testclient import TestClient

from arena.eval.store import load_rows
from arena.web.job_file import JOB_FILE, JobRecord, create_job, read_job
from arena.web.job_requests import BenchRequest, JobError, RunRequest
from arena.web.jobs import JobConflict, JobManager
from arena.web.server import create_app
from arena.web.store import NotFound, RunStore
from tests.web.browser_kit import kill_jobs

#: Longest wait for a job to reach a state (s).
WAIT_S = 300.0


@pytest.fixture
def root(tmp_path):
    folder = tmp_path / "runs"
    folder.mkdir()
    yield folder
    kill_jobs(folder)


@pytest.fixture
def manager(root):
    return JobManager(root, kill_after=20.0)


def wait_for(manager: JobManager, name: str, *states: str, until=None, timeout: float = WAIT_S):
    """The job's status once it is in one of ``states`` (and ``until(status)`` holds)."""
    deadline = time.monotonic() + timeout
    status = manager.status(name)
    while time.monotonic() < deadline:
        status = manager.status(name)
        if status.state in states and (until is None or until(status)):
            return status
        time.sleep(0.2)
    raise AssertionError(f"job {name} stayed {status.state} ({status.done}/{status.planned}); "
                         f"log: {manager.log(name)[-5:]}")


def test_a_run_job_finishes_and_its_run_is_in_the_store(manager, root):
    started = manager.start(RunRequest(name="tiny", episodes=2, seed=3))
    assert started.state == "running" and started.planned == 2
    status = wait_for(manager, "tiny", "done", "failed")
    assert status.state == "done", status.reason
    assert (status.done, status.planned, status.returncode) == (2, 2, 0)
    info = RunStore(root).info("tiny")
    assert (info.kind, info.episodes) == ("run", 2)
    assert len(RunStore(root).results("tiny")) == 2
    assert any("summary.csv" in line for line in manager.log("tiny"))
    assert [j.name for j in manager.jobs()] == ["tiny"]


def test_a_run_job_through_the_api(root):
    client = TestClient(create_app(root, pages=False))
    answer = client.post("/api/jobs", json={"kind": "run", "name": "api_run", "episodes": 2,
                                            "seed": 1})
    assert answer.status_code == 201, answer.text
    assert answer.json()["state"] == "running"
    deadline = time.monotonic() + WAIT_S
    job = answer.json()
    while job["state"] == "running" and time.monotonic() < deadline:
        time.sleep(0.2)
        job = client.get("/api/jobs/api_run").json()
    assert job["state"] == "done", job
    assert (job["done"], job["planned"]) == (2, 2)
    assert isinstance(job["log"], list) and job["log"]
    assert [j["name"] for j in client.get("/api/jobs").json()] == ["api_run"]
    runs = client.get("/api/runs").json()
    assert [(r["name"], r["kind"], r["episodes"]) for r in runs] == [("api_run", "run", 2)]
    assert len(client.get("/api/runs/api_run").json()["results"]) == 2
    assert client.post("/api/jobs/api_run/cancel").status_code == 409
    assert client.post("/api/jobs/api_run/resume").status_code == 409


def test_a_cancelled_benchmark_resumes_with_every_episode_once(manager, root):
    # quick × basic at scale 0.3: 3 + 3 + 3 episodes (the corridor stage drops), one planner
    manager.start(BenchRequest(name="bench", suite="quick", contest="basic", scale=0.3))
    running = wait_for(manager, "bench", "running", "done", "failed",
                       until=lambda s: s.done >= 1 or s.state != "running")
    assert running.state == "running" and running.planned == 9
    manager.cancel("bench")
    cancelled = wait_for(manager, "bench", "cancelled", "done", "failed")
    assert cancelled.state == "cancelled", cancelled.reason
    assert cancelled.done < cancelled.planned
    with pytest.raises(JobConflict, match="only a running job"):
        manager.cancel("bench")
    resumed = manager.resume("bench")
    assert resumed.state == "running" and resumed.attempts == 2
    assert "--resume" in resumed.argv
    done = wait_for(manager, "bench", "done", "failed")
    assert done.state == "done", done.reason
    assert done.done == done.planned == 9
    rows = load_rows(root / "bench")
    keys = [(r["contestant"], r["stage"], r["episode"]) for r in rows]
    assert len(keys) == len(set(keys)) == 9
    assert any(line.startswith("--- resumed") for line in manager.log("bench", 1000))


def test_a_cancelled_run_resumes_to_the_summary_of_an_uninterrupted_run(manager, root):
    manager.start(RunRequest(name="whole", episodes=6, seed=2))
    manager.start(RunRequest(name="parts", episodes=6, seed=2))
    wait_for(manager, "parts", "running", "done", until=lambda s: s.done >= 1)
    with contextlib.suppress(JobConflict):  # it may have finished: then it resumes nothing
        manager.cancel("parts")
    first = wait_for(manager, "parts", "cancelled", "done")
    if first.state == "cancelled":
        manager.resume("parts")
    assert wait_for(manager, "parts", "done", "failed").state == "done"
    assert wait_for(manager, "whole", "done", "failed").state == "done"

    def figures(name: str) -> list[dict[str, str]]:
        timing = ("wall_time", "control_ms_mean", "control_ms_p95")
        return [{k: repr(v) for k, v in row.items() if k not in timing}  # repr: nan == nan
                for row in RunStore(root).results(name)]

    assert len(figures("parts")) == 6
    assert figures("parts") == figures("whole")


def test_a_new_manager_sees_a_running_job_and_then_its_end(root):
    first = JobManager(root)
    first.start(RunRequest(name="long", episodes=30))
    restarted = JobManager(root)  # the web server started again: it knows only the folders
    assert restarted.status("long").state == "running"
    status = wait_for(restarted, "long", "done", "failed")
    assert status.state == "done", status.reason
    assert status.done == status.planned == 30


def test_a_job_whose_wrapper_is_killed_is_failed_crashed(manager, root):
    manager.start(RunRequest(name="victim", episodes=200))  # runs long after the check
    wait_for(manager, "victim", "running", until=lambda s: s.done >= 1)  # its command runs
    pid = read_job(root / "victim").pid
    assert pid is not None
    os.kill(pid, signal.SIGKILL)  # the wrapper only: its command runs on, orphaned
    status = wait_for(JobManager(root), "victim", "failed")
    assert status.reason.startswith("crashed")
    with pytest.raises(JobConflict, match="still run"):
        manager.resume("victim")  # its orphaned command still writes into the folder


def test_a_job_whose_command_fails_is_failed_with_the_reason(manager, root, tmp_path):
    plugin = tmp_path / "boom.py"
    plugin.write_text('raise RuntimeError("boom at import")\n')
    (root / "boom").mkdir()
    manager.launch("boom", "run", ["run", "-n", "1", "--no-video", "--plugin", str(plugin)])
    status = wait_for(manager, "boom", "failed", "done")
    assert status.state == "failed" and status.returncode == 2
    assert "boom at import" in status.reason and "\n" not in status.reason


def test_states_from_the_job_file(root):
    """Exit statuses and dead or foreign pids, without processes of our own."""
    manager = JobManager(root)

    def job(name: str, **fields) -> str:
        (root / name).mkdir()
        create_job(root / name, JobRecord(kind="run", title="t", argv=["x"], planned=1,
                                          started=1.0, **fields))  # long ago
        (root / name / "job.log").write_text("first\nlast words\n\n")
        status = manager.status(name)
        return f"{status.state}: {status.reason}"

    assert job("ok", returncode=0) == "done: "
    assert job("bad", returncode=3) == "failed: last words"
    assert job("killed", returncode=-9).startswith("failed: killed by SIGKILL")
    assert job("stopped", returncode=-15, cancelled=True) == "cancelled: cancelled"
    assert job("lost").startswith("failed: crashed")  # no pid, long ago: never started
    # a pid that lives but is not this job's wrapper (pid reuse): the wrapper is gone
    assert job("reused", pid=os.getpid()).startswith("failed: crashed")
    assert job("forced", pid=os.getpid(), cancelled=True).startswith("cancelled")
    (root / "garbled").mkdir()
    (root / "garbled" / JOB_FILE).write_text("{not json")
    assert manager.status("garbled").state == "failed"


def test_a_job_folder_without_results_is_a_run_of_the_store(root):
    (root / "fresh").mkdir()
    create_job(root / "fresh", JobRecord(kind="bench", title="quick × basic", argv=["x"]))
    info = RunStore(root).info("fresh")
    assert (info.kind, info.episodes, info.title) == ("bench", 0, "quick × basic")
    assert [r.name for r in RunStore(root).runs()] == ["fresh"]
    assert RunStore(root).results("fresh") == []


BAD = [
    ({"kind": "walk"}, "kind"),
    ({"kind": "run", "robot": "burgr"}, "did you mean 'burger'"),
    ({"kind": "run", "episodes": 0}, "episodes"),
    ({"kind": "run", "map": "atlantis"}, "no world"),
    ({"kind": "run", "config": "nowhere.yaml"}, "config"),
    ({"kind": "run", "scenario": "nope"}, "scenario"),
    ({"kind": "run", "speed": 3}, "unknown key"),
    ({"kind": "bench", "suite": "quik"}, "did you mean 'quick'"),
    ({"kind": "bench", "contest": "nobody"}, "contest"),
    ({"kind": "bench", "scale": 0.001}, "leaves no episode"),
    ({"kind": "bench", "workers": 0}, "workers"),
    ({"kind": "run", "name": "../escape"}, "no plain folder name"),
    ({"kind": "run", "name": "/etc"}, "no plain folder name"),
    ([1, 2], "JSON object"),
]


@pytest.mark.parametrize(("body", "words"), BAD)
def test_bad_input_is_one_line_and_starts_nothing(root, body, words):
    client = TestClient(create_app(root, pages=False))
    answer = client.post("/api/jobs", json=body)
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"]
    assert isinstance(detail, str) and "\n" not in detail and words in detail
    assert list(root.iterdir()) == []


def test_a_body_that_is_no_json_is_422(root):
    client = TestClient(create_app(root, pages=False))
    answer = client.post("/api/jobs", content=b"{kind: run",
                         headers={"content-type": "application/json"})
    assert answer.status_code == 422 and "JSON" in answer.json()["detail"]


def test_an_existing_folder_is_never_clobbered(root, manager):
    (root / "taken").mkdir()
    (root / "taken" / "mine.txt").write_text("keep")
    with pytest.raises(JobError, match="already exists"):
        manager.start(RunRequest(name="taken"))
    assert [p.name for p in (root / "taken").iterdir()] == ["mine.txt"]


@pytest.mark.parametrize("name", ["..", "../runs", "a/b", "/etc/passwd", "", ".hidden"])
def test_job_names_that_leave_the_store_are_refused(root, manager, name):
    (root.parent / "outside").mkdir()
    create_job(root.parent / "outside", JobRecord(kind="run", title="t", argv=["x"]))
    for call in (manager.status, manager.cancel, manager.resume, manager.log):
        with pytest.raises(NotFound):
            call(name)
    with pytest.raises(NotFound):
        manager.status("../outside")


@pytest.mark.parametrize("name", ["..", "..%2Foutside", "%2e%2e%2Foutside", "%2Fetc%2Fpasswd"])
def test_job_urls_that_leave_the_store_are_404(root, name):
    (root.parent / "outside").mkdir()
    create_job(root.parent / "outside", JobRecord(kind="run", title="t", argv=["x"]))
    client = TestClient(create_app(root, pages=False))
    for method, path in (("get", ""), ("post", "/cancel"), ("post", "/resume")):
        answer = getattr(client, method)(f"/api/jobs/{name}{path}")
        assert answer.status_code == 404, (name, path, answer.text)


def test_the_lists_the_form_offers(root):
    client = TestClient(create_app(root, pages=False))
    assert "quick" in [s["name"] for s in client.get("/api/suites").json()]
    assert "basic" in [c["name"] for c in client.get("/api/contests").json()]
    assert "jackal" in [r["name"] for r in client.get("/api/robots").json()]
    assert "corridor" in [w["name"] for w in client.get("/api/worlds").json()]
    schema = client.get("/openapi.json").json()
    assert "/api/jobs/{name}/resume" in schema["paths"]
    body = schema["paths"]["/api/jobs"]["post"]["requestBody"]["content"]["application/json"]
    assert len(body["schema"]["oneOf"]) == 2
    json.dumps(schema)  # a valid document


def test_a_saved_scenario_brings_its_map_and_live_jobs_start_no_web_app(root):
    from arena.web.job_requests import command

    (root / "_scenarios").mkdir()
    scenario = {"robots": [{"start": [-10.0, 3.5, 0.0], "goal": [8.0, 0.0, 0.0]}],
                "obstacles": {"static": [], "interactive": [], "dynamic": []},
                "map": "small_office"}
    (root / "_scenarios" / "mine.json").write_text(json.dumps(scenario))
    args = command(RunRequest(saved_scenario="mine", live=True), root).args
    assert args[args.index("--map") + 1] == "small_office"
    assert args[args.index("--scenario") + 1] == str(root.resolve() / "_scenarios" / "mine.json")
    assert args[-2:] == ["--live", "--no-web"]  # the app that starts it shows it
    bench = command(BenchRequest(suite="quick", contest="basic", scale=0.1, live=True)).args
    assert bench[-2:] == ["--live", "--no-web"]
    for request, words in ((RunRequest(saved_scenario="nope"), "no scenario 'nope'"),
                           (RunRequest(saved_scenario="../mine"), "not a plain scenario name"),
                           (RunRequest(saved_scenario="mine", map="corridor"), "drop map")):
        with pytest.raises(JobError, match=words):
            command(request, root)
    scenario["map"] = "_maps/gone"
    (root / "_scenarios" / "mine.json").write_text(json.dumps(scenario))
    with pytest.raises(JobError, match="its map '_maps/gone'"):
        command(RunRequest(saved_scenario="mine"), root)
