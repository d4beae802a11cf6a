"""Planners on people seen by the RGB-D camera (``rgbd``) and by camera and lidar (``fused``).

Runs on the MuJoCo backend (``arena[3d]``): a jackal with the training camera drives the corridor
scenario among its people; the run's record holds the tracks and their tracking metrics.
"""

from __future__ import annotations

import math

import pytest
import yaml

from arena.config import load_config
from arena.core.errors import ArenaError
from arena.eval.metrics import compute_metrics
from arena.experiment import run_experiment
from arena.maps.sources import WORLDS_DIR
from arena.perception.rgbd_data import with_camera
from arena.perception.stage import PERCEPTION
from arena.robots.presets import load_robot
from tests.mujoco_kit import require_mujoco

SCENARIO = WORLDS_DIR / "corridor" / "scenarios" / "default.json"
TRACKING = ["tracking_mota", "tracking_motp", "tracking_idf1", "tracking_id_switches"]


@pytest.fixture(scope="module")
def camera_robot(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("robot") / "jackal_rgbd.yaml"
    data = with_camera(load_robot("jackal")).model_dump(mode="json")
    data["name"] = "jackal_rgbd"
    path.write_text(yaml.safe_dump(data))
    return str(path)


def corridor(robot: str, perception: str, *extra: str):
    return load_config(None, [
        "map.name=corridor", "task.robots.type=scenario", f"task.robots.file={SCENARIO}",
        "task.obstacles.type=scenario", f"task.obstacles.file={SCENARIO}", "episodes=1",
        "task.timeout=60", "navigation.local_planner.type=social_force", f"robot={robot}",
        f"navigation.perception.type={perception}", "sim.backend.type=mujoco", *extra,
    ])


@pytest.mark.parametrize("perception", ["rgbd", "fused"])
def test_a_planner_on_camera_people_reaches_its_goal_and_is_scored_on_tracking(
    perception, camera_robot, tmp_path
):
    require_mujoco(module=False)
    cfg = corridor(camera_robot, perception, "output.video=true", "output.frame_every=5")
    _, (res,) = run_experiment(cfg, tmp_path)
    assert res.outcome == "success", res.error
    p = res.record.perception
    assert p is not None and p.perceived.sum() >= res.record.steps - 2
    assert p.seen.any() and len(p.trk_id) > 0  # the camera saw people and tracked them
    m = compute_metrics(res.record, TRACKING)
    assert all(math.isfinite(v) for v in m.values()), m
    assert m["tracking_motp"] < 0.5 and m["tracking_idf1"] > 0.0
    assert (tmp_path / "episode_000" / "video.mp4").stat().st_size > 0


def test_camera_perception_needs_a_camera_on_the_robot():
    with pytest.raises(ArenaError, match=r"navigation\.perception\.sensor: robot 'jackal' has "
                                         r"no rgbd sensor 'camera'; expected one of its cameras: "
                                         r"none \(add one under sensors:\)") as e:
        load_config(None, ["navigation.perception.type=rgbd"])
    assert "\n" not in str(e.value)
    with pytest.raises(ArenaError, match=r"navigation\.perception\.rgbd\.sensor: .*'front'"):
        load_config(None, ["navigation.perception={type: fused, rgbd: {sensor: front}}"])
    with pytest.raises(ArenaError, match=r"navigation\.perception.*pixel_scor"):
        load_config(None, ["navigation.perception={type: rgbd, pixel_scor: 0.4}"])


def test_camera_plugins_are_built_with_the_robots_camera(camera_robot):
    robot = load_robot(camera_robot)
    for name in ("rgbd", "fused"):
        plugin = PERCEPTION.build({"type": name}, robot)
        plugin.reset()
        assert plugin.last is None
        assert plugin.people.__self__ is plugin
