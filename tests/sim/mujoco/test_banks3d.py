"""The rgbd and lidar3d sensors on the mujoco backend: readings by name, each step."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.sensors.spec3d import RgbdFrame
from arena.sim.mujoco.backend import MujocoBackend
from arena.sim.native2d import Native2DBackend
from tests.mujoco_kit import require_mujoco
from tests.sim.mujoco.scenes import episode, people

require_mujoco()

CAMERA = {"type": "rgbd", "width": 64, "height": 48, "fovy": 60.0, "near": 0.05, "far": 12.0,
          "update_rate": 10.0, "mount": [0.3, 0.0, 0.5, 0.0, 0.0]}
VELODYNE = {"type": "lidar3d", "rings": 3, "num_beams": 72, "vertical_min": -0.2,
            "vertical_max": 0.2, "angle_min": -np.pi, "angle_max": np.pi, "range_max": 20.0,
            "update_rate": 10.0, "mount": [0.0, 0.0, 0.5, 0.0]}


def jackal_3d(**extra: dict) -> RobotModel:
    data = load_robot("jackal").model_dump()
    data["sensors"]["camera"] = dict(CAMERA)
    data["sensors"]["velodyne"] = dict(VELODYNE)
    for name, spec in extra.items():
        data["sensors"][name] = spec
    return RobotModel.model_validate(data)


def test_camera_and_3d_lidar_read_the_world_by_name():
    # facing the interior wall stub (x 4.0..4.1 m) from x = 1 m: 2.7 m from the camera lens
    ep = episode([("robot", jackal_3d(), (1.0, 1.2, 0.0))], obstacles=(),
                 agents=people([(2.5, 0.6)]))
    b = MujocoBackend()
    state = b.reset(ep, None, derive_rng(0, "banks3d"))
    sensors = state.robots.sensors[0]
    assert set(sensors) == {"laser", "camera", "velodyne"}
    frame = sensors["camera"]
    assert isinstance(frame, RgbdFrame)
    assert frame.rgb.shape == (48, 64, 3) and frame.rgb.dtype == np.uint8
    assert frame.depth.shape == (48, 64) and frame.depth.dtype == np.float32
    assert not frame.depth.flags.writeable and not frame.rgb.flags.writeable
    # the centre pixel looks straight ahead at the wall: depth along the axis = 4.0 - 1.3 m
    assert frame.depth[24, 31:33].mean() == pytest.approx(2.7, abs=0.02)
    assert frame.rgb.max() > 0  # rendered, not the blank frame
    # the person at (2.5, 0.6) stands right of the view axis (y = 1.2): right half of the image
    cols = np.flatnonzero((frame.person == 0).any(axis=0))
    assert len(cols) > 0 and cols.min() > 32
    # the 3-D lidar: its middle ring is level at 0.5 m; the beam straight ahead hits the wall
    scan = sensors["velodyne"]
    assert scan.shape == (3, 72)
    assert scan[1, 36] == pytest.approx(4.0 - 1.0, abs=1e-6)  # beam 36 points at yaw 0
    assert np.all(scan <= 20.0) and np.all(scan > 0)
    # the readings follow the robot: a step forward brings the wall 0.04 m closer
    state = b.step(np.array([[0.4, 0.0, 0.0]]), 0.1)
    s2 = state.robots.sensors[0]
    assert s2["velodyne"][1, 36] == pytest.approx(scan[1, 36] - 0.04, abs=1e-6)
    assert s2["camera"].depth[24, 31:33].mean() == pytest.approx(2.66, abs=0.02)


def test_same_seed_same_frames_and_noise_from_the_sensor_stream():
    noisy = jackal_3d(
        camera={**CAMERA, "depth_noise_std": 0.01},
        velodyne={**VELODYNE, "noise_std": 0.02},
    )
    ep = episode([("robot", noisy, (1.0, 1.2, 0.3))], agents=people([(2.5, 0.6)]))

    def run(seed: str) -> list[tuple[bytes, bytes, bytes]]:
        b = MujocoBackend()
        b.reset(ep, None, derive_rng(0, seed))
        out = []
        for _ in range(3):
            s = b.step(np.array([[0.3, 0.0, 0.1]]), 0.1).robots.sensors[0]
            out.append((s["camera"].rgb.tobytes(), s["camera"].depth.tobytes(),
                        s["velodyne"].tobytes()))
        return out

    a, again, other = run("n"), run("n"), run("m")
    assert a == again
    assert [x[0] for x in a] == [x[0] for x in other]  # colour has no noise
    assert all(x[1] != y[1] and x[2] != y[2] for x, y in zip(a, other, strict=True))


def test_native2d_refuses_the_3d_sensor_types():
    ep = episode([("robot", jackal_3d(), (1.0, 1.2, 0.0))], obstacles=())
    with pytest.raises(ConfigError, match=r"sensor type '(rgbd|lidar3d)' needs the 3-D backend"):
        Native2DBackend().reset(ep, None, derive_rng(0, "x"))
