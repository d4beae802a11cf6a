"""``arena export rosbag2`` / ``rosbag``: read the bags back with rosbags' readers and check
topics, types, counts, times and values against the recorded episode."""

from __future__ import annotations

import sys
from collections import Counter

import numpy as np
import pytest

pytest.importorskip("rosbags")

from rosbags.rosbag1 import Reader as Reader1
from rosbags.rosbag2 import Reader as Reader2
from ruamel.yaml import YAML

from arena.config import load_config
from arena.core.errors import ConfigError
from arena.eval.io import load_record
from arena.eval.replay import resimulate
from arena.experiment import run_experiment
from arena.export.rosbag import export_rosbag
from arena.live.hook import LiveHook
from arena.ros.bag import rosbags_module, typestore
from arena.ros.topics import topic_table
from tests.cli_kit import run_cli


class _SceneOnly:
    """A sink keeping the scene (to compare the bag's map and table with)."""

    scene_seen = None

    def wants_frame(self, time):
        return False

    def scene(self, scene):
        self.scene_seen = scene

    def frame(self, frame, *, last=False):
        pass


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    run_experiment(load_config(None, ["episodes=1", "output.video=false", "seed=5"]), out)
    return out


@pytest.fixture(scope="module")
def bags(run_dir, tmp_path_factory):
    base = tmp_path_factory.mktemp("bags")
    return {fl: export_rosbag(run_dir, base / fl, flavour=fl)[0] for fl in ("ros2", "ros1")}


@pytest.fixture(scope="module")
def scene(bags):
    sink = _SceneOnly()
    resimulate(load_record(bags["ros2"].record), None, hooks=[LiveHook([sink])])
    return sink.scene_seen


def _read(item, flavour):
    """``(connections, [(topic, time ns, message)])`` of a bag, decoded."""
    store = typestore(flavour)
    reader = Reader2(item.path) if flavour == "ros2" else Reader1(item.path)
    with reader:
        conns = {c.topic: c for c in reader.connections}
        decode = store.deserialize_cdr if flavour == "ros2" else store.deserialize_ros1
        msgs = [(c.topic, t, decode(raw, c.msgtype)) for c, t, raw in reader.messages()]
    return conns, msgs


def _ns(stamp):
    return stamp.sec * 1_000_000_000 + stamp.nanosec


@pytest.mark.parametrize("flavour", ["ros2", "ros1"])
def test_topics_types_counts_and_times(bags, scene, flavour):
    item = bags[flavour]
    record = load_record(item.record)
    assert item.matches_record and item.steps == record.steps - 1
    conns, msgs = _read(item, flavour)
    table = topic_table(scene, clock=False)
    assert {t: c.msgtype for t, c in conns.items()} == {t.name: t.msgtype for t in table}
    assert set(conns) == {"/tf", "/tf_static", "/map", "/odom", "/scan", "/people/markers",
                          "/people/states", "/plan", "/local_plan", "/goal_pose", "/cmd_vel"}
    counts = Counter(topic for topic, _, _ in msgs)
    for t in table:
        # the default lidar runs at 10 Hz, the step is 0.1 s: a scan every step
        assert counts[t.name] == (1 if t.latched else record.steps), t.name
    assert len(msgs) == item.messages
    times = np.array([t for _, t, _ in msgs])
    assert np.all(np.diff(times) >= 0)  # the reader returns them in time order
    sim_ns = np.round(record.time * 1e9).astype(np.int64)
    for topic in ("/tf", "/odom", "/scan", "/people/states"):
        rec_t = [t for top, t, _ in msgs if top == topic]
        np.testing.assert_array_equal(rec_t, sim_ns, err_msg=topic)
        stamps = [_ns(m.transforms[0].header.stamp if topic == "/tf" else m.header.stamp)
                  for top, _, m in msgs if top == topic]
        np.testing.assert_array_equal(stamps, sim_ns, err_msg=topic)


@pytest.mark.parametrize("flavour", ["ros2", "ros1"])
def test_values_equal_the_record(bags, scene, flavour):
    item = bags[flavour]
    record = load_record(item.record)
    _, msgs = _read(item, flavour)

    def of(topic):
        return [m for t, _, m in msgs if t == topic]

    odom = of("/odom")
    xy = np.array([[o.pose.pose.position.x, o.pose.pose.position.y] for o in odom])
    np.testing.assert_allclose(xy, record.pose[:, :2])
    yaw = np.array([2 * np.arctan2(o.pose.pose.orientation.z, o.pose.pose.orientation.w)
                    for o in odom])
    np.testing.assert_allclose(np.angle(np.exp(1j * (yaw - record.pose[:, 2]))), 0, atol=1e-9)
    assert odom[0].header.frame_id == "odom" and odom[0].child_frame_id == "base_link"
    np.testing.assert_allclose([o.twist.twist.linear.x for o in odom], record.velocity[:, 0])
    tf = of("/tf")
    np.testing.assert_allclose([m.transforms[0].transform.translation.x for m in tf],
                               record.pose[:, 0])
    cmd = of("/cmd_vel")
    np.testing.assert_allclose([[c.linear.x, c.linear.y, c.angular.z] for c in cmd],
                               record.command)
    assert np.abs(record.command[:, 0]).max() > 0.1  # the robot drove
    scans = of("/scan")
    spec = scene.lidar
    s = scans[5]
    assert s.header.frame_id == "laser" and len(s.ranges) == spec.num_beams
    assert s.angle_min == pytest.approx(spec.angle_min)
    assert s.angle_increment == pytest.approx(spec.angle_increment)
    assert s.range_max == pytest.approx(spec.range_max)
    np.testing.assert_allclose([np.min(m.ranges) for m in scans], record.min_range, rtol=1e-6)
    people = of("/people/states")
    markers = of("/people/markers")
    from arena.ros.messages import PEOPLE_DTYPE

    for row in (0, 7, record.steps - 1):
        rows = record.pedestrians_at(row)
        pts = np.frombuffer(people[row].data.tobytes(), dtype=PEOPLE_DTYPE)
        assert people[row].width == len(rows) == len(pts)
        assert [f.name for f in people[row].fields][:5] == ["x", "y", "z", "vx", "vy"]
        np.testing.assert_allclose(np.column_stack([pts["x"], pts["y"]]),
                                   record.ped_position[rows], atol=1e-5)
        np.testing.assert_allclose(np.column_stack([pts["vx"], pts["vy"]]),
                                   record.ped_velocity[rows], atol=1e-5)
        np.testing.assert_array_equal(pts["id"], record.ped_id[rows])
        cyl = [m for m in markers[row].markers if m.ns == "people"][1:]  # after DELETEALL
        assert markers[row].markers[0].action == 3
        np.testing.assert_allclose([[m.pose.position.x, m.pose.position.y] for m in cyl],
                                   record.ped_position[rows])
    plan = of("/plan")
    assert len(plan[1].poses) > 1 and plan[1].header.frame_id == "map"
    goal = of("/goal_pose")[0]
    np.testing.assert_allclose([goal.pose.position.x, goal.pose.position.y],
                               record.meta.goal[:2])


@pytest.mark.parametrize("flavour", ["ros2", "ros1"])
def test_map_and_tf_tree(bags, scene, flavour):
    _, msgs = _read(bags[flavour], flavour)
    grid = next(m for t, _, m in msgs if t == "/map")
    g = scene.grid
    assert grid.header.frame_id == "map"
    assert grid.info.resolution == pytest.approx(g.resolution)
    assert (grid.info.width, grid.info.height) == (g.width, g.height)
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == pytest.approx(g.origin)
    np.testing.assert_array_equal(np.asarray(grid.data).reshape(g.height, g.width), g.data)
    parent = {}
    for topic in ("/tf_static", "/tf"):
        first = next(m for t, _, m in msgs if t == topic)
        for tr in first.transforms:
            parent[tr.child_frame_id] = (tr.header.frame_id, tr.transform)
    chain, frame = [], "laser"
    while frame in parent:
        chain.append(frame)
        frame = parent[frame][0]
    assert [*chain, frame] == ["laser", "base_link", "odom", "map"]
    odom = parent["odom"][1]  # map → odom: the identity (no drift)
    assert (odom.translation.x, odom.translation.y, odom.rotation.w) == (0.0, 0.0, 1.0)
    laser = parent["laser"][1]
    assert laser.translation.x == pytest.approx(scene.lidar.mount[0])


def test_same_episode_gives_identical_bags(bags, run_dir, tmp_path):
    for flavour in ("ros2", "ros1"):
        again = export_rosbag(run_dir, tmp_path / flavour, flavour=flavour)[0]
        first = bags[flavour].path
        if flavour == "ros2":
            for name in ("episode.mcap", "metadata.yaml"):
                assert (first / name).read_bytes() == (again.path / name).read_bytes(), name
        else:
            assert first.read_bytes() == again.path.read_bytes()


def test_rosbag2_metadata_says_which_episode(bags):
    item = bags["ros2"]
    record = load_record(item.record)
    meta = YAML(typ="safe").load((item.path / "metadata.yaml").read_text())
    info = meta["rosbag2_bagfile_information"]
    assert info["storage_identifier"] == "mcap" and info["version"] == 8
    custom = info["custom_data"]
    assert custom["arena.episode"] == str(record.meta.episode)
    assert custom["arena.outcome"] == record.meta.outcome
    assert custom["arena.matches_record"] == "true"
    qos = {t["topic_metadata"]["name"]: t["topic_metadata"]["offered_qos_profiles"]
           for t in info["topics_with_message_count"]}
    for topic in ("/map", "/tf_static"):  # latched: transient local (1), keep last 1
        (profile,) = YAML(typ="safe").load(qos[topic])
        assert (profile["durability"], profile["depth"]) == (1, 1), topic
    assert qos["/odom"] == ""


def test_bad_runs_get_one_line(tmp_path, run_dir, monkeypatch):
    with pytest.raises(ConfigError, match="no such run folder"):
        export_rosbag(tmp_path / "nowhere")
    with pytest.raises(ConfigError, match="holds no episode records"):
        export_rosbag(tmp_path, flavour="ros1")
    with pytest.raises(ConfigError, match="matches 'x"):
        export_rosbag(run_dir, tmp_path / "o", only="x*")
    (tmp_path / "keep/episode_000/episode").mkdir(parents=True)
    (tmp_path / "keep/episode_000/episode/notes.txt").write_text("mine")
    with pytest.raises(ConfigError, match="not a ROS 2 bag"):
        export_rosbag(run_dir, tmp_path / "keep")
    assert (tmp_path / "keep/episode_000/episode/notes.txt").read_text() == "mine"
    monkeypatch.setitem(sys.modules, "rosbags", None)
    with pytest.raises(ConfigError, match=r"pip install 'arena\[rosbag\]'"):
        rosbags_module()


@pytest.mark.parametrize(("command", "written"), [
    ("rosbag2", "episode_000/episode/episode.mcap"), ("rosbag", "episode_000/episode.bag")])
def test_cli(monkeypatch, capsys, run_dir, tmp_path, command, written):
    for _ in range(2):  # a second export replaces the first
        code, out, err = run_cli(monkeypatch, capsys, "export", command, str(run_dir), "-o",
                                 str(tmp_path), "--only", "episode_000/*", "--clock")
        assert code == 0, err
        assert "1 episode(s) written" in out and (tmp_path / written).is_file()
    code, out, err = run_cli(monkeypatch, capsys, "export", command, str(tmp_path / "no"))
    assert code == 2 and err.count("\n") == 1 and "no such run folder" in err


def test_a_failed_episode_leaves_no_bag(run_dir, tmp_path, monkeypatch):
    import arena.export.rosbag as mod

    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(mod, "resimulate", broken)
    for flavour in ("ros2", "ros1"):
        with pytest.raises(RuntimeError, match="boom"):
            export_rosbag(run_dir, tmp_path / flavour, flavour=flavour)
        assert not [p for p in (tmp_path / flavour).rglob("*") if p.is_file()]
