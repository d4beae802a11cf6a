"""The 3-D sensor specs (``rgbd``, ``lidar3d``): validation, geometry, registry, 2-D refusal."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from pydantic import ValidationError

from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.robots import presets
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.sensors import SENSORS, LidarSpec
from arena.sensors.spec3d import Lidar3DSpec, RgbdFrame, RgbdSpec
from arena.sim.engine import Engine
from tests.sim.engine.helpers import driver, episodes

CAM = {"type": "rgbd", "width": 64, "height": 48, "fovy": 60.0, "mount": [0.2, 0, 0.4, 0, 0.1]}
VLP = {"type": "lidar3d", "rings": 16, "num_beams": 360, "range_max": 30.0,
       "mount": [0, 0, 0.5, 0]}


def jackal_with(**sensors: dict) -> RobotModel:
    data = load_robot("jackal").model_dump()
    data["sensors"] = {**data["sensors"], **sensors}
    return RobotModel.model_validate(data)


def test_a_robot_declares_rgbd_and_lidar3d_and_keeps_its_primary_lidar():
    model = jackal_with(cam=CAM, vlp=VLP)
    assert isinstance(model.sensors["cam"], RgbdSpec)
    assert isinstance(model.sensors["vlp"], Lidar3DSpec)
    assert model.primary_lidar == "laser" and isinstance(model.laser, LidarSpec)
    again = RobotModel.model_validate(model.model_dump())  # a dumped robot reloads
    assert again.sensors["cam"] == model.sensors["cam"]
    assert again.sensors["vlp"] == model.sensors["vlp"]


def test_a_robot_yaml_declares_them_and_a_bad_field_is_one_line(tmp_path):
    jackal = (Path(presets.__file__).parent / "presets" / "jackal.yaml").read_text()
    assert "\nlaser:" in jackal  # Arena's layout: one laser block, read as sensors.laser
    body = re.sub(r"^laser:\n((?:  .*\n)+)", lambda m: "sensors:\n  laser:\n    type: lidar2d\n"
                  + m.group(1).replace("  ", "    "), jackal, count=1, flags=re.MULTILINE)
    block = ("  cam: {type: rgbd, width: 64, height: 48, fx: 50, fy: 50, cx: 31.5, cy: 23.5,\n"
             "        mount: [0.2, 0, 0.4, 0, 0.1]}\n"
             "  vlp: {type: lidar3d, rings: 4, num_beams: 90, range_max: 20,"
             " mount: [0, 0, 0.5, 0]}\n")
    path = tmp_path / "robot.yaml"
    path.write_text(body.replace("sensors:\n", "sensors:\n" + block, 1))
    model = load_robot(str(path))
    assert model.sensors["cam"].intrinsics() == (50, 50, 31.5, 23.5)
    assert model.sensors["vlp"].directions().shape == (4, 90, 3)
    assert model.primary_lidar == "laser"
    path.write_text(body.replace("sensors:\n", "sensors:\n" + block.replace("fy: 50", "fy: 40"),
                                 1))
    with pytest.raises(ConfigError) as e:
        load_robot(str(path))
    msg = str(e.value)
    assert "\n" not in msg and str(path) in msg and "sensors.cam" in msg
    assert "fx (50.0) must equal fy (40.0)" in msg


def test_every_3d_type_is_registered_with_its_params():
    assert SENSORS.get("rgbd").Params is RgbdSpec
    assert SENSORS.get("lidar3d").Params is Lidar3DSpec


def test_the_2d_engine_refuses_a_3d_sensor_in_one_line():
    model = jackal_with(cam=CAM)
    eng = Engine(1)
    with pytest.raises(ConfigError) as e:
        eng.reset_worlds([0], episodes([model], 1), [driver(None)], [derive_rng(1, 0)])
    assert str(e.value) == "sensor type 'rgbd' needs the 3-D backend (sim.backend.type: mujoco)"
    bank = SENSORS.get("lidar3d")()
    with pytest.raises(ConfigError, match=r"^sensor type 'lidar3d' needs the 3-D backend"):
        bank.set_sensors([0], [0], [Lidar3DSpec.model_validate(VLP)])


@pytest.mark.parametrize(("change", "fragment"), [
    ({"fx": 50.0}, "give either fovy or fx, fy, cx, cy, not both"),
    ({"fovy": None, "fx": 50.0, "fy": 50.0}, "fx, fy, cx, cy go together: cx, cy missing"),
    ({"fovy": None, "fx": 50.0, "fy": 40.0, "cx": 1, "cy": 1}, "fx (50.0) must equal fy (40.0)"),
    ({"near": 5.0, "far": 2.0}, "near (5.0) must be < far (2.0)"),
    ({"width": 5000}, "less than or equal to 4096"),
    ({"mount": [0, 0, 0.4, 0]}, "mount"),
    ({"mount": [0, 0, 0.4, 0, 2.0]}, "mount pitch (2.0) must lie in (-pi/2, pi/2)"),
    ({"mount": [0, 0, -0.1, 0, 0]}, "mount z (-0.1) must be >= 0"),
    ({"fovy": 180.0}, "less than 180"),
    ({"depth_noise": 0.1}, "depth_noise"),
])
def test_rgbd_bad_input_says_what(change: dict, fragment: str):
    with pytest.raises(ValidationError) as e:
        RgbdSpec.model_validate({**CAM, **change})
    assert fragment in str(e.value)


def test_rgbd_intrinsics_from_fovy_and_given():
    spec = RgbdSpec.model_validate(CAM)
    fx, fy, cx, cy = spec.intrinsics()
    assert fx == fy == pytest.approx(24.0 / math.tan(math.radians(30.0)))
    assert (cx, cy) == (31.5, 23.5)
    default = RgbdSpec.model_validate({**CAM, "fovy": None}).intrinsics()
    assert default[1] == pytest.approx(24.0 / math.tan(math.radians(30.0)))  # fovy 60 by default
    given = RgbdSpec.model_validate({**CAM, "fovy": None, "fx": 40, "fy": 40, "cx": 10, "cy": 30})
    assert given.intrinsics() == (40, 40, 10, 30)
    rays = given.rays()
    assert rays.shape == (48, 64, 3)
    np.testing.assert_allclose(rays[30, 10], (0.0, 0.0, 1.0))
    np.testing.assert_allclose(rays[0, 50], ((50 - 10) / 40, (0 - 30) / 40, 1.0))


@pytest.mark.parametrize(("change", "fragment"), [
    ({"vertical_min": 0.3, "vertical_max": 0.1}, "vertical_max (0.1) must be >= vertical_min"),
    ({"vertical_max": 2.0}, "less than or equal to 1.57"),
    ({"angle_min": 1.0, "angle_max": 0.5}, "angle_max (0.5) must be >= angle_min (1.0)"),
    ({"range_min": 40.0}, "range_min (40.0) must be < range_max (30.0)"),
    ({"rings": 1000, "num_beams": 2000}, "rings x num_beams = 2,000,000 rays, more than"),
    ({"mount": [0, 0, 0.5]}, "mount"),
    ({"num_beam": 3}, "num_beam"),
])
def test_lidar3d_bad_input_says_what(change: dict, fragment: str):
    with pytest.raises(ValidationError) as e:
        Lidar3DSpec.model_validate({**VLP, **change})
    assert fragment in str(e.value)


def test_lidar3d_geometry():
    spec = Lidar3DSpec.model_validate({**VLP, "rings": 3, "num_beams": 4,
                                       "vertical_min": -0.2, "vertical_max": 0.4})
    np.testing.assert_allclose(spec.elevations(), [-0.2, 0.1, 0.4])
    # full circle: no beam repeated at the seam, as LidarSpec
    np.testing.assert_allclose(spec.angles(), [-math.pi, -math.pi / 2, 0.0, math.pi / 2])
    d = spec.directions()
    assert d.shape == (3, 4, 3)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0)
    np.testing.assert_allclose(d[2, 2], (math.cos(0.4), 0.0, math.sin(0.4)))
    np.testing.assert_allclose(d[0, 3], (0.0, math.cos(0.2), -math.sin(0.2)), atol=1e-12)
    fan = Lidar3DSpec.model_validate({**VLP, "rings": 1, "num_beams": 3, "angle_min": -0.5,
                                      "angle_max": 0.5})
    np.testing.assert_allclose(fan.angles(), [-0.5, 0.0, 0.5])
    np.testing.assert_allclose(fan.elevations(), [VLP.get("vertical_min", -math.radians(15))])


def test_person_pixels_counts_each_persons_pixels():
    person = np.full((4, 5), -1, dtype=np.int32)
    person[0, :3] = 2
    person[3, 4] = 0
    frame = RgbdFrame(np.zeros((4, 5, 3), np.uint8), np.ones((4, 5), np.float32), person)
    assert frame.person_pixels(4).tolist() == [1, 0, 3, 0]
    assert frame.person_pixels(2).tolist() == [1, 0]  # people past n are not counted
    blind = RgbdFrame(frame.rgb, frame.depth, None)
    assert blind.person_pixels(3).tolist() == [0, 0, 0]
