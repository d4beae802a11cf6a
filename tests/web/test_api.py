"""The web app's API on a real run store: runs, results, files (path traversal refused),
replays, the live socket, and the token gate."""

from __future__ import annotations

import json
import threading

import pytest
from fastapi.testclient import TestClient

from arena.config import load_config
from arena.experiment import run_experiment
from arena.live import LiveControl, LiveHook, LiveServer
from arena.web.server import TokenGate, check_host, create_app
from arena.web.store import NotFound, RunStore

OVERRIDES = ["episodes=1", "output.video=false", "seed=2"]


@pytest.fixture(scope="module")
def store_root(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    run_experiment(load_config(None, OVERRIDES), root / "first")
    (root / "not_a_run").mkdir()
    (root / "secret.txt").write_text("outside every run")
    return root


@pytest.fixture(scope="module")
def client(store_root):
    return TestClient(create_app(store_root, pages=False))


def test_runs_and_results(client):
    runs = client.get("/api/runs").json()
    assert [r["name"] for r in runs] == ["first"]
    assert runs[0]["kind"] == "run" and runs[0]["episodes"] == 1 and not runs[0]["live"]
    run = client.get("/api/runs/first").json()
    assert run["records"] == ["episode_000/episode.parquet"]
    row = run["results"][0]
    assert row["record"] == "episode_000/episode.parquet" and row["outcome"] in (
        "success", "timeout", "collision")
    assert isinstance(row["time"], float)
    assert client.get("/api/health").json()["ok"] is True
    assert "/api/runs/{run}/replay" in client.get("/openapi.json").json()["paths"]


@pytest.mark.parametrize("path", [
    "../secret.txt", "..%2Fsecret.txt", "%2Fetc%2Fpasswd", "episode_000/../../secret.txt",
    "nothing.json",
])
def test_files_stay_inside_their_run(client, store_root, path):
    # the HTTP client may normalise a plain ../ away (then no route matches): 404 either way
    assert client.get(f"/api/runs/first/files/{path}").status_code == 404
    raw = path.replace("%2F", "/")
    with pytest.raises(NotFound, match="no file"):
        RunStore(store_root).file("first", raw)


@pytest.mark.parametrize("name", ["..", "not_a_run", "nope", "first%2F..", ".hidden"])
def test_unknown_runs(client, name):
    r = client.get(f"/api/runs/{name}")
    assert r.status_code == 404


def test_store_refuses_symlinks_out(store_root, tmp_path):
    (tmp_path / "outside.txt").write_text("x")
    link = store_root / "first" / "link.txt"
    link.symlink_to(tmp_path / "outside.txt")
    try:
        with pytest.raises(NotFound):
            RunStore(store_root).file("first", "link.txt")
    finally:
        link.unlink()


def test_a_file_is_served(client):
    r = client.get("/api/runs/first/files/episode_000/episode.json")
    assert r.status_code == 200 and r.json()["index"] == 0


def test_replay_is_the_recorded_episode(client):
    r = client.get("/api/runs/first/replay", params={"record": "episode_000/episode.parquet"})
    data = r.json()
    assert data["matches_record"] is True
    steps = client.get("/api/runs/first/files/episode_000/episode.json").json()["steps"]
    assert len(data["frames"]) == steps + 1
    assert data["frames"][-1]["outcome"] == data["outcome"]
    assert data["scene"]["type"] == "scene"
    bad = client.get("/api/runs/first/replay", params={"record": "episode_000/episode.json"})
    assert bad.status_code == 404


def test_live_socket_relays_frames_and_commands(store_root, tmp_path):
    cfg = load_config(None, OVERRIDES)
    control = LiveControl(speed=0)
    control.pause()
    server = LiveServer(control=control, rate=1000)
    run_dir = store_root / "watched"
    hook = LiveHook([server], control)
    done = threading.Event()

    def simulate() -> None:
        run_experiment(cfg, run_dir, hooks=[hook], on_start=server.write_info)
        done.set()

    thread = threading.Thread(target=simulate, daemon=True)
    thread.start()
    try:
        for _ in range(500):
            if (run_dir / "live.json").is_file():
                break
            threading.Event().wait(0.01)
        client = TestClient(create_app(store_root, pages=False))
        assert client.get("/api/runs/watched").json()["info"]["live"] is True
        with client.websocket_connect("/api/runs/watched/live") as ws:
            assert json.loads(ws.receive_text())["paused"] is True
            kinds = [json.loads(ws.receive_text())["type"] for _ in range(2)]
            assert kinds == ["scene", "frame"]
            ws.send_text("not json")
            assert "JSON object" in json.loads(ws.receive_text())["message"]
            ws.send_text(json.dumps({"cmd": "goal", "x": 1, "y": 1}))
            assert "no goals" in json.loads(ws.receive_text())["message"]
            ws.send_text(json.dumps({"cmd": "resume"}))
            outcome = None
            for _ in range(10000):
                m = json.loads(ws.receive_text())
                if m["type"] == "frame" and m["outcome"]:
                    outcome = m["outcome"]
                    break
            assert outcome is not None
        assert done.wait(30)
    finally:
        control.close()
        server.close()
        thread.join(30)


def test_live_socket_of_a_finished_run(client):
    with client.websocket_connect("/api/runs/first/live") as ws:
        m = json.loads(ws.receive_text())
        assert m["type"] == "closed" and "not running" in m["message"]


def test_token_gate(store_root):
    app = create_app(store_root, pages=False, token="s3cret")
    client = TestClient(app)
    assert client.get("/api/runs").status_code == 401
    assert client.get("/api/runs", headers={"Authorization": "Bearer wrong"}).status_code == 401
    assert client.get("/api/runs", headers={"Authorization": "Bearer s3cret"}).status_code == 200
    r = client.get("/api/health?token=s3cret")
    assert r.status_code == 200 and "arena_token=s3cret" in r.headers["set-cookie"]
    assert client.get("/api/runs").status_code == 200  # the cookie now
    assert any(isinstance(m.cls, type) and m.cls is TokenGate for m in app.user_middleware)


def test_hosts_other_than_loopback_need_a_token():
    assert check_host("127.0.0.1", None) is None
    assert check_host("0.0.0.0", None)  # a generated one
    assert check_host("0.0.0.0", "mine") == "mine"


def test_missing_web_extra_is_one_line(monkeypatch, capsys, tmp_path):
    import sys

    from tests.cli_kit import run_cli

    monkeypatch.setitem(sys.modules, "nicegui", None)  # as if not installed
    code, _, err = run_cli(monkeypatch, capsys, "web", "--root", str(tmp_path))
    assert code == 2 and err.count("\n") == 1 and "pip install 'arena[web]'" in err
    code, _, err = run_cli(monkeypatch, capsys, "run", "-n", "1", "--no-video", "--live",
                           "-o", str(tmp_path / "r"))
    assert code == 2 and "pip install 'arena[web]'" in err
    assert not (tmp_path / "r").exists()  # refused before the run began
