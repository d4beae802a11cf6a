"""The Gymnasium env observes an RGB-D camera (depth and colour) on the mujoco backend."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.learn.batched import BatchedSocialNavEnv
from arena.learn.env import SocialNavEnv
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from tests.mujoco_kit import require_mujoco

ROOM = ["map.type=empty", "map.width=8", "map.height=8", "task.obstacles.static=2",
        "task.obstacles.dynamic=3", "task.robots.min_goal_distance=3", "sim.backend.type=mujoco"]
CAMERA = {"type": "rgbd", "width": 40, "height": 30, "fovy": 70.0, "near": 0.05, "far": 9.0,
          "update_rate": 10.0, "mount": [0.3, 0.0, 0.6, 0.0, 0.1]}


def camera_jackal() -> RobotModel:
    data = load_robot("jackal").model_dump()
    data["sensors"]["front_cam"] = dict(CAMERA)
    return RobotModel.model_validate(data)


def test_depth_and_colour_observations_are_the_cameras_frames():
    require_mujoco(module=False)
    env = SocialNavEnv(None, [*ROOM, "learning.env.observation.camera.sensor=front_cam",
                              "learning.env.observation.camera.channels=[depth, rgb]"],
                       robot=camera_jackal())
    space = env.observation_space
    assert space["depth"].shape == (30, 40) and space["depth"].dtype == np.float32
    assert float(space["depth"].high.max()) == 9.0
    assert space["rgb"].shape == (30, 40, 3) and space["rgb"].dtype == np.uint8
    obs, _ = env.reset(seed=3)
    assert space.contains(obs)
    frame = env.driver.state.robots.sensors[0]["front_cam"]
    assert np.array_equal(obs["depth"], frame.depth) and np.array_equal(obs["rgb"], frame.rgb)
    assert obs["depth"].max() > 0.0 and obs["rgb"].max() > 0  # the room is in view
    obs["depth"][0, 0] = -1.0  # the observation is the env's to give away, not the frame
    assert frame.depth[0, 0] != -1.0
    seen = [obs["depth"].copy()]
    env.action_space.seed(0)
    for _ in range(5):
        obs, *_ = env.step(env.action_space.sample())
        assert space.contains(obs)
        seen.append(obs["depth"])
    assert not np.array_equal(seen[0], seen[-1])  # the view follows the robot


def test_camera_observation_errors_are_one_line():
    with pytest.raises(ConfigError, match=r"camera\.sensor: robot 'jackal' has no rgbd sensor "
                                          r"'laser'; expected one of its cameras: front_cam"):
        SocialNavEnv(None, [*ROOM, "learning.env.observation.camera.sensor=laser"],
                     robot=camera_jackal())
    with pytest.raises(ConfigError, match=r"none \(add one under sensors:\)"):
        SocialNavEnv(None, [*ROOM, "learning.env.observation.camera.sensor=cam"], robot="jackal")
    with pytest.raises(ConfigError, match=r"flatten: camera images need the Dict observation"):
        SocialNavEnv(None, [*ROOM, "learning.env.observation.camera.sensor=front_cam",
                            "learning.env.observation.flatten=true"], robot=camera_jackal())
    with pytest.raises(ConfigError, match=r"batched env runs the native2d engine"):
        BatchedSocialNavEnv(None, ["learning.env.observation.camera.sensor=front_cam"],
                            num_envs=2, robot=camera_jackal())
    with pytest.raises(ConfigError, match=r"camera\.channels"):
        SocialNavEnv(None, [*ROOM, "learning.env.observation.camera.channels=[lidar]"],
                     robot=camera_jackal())
