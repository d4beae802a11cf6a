"""The recorder: a real episode's record matches the CSV files; collision kinds are kept."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from arena.config import load_config
from arena.core.geometry import rectangle
from arena.eval.io import load_record
from arena.eval.record import EpisodeMeta
from arena.eval.recorder import Recorder
from arena.experiment import run_experiment
from arena.robots.presets import load_robot
from arena.scene.state import Obstacle
from arena.sim.native2d import Native2DBackend
from tests.conftest import make_episode, standing_agents

SHORT = ["output.video=false", "task.timeout=5", "task.obstacles.dynamic=3", "episodes=1"]


def _csv(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open() as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float).reshape(-1, len(rows[0]))


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    _, (res,) = run_experiment(load_config(None, SHORT), out)
    return out / "episode_000", res


def test_record_matches_trajectory_csv(short_run):
    folder, res = short_run
    rec = res.record
    assert rec is not None
    head, traj = _csv(folder / "trajectory.csv")
    col = {h: traj[:, i] for i, h in enumerate(head)}
    assert rec.steps == len(traj) == res.steps + 1
    close = dict(rtol=1e-5, atol=1e-6)
    assert np.allclose(rec.time, col["time"], **close)
    assert np.allclose(rec.pose, np.column_stack([col["x"], col["y"], col["theta"]]), **close)
    assert np.allclose(rec.velocity, np.column_stack([col["vx"], col["vy"], col["omega"]]),
                       **close)
    assert np.allclose(
        rec.command, np.column_stack([col["cmd_vx"], col["cmd_vy"], col["cmd_omega"]]), **close
    )
    assert np.allclose(rec.min_range, col["min_range"], **close)
    assert np.array_equal(rec.collision, col["collision"].astype(bool))
    assert np.all(rec.command[0] == 0.0)
    assert rec.meta.outcome == res.outcome
    assert rec.meta.dt == pytest.approx(0.1, abs=0.5)
    assert rec.events[-1] == (pytest.approx(rec.time[-1]), "outcome", res.outcome)


def test_record_matches_agents_csv(short_run):
    folder, res = short_run
    rec = res.record
    head, ag = _csv(folder / "agents.csv")
    col = {h: ag[:, i] for i, h in enumerate(head)}
    assert len(ag) == rec.ped_row.size > 0
    assert np.array_equal(rec.ped_row, col["step"].astype(int))  # row k is the state of step k
    assert np.array_equal(rec.ped_id, col["id"].astype(int))
    assert np.array_equal(rec.ped_kind, col["kind"].astype(int))
    assert np.array_equal(rec.ped_state, col["state"].astype(int))
    close = dict(rtol=1e-5, atol=1e-6)
    assert np.allclose(rec.ped_position, np.column_stack([col["x"], col["y"]]), **close)
    assert np.allclose(rec.ped_velocity, np.column_stack([col["vx"], col["vy"]]), **close)
    assert np.allclose(rec.ped_heading, col["heading"], **close)
    assert np.allclose(rec.ped_radius, col["radius"], **close)
    assert np.allclose(rec.time[rec.ped_row], col["time"], **close)


def test_episode_folder_has_parquet_not_in_json(short_run):
    folder, res = short_run
    assert res.files["record"] == str(folder / "episode.parquet")
    back = load_record(folder / "episode.parquet")
    assert np.array_equal(back.pose, res.record.pose)
    summary = json.loads((folder / "episode.json").read_text())
    assert "record" not in summary and summary["files"]["record"].endswith("episode.parquet")
    assert back.meta.config == res.record.meta.config and "seed" in back.meta.config


def _meta(ep_robot) -> EpisodeMeta:
    return EpisodeMeta(
        episode=0, seed=0, stage="", map_name="room", robot=ep_robot.name,
        robot_radius=float(ep_robot.radius), start=np.zeros(3), goal=np.zeros(3),
        goal_radius=0.3, goal_tolerance_angle=None, time_limit=30.0, dt=0.1, outcome="timeout",
    )


def _drive(ep, steps, cmd=(0.22, 0.0, 0.0), keep_scans=False):
    b = Native2DBackend()
    rec = Recorder(keep_scans=keep_scans, capacity=4)  # small: exercises the buffer growth
    rec.record(b.reset(ep, None, np.random.default_rng(0)))
    for _ in range(steps):
        c = np.asarray(cmd, dtype=float)
        rec.record(b.step(c[None, :], 0.1), c)
    return rec


def test_wall_collision_is_recorded_as_wall(room):
    burger = load_robot("burger")
    rec = _drive(make_episode(room, [(burger, (9.0, 5, 0), (1, 5, 0))]), 60)
    r = rec.finish(_meta(burger))
    assert r.steps == 61
    assert r.collision_wall.any() and not r.collision_wall[0]
    assert not (r.collision_obstacle.any() or r.collision_pedestrian.any()
                or r.collision_robot.any())
    assert r.ped_row.size == 0 and r.ped_position.shape == (0, 2)
    assert np.allclose(r.command[1:], [0.22, 0, 0])


def test_obstacle_and_pedestrian_collisions_are_recorded(room):
    burger = load_robot("burger")
    box = Obstacle("box", "cuboid", np.array([4.0, 5.0, 0.0]), rectangle(0.6, 0.6))
    r = _drive(make_episode(room, [(burger, (2.0, 5, 0), (8, 5, 0))], obstacles=[box]),
               100).finish(_meta(burger))
    assert r.collision_obstacle.any() and not r.collision_wall.any()
    peds = standing_agents([[4.0, 5.0], [7.0, 8.0]])
    r = _drive(make_episode(room, [(burger, (2.0, 5, 0), (8, 5, 0))], agents=peds),
               100).finish(_meta(burger))
    assert r.collision_pedestrian.any() and not r.collision_obstacle.any()
    assert r.ped_row.size == 2 * r.steps
    assert np.array_equal(r.ped_row, np.repeat(np.arange(r.steps), 2))


def test_scans_kept_on_request(room):
    burger = load_robot("burger")
    ep = make_episode(room, [(burger, (2.0, 5, 0), (8, 5, 0))])
    rec = _drive(ep, 10, keep_scans=True)
    scans = rec.scans
    assert scans is not None and scans.shape == (11, burger.laser.num_beams)
    assert np.allclose(rec.finish(_meta(burger)).min_range, scans.min(axis=1))
    assert _drive(ep, 2).scans is None
