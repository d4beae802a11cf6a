"""The live channel: scenes and frames of a real episode reach a client; pause, steps, speed,
goals; a slow or rude client never blocks the run."""

from __future__ import annotations

import json
import threading

import numpy as np
import pytest

from arena.config import load_config
from arena.core.types import Pose2D
from arena.experiment import run_experiment
from arena.live import (
    LIVE_FILE,
    LiveClient,
    LiveControl,
    LiveHook,
    LiveServer,
    frame_json,
    scene_json,
)
from arena.live.frame import scan_points
from arena.sensors.spec import LidarSpec
from arena.tasks.modules.interactive import CommandError, InteractiveModule

OVERRIDES = ["episodes=1", "output.video=false", "seed=3"]


class ListSink:
    """A sink that keeps everything (every frame wanted)."""

    def __init__(self) -> None:
        self.scenes, self.frames, self.last = [], [], []

    def wants_frame(self, time: float) -> bool:
        return True

    def scene(self, scene) -> None:
        self.scenes.append(scene)

    def frame(self, frame, *, last: bool = False) -> None:
        self.frames.append(frame)
        self.last.append(last)


@pytest.fixture(scope="module")
def watched(tmp_path_factory):
    """One default episode with a sink that takes every frame, and the same run unwatched."""
    cfg = load_config(None, OVERRIDES)
    sink = ListSink()
    _, watched = run_experiment(cfg, tmp_path_factory.mktemp("w"), hooks=[LiveHook([sink])])
    _, plain = run_experiment(cfg, tmp_path_factory.mktemp("p"))
    return sink, watched[0], plain[0]


def test_frames_follow_the_episode_and_change_nothing(watched):
    sink, res, plain = watched
    assert len(sink.scenes) == 1
    # the first state, every step, then the last state again with its outcome
    assert len(sink.frames) == res.steps + 2
    assert sink.last == [False] * (res.steps + 1) + [True]
    assert [f.step for f in sink.frames[:-1]] == list(range(res.steps + 1))
    assert sink.frames[-1].outcome == res.outcome and sink.frames[0].outcome is None
    np.testing.assert_array_equal(np.array([f.poses[0] for f in sink.frames[:-1]]),
                                  res.record.pose)
    # watching changes nothing
    np.testing.assert_array_equal(res.record.pose, plain.record.pose)
    people = sink.frames[10].people
    rows = res.record.pedestrians_at(10)
    np.testing.assert_allclose(people.positions, res.record.ped_position[rows])


def test_frame_content(watched):
    sink, res, _ = watched
    scene, frame = sink.scenes[0], sink.frames[5]
    assert scene.map_name == res.map and scene.lidar is not None
    assert scene.footprints[0].shape[1] == 2
    assert frame.plan.shape[1] == 2 and len(frame.plan) > 1
    np.testing.assert_allclose(frame.goal[:2], res.goal[:2])
    # the lidar's hit points lie where the ranges say, from the robot
    d = np.hypot(*(frame.scan_points - frame.poses[0, :2]).T)
    hits = frame.scan[np.isfinite(frame.scan) & (frame.scan < scene.lidar.range_max - 1e-6)]
    assert len(frame.scan_points) == len(hits)
    mount = np.hypot(*scene.lidar.mount[:2])
    assert np.all(np.abs(np.sort(d) - np.sort(hits)) <= mount + 1e-9)
    assert frame.groups.shape == (len(frame.people),)
    assert np.any(frame.groups >= 0)  # the default crowd forms groups


def test_json_is_compact_and_complete(watched):
    sink, _, _ = watched
    s = scene_json(sink.scenes[0])
    f = frame_json(sink.frames[5])
    json.dumps(s), json.dumps(f)  # JSON-ready
    assert s["type"] == "scene" and s["map"]["png"] and s["states"][1] == "walking"
    assert f["type"] == "frame" and len(f["people"]["x"]) == len(sink.frames[5].people)
    assert set(f["people"]) == {"id", "x", "y", "heading", "radius", "kind", "state", "group"}
    assert all(round(v, 3) == v for v in f["people"]["x"])


def test_scan_points_geometry():
    lidar = LidarSpec(angle_min=0.0, angle_max=np.pi / 2, num_beams=2, range_max=5.0,
                      mount=(1.0, 0.0, 0.0))
    pts = scan_points(np.array([2.0, 5.0]), np.array([1.0, 1.0, np.pi / 2]), lidar)
    # the lidar sits 1 m ahead of a robot facing +y; beam 0 looks along +y; beam 1 is a miss
    np.testing.assert_allclose(pts, [[1.0, 4.0]])


class FakeClock:
    def __init__(self) -> None:
        self.now, self.slept = 0.0, []

    def __call__(self) -> float:
        return self.now

    def sleep(self, s: float) -> None:
        self.slept.append(s)
        self.now += s


def test_control_paces_to_the_speed():
    clock = FakeClock()
    ctl = LiveControl(speed=2.0, clock=clock, sleep=clock.sleep)
    ctl.wait(0.0)
    ctl.wait(1.0)  # 1 s simulated at 2x: 0.5 s of wall time
    assert clock.slept == [pytest.approx(0.5)]
    ctl.set_speed(0)
    ctl.wait(5.0)
    assert len(clock.slept) == 1  # as fast as it goes
    with pytest.raises(CommandError, match="speed"):
        ctl.apply({"cmd": "speed", "value": -1})
    with pytest.raises(CommandError, match="unknown command"):
        ctl.apply({"cmd": "fly"})
    with pytest.raises(CommandError, match="no goals"):
        ctl.apply({"cmd": "goal", "x": 1.0, "y": 2.0})


def test_a_new_episode_is_paced_from_its_own_start():
    clock = FakeClock()
    ctl = LiveControl(speed=1.0, clock=clock, sleep=clock.sleep)
    for t in (0.0, 1.0, 2.0):  # episode 0: 2 s at real time
        ctl.wait(t)
    clock.now += 3.0  # the episode's end and the next one's set-up take wall time
    ctl.wait(0.0)  # episode 1's clock starts again at 0
    ctl.wait(1.0)  # ... and its first second takes one second, not none
    assert clock.slept == [pytest.approx(1.0)] * 3


def test_pause_holds_the_tick_and_steps_release_one():
    ctl = LiveControl(speed=0)
    statuses = []
    ctl.listeners.append(statuses.append)
    ctl.pause()
    passed = []

    def sim() -> None:
        for k in range(3):
            ctl.wait(float(k))
            passed.append(k)

    t = threading.Thread(target=sim, daemon=True)
    t.start()
    t.join(0.3)
    assert passed == []  # paused
    ctl.step()
    for _ in range(100):
        if passed:
            break
        t.join(0.02)
    assert passed == [0]
    ctl.resume()
    t.join(5)
    assert passed == [0, 1, 2]
    assert [s["paused"] for s in statuses] == [True, True, False]


def test_goals_go_through_the_interactive_module():
    ui = InteractiveModule()
    ctl = LiveControl(interactive=ui)
    ctl.apply({"cmd": "goal", "x": 1.5, "y": -2.0})
    ctl.apply({"cmd": "teleport", "x": 0.5, "y": 0.5, "theta": 1.0})
    cmds = ui.poll(0.0)
    assert [(c.kind, c.pose) for c in cmds] == [("goal", Pose2D(1.5, -2.0, 0.0)),
                                                 ("teleport", Pose2D(0.5, 0.5, 1.0))]
    with pytest.raises(CommandError, match="finite number"):
        ctl.apply({"cmd": "goal", "x": "left", "y": 0})


def test_server_serves_a_run_to_a_client(tmp_path):
    cfg = load_config(None, OVERRIDES)
    ctl = LiveControl(speed=0)
    with LiveServer(control=ctl, rate=1e6) as server:
        server.write_info(tmp_path)
        info = json.loads((tmp_path / LIVE_FILE).read_text())
        assert info["port"] == server.address[1] and info["host"] == "127.0.0.1"
        assert (tmp_path / LIVE_FILE).stat().st_mode & 0o077 == 0  # the token stays private
        got: list[dict] = []
        with LiveClient.from_run(tmp_path) as client:
            assert client.receive()["type"] == "status"
            for _ in range(200):  # the server counts the client once it has read the token
                if server.clients:
                    break
                threading.Event().wait(0.01)
            assert server.clients == 1
            _, res = run_experiment(cfg, tmp_path / "run", hooks=[LiveHook([server], ctl)])
            for m in client.messages():
                got.append(m)
                if m["type"] == "frame" and m["outcome"]:
                    break
            client.send({"cmd": "speed", "value": "fast"})
            err = client.receive()
            assert err["type"] == "error" and "value" in err["message"]
            client.send({"cmd": "pause"})
            assert client.receive() == {"type": "status", "paused": True, "speed": 0.0,
                                        "interactive": False}
    kinds = [m["type"] for m in got]
    assert kinds[0] == "scene" and kinds.count("scene") == 1
    frames = [m for m in got if m["type"] == "frame"]
    assert frames[-1]["outcome"] == res[0].outcome
    steps = [m["step"] for m in frames]
    assert steps == sorted(steps) and steps[-1] == res[0].steps  # newest frames, in order


def test_a_wrong_token_is_shut_out():
    with LiveServer() as server:
        host, port = server.address
        with LiveClient(host, port, "not-the-token", timeout=5) as client, \
                pytest.raises(ConnectionError):
            client.receive()
        assert server.clients == 0


def test_no_viewer_no_frames(tmp_path):
    cfg = load_config(None, OVERRIDES)
    with LiveServer() as server:
        hook = LiveHook([server])
        run_experiment(cfg, tmp_path, hooks=[hook])
        # only the forced ones: the first and the last frame
        assert hook.frames == 2 and server.frames_sent == 0
