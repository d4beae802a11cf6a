"""``arena export mcap``: read the files back and check schemas, topics, counts and times
against the recorded episode."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from arena.config import load_config
from arena.core.errors import ConfigError
from arena.eval.io import load_record
from arena.experiment import run_experiment
from arena.export.foxglove import SCENE_TOPICS, TOPICS
from arena.export.mcap import export_mcap
from tests.cli_kit import run_cli


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    cfg = load_config(None, ["episodes=2", "output.video=false", "seed=5"])
    run_experiment(cfg, out)
    return out


@pytest.fixture(scope="module")
def exported(run_dir, tmp_path_factory):
    return export_mcap(run_dir, tmp_path_factory.mktemp("mcap"))


def _read(path):
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
        messages = [(ch.topic, msg.log_time, dec)
                    for _, ch, msg, dec in reader.iter_decoded_messages()]
    return summary, metadata, messages


def test_schemas_topics_counts_and_times(exported, run_dir):
    assert [f.path.relative_to(f.path.parents[1]).as_posix() for f in exported] == [
        "episode_000/episode.mcap", "episode_001/episode.mcap"]
    for item in exported:
        record = load_record(item.record)
        assert item.matches_record and item.steps == record.steps - 1
        summary, metadata, messages = _read(item.path)
        schemas = {c.topic: (summary.schemas[c.schema_id].name,
                             summary.schemas[c.schema_id].encoding, c.message_encoding)
                   for c in summary.channels.values()}
        assert schemas == {t: (s, "protobuf", "protobuf") for t, s in TOPICS.items()}
        counts = Counter(topic for topic, _, _ in messages)
        for topic in TOPICS:
            assert counts[topic] == (1 if topic in SCENE_TOPICS else record.steps), topic
        assert summary.statistics.message_count == len(messages) == item.messages
        # log times: ns of simulated time, one per recorded row
        tf_times = np.array([t for topic, t, _ in messages if topic == "/tf"])
        np.testing.assert_array_equal(tf_times, np.round(record.time * 1e9).astype(np.int64))
        assert metadata["arena"]["episode"] == str(record.meta.episode)
        assert metadata["arena"]["outcome"] == record.meta.outcome
        assert metadata["arena"]["matches_record"] == "true"


def test_messages_carry_the_recorded_episode(exported):
    item = exported[0]
    record = load_record(item.record)
    _, _, messages = _read(item.path)
    tf = [dec for topic, _, dec in messages if topic == "/tf"]
    xy = np.array([[t.transforms[0].translation.x, t.transforms[0].translation.y] for t in tf])
    np.testing.assert_allclose(xy, record.pose[:, :2])
    assert tf[3].transforms[0].parent_frame_id == "map"
    assert tf[3].transforms[0].child_frame_id == "base_link"
    assert tf[3].transforms[1].child_frame_id == "laser"
    yaw = [2 * np.arctan2(t.transforms[0].rotation.z, t.transforms[0].rotation.w) for t in tf]
    np.testing.assert_allclose(np.angle(np.exp(1j * np.array(yaw))),
                               np.angle(np.exp(1j * record.pose[:, 2])), atol=1e-9)
    people = [dec for topic, _, dec in messages if topic == "/people"]
    for row in (0, 7, record.steps - 1):
        cyl = people[row].entities[0].cylinders
        rows = record.pedestrians_at(row)
        assert len(cyl) == len(rows)
        np.testing.assert_allclose([[c.pose.position.x, c.pose.position.y] for c in cyl],
                                   record.ped_position[rows])
    scans = [dec for topic, _, dec in messages if topic == "/scan"]
    assert scans[0].frame_id == "laser" and len(scans[0].ranges) > 100
    assert np.min(scans[5].ranges) == pytest.approx(record.min_range[5])
    grid = next(dec for topic, _, dec in messages if topic == "/map")
    cells = np.frombuffer(grid.data, dtype=np.int8).reshape(-1, grid.column_count)
    assert grid.row_stride == grid.column_count and grid.frame_id == "map"
    assert set(np.unique(cells)) <= {-1, 0, 100} and {0, 100} <= set(np.unique(cells))
    plan = [dec for topic, _, dec in messages if topic == "/plan"]
    assert len(plan[1].poses) > 1 and plan[1].frame_id == "map"
    goal = next(dec for topic, _, dec in messages if topic == "/goal")
    np.testing.assert_allclose([goal.pose.position.x, goal.pose.position.y],
                               record.meta.goal[:2])


def test_bad_runs_get_one_line(tmp_path, run_dir):
    with pytest.raises(ConfigError, match="no such run folder"):
        export_mcap(tmp_path / "nowhere")
    with pytest.raises(ConfigError, match="holds no episode records"):
        export_mcap(tmp_path)
    with pytest.raises(ConfigError, match="matches 'x"):
        export_mcap(run_dir, tmp_path / "o", only="x*")


def test_cli(monkeypatch, capsys, run_dir, tmp_path):
    code, out, err = run_cli(monkeypatch, capsys, "export", "mcap", str(run_dir), "-o",
                             str(tmp_path), "--only", "episode_001/*")
    assert code == 0, err
    assert "1 episode(s) written" in out and (tmp_path / "episode_001/episode.mcap").is_file()
    code, out, err = run_cli(monkeypatch, capsys, "export", "mcap", str(tmp_path / "no"))
    assert code == 2 and err.count("\n") == 1 and "no such run folder" in err
