"""navigation.perception: every perception plugin, the lidar one on scans, and a run on it."""

from __future__ import annotations

import numpy as np
import pytest

from arena.config import load_config
from arena.core.errors import ArenaError
from arena.experiment import run_experiment
from arena.maps.grid import OccupancyGrid
from arena.maps.sources import WORLDS_DIR
from arena.nav.intermediate.base import Pedestrians
from arena.perception.stage import PERCEPTION, Senses
from arena.scene.state import AgentStates
from arena.sensors.lidar2d import Lidar2D
from arena.sensors.spec import LidarReading, LidarSpec, lidar_geometry

SPEC = LidarSpec(angle_min=-np.pi, angle_max=np.pi, num_beams=720, range_max=12.0)
POSE = np.array([5.0, 5.0, 0.5])


def reading(people: np.ndarray, t: float) -> LidarReading:
    """A scan from POSE in a 10 x 10 m room of people walking as two swinging legs."""
    occ = np.zeros((200, 200), dtype=bool)
    occ[:3, :] = occ[-3:, :] = occ[:, :3] = occ[:, -3:] = True
    lidar = Lidar2D(SPEC)
    lidar.bind(OccupancyGrid.from_occupied(occ, 0.05))
    swing = 0.12 * np.sin(2 * np.pi * t)
    offset = np.array([swing, 0.1])
    legs = np.concatenate([people + offset, people - offset])
    ranges = lidar.scan(POSE, legs, np.full(len(legs), 0.07))
    return LidarReading(ranges, *lidar_geometry(SPEC))


def agents(xy: np.ndarray) -> AgentStates:
    n = len(xy)
    z = np.zeros(n, dtype=np.int64)
    return AgentStates(np.arange(n), xy, np.tile([0.5, 0.0], (n, 1)), np.zeros(n),
                       np.full(n, 0.3), z, z.copy())


SCAN_PLUGINS = ("ground_truth", "lidar")
"""The plugins that need no camera (``tests/perception/test_camera_stage.py`` runs the rest)."""


def test_every_perception_plugin_is_run_by_a_test():
    assert set(PERCEPTION.names()) == {*SCAN_PLUGINS, "rgbd", "fused"}


@pytest.mark.parametrize("name", SCAN_PLUGINS)
def test_every_perception_plugin_gives_people_in_the_world_frame(name):
    plugin = PERCEPTION.build({"type": name})
    plugin.reset()
    for k in range(4):
        t = 0.1 * k
        people = np.array([[7.0 + 0.5 * t, 6.0], [3.0, 3.0 + 0.5 * t]])
        out = plugin.people(Senses(t, POSE, reading(people, t), SPEC.range_max,
                                   agents=agents(people)))
        assert isinstance(out, Pedestrians)
        pos = np.asarray(out.positions).reshape(-1, 2)
        vel = np.asarray(out.velocities).reshape(-1, 2)
        assert pos.shape == vel.shape and np.all(np.isfinite(pos)) and np.all(np.isfinite(vel))
    # after a few frames every plugin sees both people where they are (world frame)
    assert len(pos) == 2
    for p in people:
        assert np.min(np.hypot(*(pos - p).T)) < 0.2


def test_lidar_people_are_tracked_with_their_velocity_and_know_no_types():
    plugin = PERCEPTION.build({"type": "lidar"})
    plugin.reset()
    for k in range(20):
        t = 0.1 * k
        people = np.array([[6.5 + 0.8 * t, 6.5]])
        out = plugin.people(Senses(t, POSE, reading(people, t), SPEC.range_max))
    assert len(out) == 1
    assert np.asarray(out.velocities)[0] == pytest.approx([0.8, 0.0], abs=0.25)
    assert len(out.kinds) == 0 and len(out.states) == 0  # a scan shows neither


def test_a_misspelt_perception_is_a_one_line_error():
    with pytest.raises(ArenaError, match=r"navigation\.perception.*lidr.*lidar"):
        load_config(None, ["navigation.perception.type=lidr"])
    cfg = load_config(None, ["navigation.perception=lidar"])
    assert cfg.navigation.perception == {"type": "lidar"}


def test_a_planner_on_lidar_people_reaches_its_goal_in_the_corridor(tmp_path):
    file = WORLDS_DIR / "corridor" / "scenarios" / "default.json"
    cfg = load_config(None, [
        "map.name=corridor", "task.robots.type=scenario", f"task.robots.file={file}",
        "task.obstacles.type=scenario", f"task.obstacles.file={file}", "episodes=1",
        "output.video=false", "task.timeout=60", "navigation.local_planner.type=social_force",
        "navigation.perception.type=lidar", "sim.backend.pedestrian_body=legs",
    ])
    _, (res,) = run_experiment(cfg, tmp_path)
    assert res.outcome == "success", res.error


def test_a_contestant_may_plan_on_perceived_people(tmp_path):
    from arena.config.schema import ExperimentConfig
    from arena.tasks.suite import contestant_config, load_contest

    good = tmp_path / "good.yaml"
    good.write_text("contestants:\n  - {name: sf, local_planner: social_force}\n"
                    "  - {name: sf_lidar, local_planner: social_force,\n"
                    "     perception: {type: lidar}}\n")
    contest, _ = load_contest(str(good))
    base = ExperimentConfig()
    assert contestant_config(base, contest.contestants[0]).navigation.perception == {
        "type": "ground_truth"}
    assert contestant_config(base, contest.contestants[1]).navigation.perception == {
        "type": "lidar"}
    bad = tmp_path / "bad.yaml"
    bad.write_text("contestants:\n  - {name: x, local_planner: dwa, perception: {type: lidr}}\n")
    contest, _ = load_contest(str(bad))
    with pytest.raises(ArenaError, match=r"bad\.yaml: contestants\[0\]\.perception.*lidr") as e:
        contestant_config(base, contest.contestants[0], source=str(bad))
    assert "\n" not in str(e.value)
