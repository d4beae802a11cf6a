"""Parquet round trip of episode records and the Arena CSV export."""

import csv
import json
from dataclasses import fields

import numpy as np
import pyarrow.parquet as pq
import pytest

from arena.config import load_config
from arena.eval.io import (
    ARENA_RECORD_PERIOD,
    ARENA_TIME_SCALE,
    export_arena_csv,
    load_record,
    save_record,
)
from arena.eval.record import EpisodeRecord
from arena.experiment import run_experiment

SHORT = ["output.video=false", "task.timeout=5", "task.obstacles.dynamic=3", "episodes=1"]
ARRAYS = [f.name for f in fields(EpisodeRecord) if f.name not in ("meta", "events")]


@pytest.fixture(scope="module")
def record(tmp_path_factory) -> EpisodeRecord:
    _, (res,) = run_experiment(load_config(None, SHORT), tmp_path_factory.mktemp("run"))
    assert res.record is not None
    return res.record


def _assert_same(a: EpisodeRecord, b: EpisodeRecord) -> None:
    for name in ARRAYS:
        x, y = getattr(a, name), getattr(b, name)
        if x is None or y is None:  # optional columns (the counterfactual crowd)
            assert x is None and y is None, name
            continue
        assert x.dtype == y.dtype, name
        assert x.shape == y.shape, name
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
    assert a.events == b.events
    ma, mb = a.meta, b.meta
    for f in fields(ma):
        va, vb = getattr(ma, f.name), getattr(mb, f.name)
        if isinstance(va, np.ndarray):
            assert va.dtype == vb.dtype and np.array_equal(va, vb), f.name
        else:
            assert va == vb, f.name


def test_parquet_round_trip_is_exact(record, tmp_path):
    path = save_record(record, tmp_path / "episode.parquet")
    back = load_record(path)
    _assert_same(record, back)
    md = pq.read_schema(path).metadata
    assert b"arena.meta" in md and b"arena.events" in md
    assert pq.read_metadata(path).num_rows == record.steps


def test_round_trip_keeps_inf_nan_and_empty_pedestrians(record, tmp_path):
    t = record.steps
    empty_i = np.zeros(0, dtype=np.int64)
    rec = EpisodeRecord(
        meta=record.meta, time=record.time, pose=record.pose, velocity=record.velocity,
        command=record.command,
        min_range=np.where(np.arange(t) % 2 == 0, np.inf, np.nan),
        collision_wall=np.arange(t) % 3 == 0, collision_obstacle=record.collision_obstacle,
        collision_pedestrian=record.collision_pedestrian, collision_robot=record.collision_robot,
        ped_row=empty_i, ped_id=empty_i, ped_kind=empty_i, ped_state=empty_i,
        ped_position=np.zeros((0, 2)), ped_velocity=np.zeros((0, 2)),
        ped_heading=np.zeros(0), ped_radius=np.zeros(0), events=[],
    )
    _assert_same(rec, load_record(save_record(rec, tmp_path / "e.parquet")))


def _read(path):
    with path.open() as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def test_arena_csv_export_parses_back(record, tmp_path):
    scans = np.tile(np.linspace(0.5, 3.0, 8), (record.steps, 1))
    scans[:, 3] = np.nan
    files = export_arena_csv(record, tmp_path, scan=scans, scan_range_max=3.5)
    assert set(files) == {"odom", "cmd_vel", "pedsim_agents_data", "episode", "start_goal",
                          "scan"}
    t = record.steps
    head, odom = _read(tmp_path / "odom.csv")
    assert head == ["time", "data"] and len(odom) == t
    times = np.array([int(r[0]) for r in odom]) / ARENA_TIME_SCALE
    assert np.allclose(times, record.time, atol=1e-9)
    data = [json.loads(r[1]) for r in odom]
    assert np.allclose([d["position"] for d in data], record.pose, atol=5e-4)
    assert np.allclose([d["velocity"] for d in data], record.velocity, atol=5e-4)
    head, cmd = _read(tmp_path / "cmd_vel.csv")
    assert head == ["time", "data"] and len(cmd) == t
    assert np.allclose([json.loads(r[1]) for r in cmd], record.command, atol=5e-4)
    head, peds = _read(tmp_path / "pedsim_agents_data.csv")
    assert head == ["time", "data"] and len(peds) == t
    agents = [json.loads(r[1]) for r in peds]
    assert sum(len(a) for a in agents) == record.ped_row.size
    row = 1
    got = agents[row]
    idx = record.pedestrians_at(row)
    assert [a["id"] for a in got] == [str(i) for i in record.ped_id[idx]]
    assert set(got[0]) == {"id", "type", "social_state", "position", "theta", "destination"}
    assert np.allclose([a["position"] for a in got], record.ped_position[idx], atol=5e-4)
    assert np.allclose([a["theta"] for a in got], record.ped_heading[idx], atol=5e-4)
    assert [a["destination"] for a in got] == [a["position"] for a in got]
    head, ep = _read(tmp_path / "episode.csv")
    assert head == ["time", "episode"] and len(ep) == t
    assert all(int(r[1]) == record.meta.episode for r in ep)
    head, sg = _read(tmp_path / "start_goal.csv")
    assert head == ["episode", "start", "goal"] and len(sg) == 1
    assert np.allclose(json.loads(sg[0][1]), record.meta.start, atol=5e-4)
    assert np.allclose(json.loads(sg[0][2]), record.meta.goal, atol=5e-4)
    head, sc = _read(tmp_path / "scan.csv")
    assert head == ["time", "data"] and len(sc) == t
    ranges = np.array([json.loads(r[1]) for r in sc])
    assert np.all(ranges[:, 3] == 3.5) and np.allclose(ranges[:, 0], 0.5)


def test_arena_csv_downsampling_and_no_scan(record, tmp_path):
    files = export_arena_csv(record, tmp_path, record_period=ARENA_RECORD_PERIOD)
    assert "scan" not in files and not (tmp_path / "scan.csv").exists()
    _, odom = _read(tmp_path / "odom.csv")
    times = np.array([int(r[0]) for r in odom]) / ARENA_TIME_SCALE
    assert times[0] == record.time[0]
    assert np.all(np.diff(times) >= ARENA_RECORD_PERIOD - 1e-6)
    assert np.all(np.diff(times) < ARENA_RECORD_PERIOD + record.meta.dt + 1e-6)
    expected = int(np.floor((record.time[-1] - record.time[0]) / ARENA_RECORD_PERIOD + 1e-6)) + 1
    assert len(odom) == expected
    for name in ("cmd_vel", "pedsim_agents_data", "episode"):
        assert len(_read(tmp_path / f"{name}.csv")[1]) == len(odom)
