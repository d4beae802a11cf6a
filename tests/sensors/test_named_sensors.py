"""Named sensors: a robot's ``sensors`` mapping, the registry, and readings by name."""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.learn.batched import BatchedSocialNavEnv
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot, robot_names
from arena.scene.state import RobotStates, SimState, StaticWorld
from arena.sensors import SENSORS, Lidar2D, LidarSpec, SensorBank
from arena.sim.engine import Engine
from arena.sim.native2d import Native2DBackend
from tests.learn.helpers import small_cfg
from tests.sim.engine.helpers import driver, episodes, lock_step

FRONT = {"type": "lidar2d", "angle_min": -2.356, "angle_max": 2.356, "num_beams": 181,
         "range_max": 12.0, "mount": [0.12, 0.0, 0.0]}
REAR = {"type": "lidar2d", "angle_min": -0.785, "angle_max": 0.785, "num_beams": 37,
        "range_max": 6.0, "mount": [-0.2, 0.05, math.pi]}


def two_lidar_robot(**extra: dict) -> RobotModel:
    """The Jackal carrying ``laser`` (front, 270°) and ``rear`` (90°, facing backwards)."""
    data = load_robot("jackal").model_dump()
    data["sensors"] = {"laser": FRONT, "rear": REAR, **extra}
    return RobotModel.model_validate(data)


def reference(spec: LidarSpec, world: StaticWorld, state: SimState, i: int = 0) -> np.ndarray:
    """A :class:`Lidar2D` scan of ``spec`` from robot ``i``'s pose (one robot, body circles)."""
    lidar = Lidar2D(spec)
    lidar.bind(world.grid, world.segments_a, world.segments_b)
    return lidar.scan(state.robots.poses[i], state.agents.positions, state.agents.radii)


def assert_readings(model: RobotModel, world: StaticWorld, state: SimState, i: int = 0) -> None:
    """Each lidar of robot ``i`` reads exactly its own spec's scan; the rear one looks back."""
    by_name = state.robots.sensors[i]
    assert list(by_name) == list(model.sensors)
    for name, spec in model.sensors.items():
        if isinstance(spec, LidarSpec):
            assert np.array_equal(by_name[name], reference(spec, world, state, i)), name
    assert state.robots.scans[i] is by_name["laser"]  # the primary lidar
    # every return of the rear lidar lies behind the robot (robot-frame x < mount x)
    rear = model.sensors["rear"]
    r = by_name["rear"]
    hit = r < rear.range_max
    assert hit.any()
    a = rear.angles() + rear.mount[2]
    ox = rear.mount[0]
    ex = ox + r[hit] * np.cos(a[hit])  # robot frame
    assert np.all(ex < ox + 1e-9)
    assert not by_name["rear"].flags.writeable


def test_two_lidars_in_native2d():
    model = two_lidar_robot()
    ep = episodes([model], 1)[0]
    sim = Native2DBackend()
    state = sim.reset(ep, driver({"type": "pysocial"}), derive_rng(3, "named"))
    world = sim.world
    assert_readings(model, world, state)
    rng = np.random.default_rng(0)
    for _ in range(12):
        state = sim.step(np.array([[rng.uniform(0, 0.8), 0.0, rng.uniform(-1, 1)]]), 0.1)
        assert state.robots.sensors[0]["laser"].shape == (181,)
        assert state.robots.sensors[0]["rear"].shape == (37,)
        assert_readings(model, world, state)


def test_two_lidars_in_the_batched_env():
    model = two_lidar_robot()
    env = BatchedSocialNavEnv(small_cfg("learning.env.observation.sensor=rear"), robot=model,
                              num_envs=3)
    obs, _ = env.reset(seed=4)
    assert obs["lidar"].shape == (3, 37)
    for k in range(6):
        if k:
            obs, *_ = env.step(np.zeros((3, *env.single_action_space.shape)))
        rear, laser = env.sensor_readings("rear"), env.sensor_readings("laser")
        assert rear.shape == (3, 37)
        assert laser.shape == (3, 181)
        for w in range(3):
            state = env.sim.world_state(w)
            assert np.array_equal(rear[w], state.robots.sensors[0]["rear"])
            assert_readings(model, env.sim.world(w), state)
        assert np.allclose(obs["lidar"], np.clip(rear, 0, REAR["range_max"]).astype(np.float32))
    with pytest.raises(KeyError, match="no sensor 'top'"):
        env.sensor_readings("top")


def test_engine_equivalence_with_two_sensors_per_robot():
    model = two_lidar_robot()
    eps = episodes([model], 4)
    seen = lock_step(eps, {"type": "pysocial"}, steps=30, reset_at=15)
    assert seen["people_moved"]


def test_every_preset_has_one_sensor_named_laser():
    for name in robot_names():
        model = load_robot(name)
        assert list(model.sensors) == ["laser"], name
        assert model.primary_lidar == "laser"
        assert model.laser is model.sensors["laser"]
        assert model.laser.type == "lidar2d"
        # the dump is in the sensors layout and loads back equal
        assert RobotModel.model_validate(model.model_dump()) == model


def test_laser_is_the_sensor_named_laser_else_the_first_lidar():
    model = two_lidar_robot()
    assert model.laser == LidarSpec.model_validate(FRONT)
    data = model.model_dump()
    data["sensors"] = {"rear": REAR, "front": FRONT}
    other = RobotModel.model_validate(data)
    assert other.primary_lidar == "rear"
    assert other.laser.num_beams == 37
    with pytest.raises(ConfigError, match=r"no lidar2d sensor 'laser'.*rear, front"):
        other.lidar("laser", path="navigation.scan_sensor")
    # a copy replacing `laser` replaces the primary lidar (old code's idiom)
    copy = model.model_copy(update={"laser": model.laser.model_copy(update={"num_beams": 9})})
    assert copy.sensors["laser"].num_beams == 9
    assert copy.sensors["rear"] is model.sensors["rear"]


@pytest.mark.parametrize(
    ("sensors", "path", "fragment"),
    [
        ({"laser": {**FRONT, "type": "lidar2"}}, "sensors.laser.type", "did you mean 'lidar2d'"),
        ({"rear": {**REAR, "num_beam": 3}}, "sensors.rear.num_beam", "unknown key"),
        ({"rear": {**REAR, "num_beams": 0}}, "sensors.rear.num_beams", "greater than 0"),
        ({"rear left": REAR}, "sensors.rear left", "identifier"),
        ({"1st": REAR}, "sensors.1st", "identifier"),
    ],
)
def test_bad_sensor_blocks_name_the_field(sensors, path, fragment):
    data = load_robot("jackal").model_dump()
    data["sensors"] = sensors
    with pytest.raises(ConfigError, match=fragment) as err:
        RobotModel.model_validate(data)
    assert err.value.path == path


def test_laser_and_sensors_together_is_an_error():
    data = load_robot("jackal").model_dump()
    data["laser"] = FRONT
    with pytest.raises(ConfigError, match="not both") as err:
        RobotModel.model_validate(data)
    assert err.value.path == "laser"


# -- a toy sensor type, registered here: the engine is not edited for it -------------------------
class RangeRingSpec(BaseModel):
    """Distance to the nearest pedestrian edge in each of ``sectors`` equal robot-frame sectors."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    type: Literal["range_ring"] = "range_ring"
    sectors: int = Field(gt=0)
    range_max: float = Field(gt=0)
    update_rate: float = Field(10.0, gt=0)


@SENSORS.register("range_ring")
class RangeRingBank:
    """The ``range_ring`` rows of every world, from the scene's pedestrian circles."""

    Params = RangeRingSpec

    def __init__(self) -> None:
        self.specs: list[RangeRingSpec] = []
        self.robots = np.zeros(0, dtype=np.int64)
        self.worlds = np.zeros(0, dtype=np.int64)
        self.out: list[np.ndarray] = []

    def bind_world(self, w, grid, segments_a=None, segments_b=None) -> None:
        """Walls are not seen by this sensor."""

    def set_sensors(self, row_world, row_robot, specs) -> None:
        self.worlds = np.asarray(row_world, dtype=np.int64)
        self.robots = np.asarray(row_robot, dtype=np.int64)
        self.specs = list(specs)
        self.out = [np.full(s.sectors, s.range_max) for s in self.specs]

    def scan(self, due, poses, scene, *, parallel=False, chunksize=1) -> None:
        for s in np.flatnonzero(due):
            spec, w = self.specs[s], self.worlds[s]
            x, y, th = poses[self.robots[s]]
            a, b = scene.circ_off[w], scene.circ_off[w + 1]
            peds = scene.circ_owner[a:b] < 0
            xy, r = scene.circ_xy[a:b][peds], scene.circ_r[a:b][peds]
            self.out[s] = ring(xy, r, x, y, th, spec)

    def read(self, s: int, rng: np.random.Generator | None) -> np.ndarray:
        """A copy of the latest reading (no noise)."""
        return self.out[s].copy()


def ring(xy, r, x, y, th, spec: RangeRingSpec) -> np.ndarray:
    """``(sectors,)`` m: per sector the nearest circle edge, ``range_max`` if none nearer."""
    out = np.full(spec.sectors, spec.range_max)
    d = np.hypot(xy[:, 0] - x, xy[:, 1] - y) - r
    bearing = np.mod(np.arctan2(xy[:, 1] - y, xy[:, 0] - x) - th, 2 * np.pi)
    sector = np.minimum((bearing / (2 * np.pi / spec.sectors)).astype(int), spec.sectors - 1)
    for k, dist in zip(sector, d, strict=True):
        out[k] = min(out[k], dist)
    return out


def test_a_registered_sensor_type_plugs_in_by_name():
    ring_block = {"type": "range_ring", "sectors": 4, "range_max": 9.0}
    model = two_lidar_robot(ring=ring_block)
    assert isinstance(model.sensors["ring"], RangeRingSpec)
    assert model.model_dump()["sensors"]["ring"] == {**ring_block, "update_rate": 10.0}
    eps = episodes([model], 2)
    eng = Engine(2)
    drivers = [driver({"type": "pysocial"}) for _ in range(2)]
    eng.reset_worlds([0, 1], eps, drivers, [derive_rng(1, w) for w in range(2)])
    spec = model.sensors["ring"]
    for _ in range(5):
        eng.step(np.tile([0.5, 0.0, 0.3], (2, 1)), 0.1)
        for w in range(2):
            state = eng.world_state(w)
            got = state.robots.sensors[0]["ring"]
            x, y, th = state.robots.poses[0]
            want = ring(state.agents.positions, state.agents.radii, x, y, th, spec)
            assert np.array_equal(got, want)
            assert (got < spec.range_max).any()
            assert_readings(model, eng.world(w), state)  # the lidars are unchanged by it


def test_every_sensor_type_conforms():
    assert "lidar2d" in SENSORS.names()
    for name in SENSORS.names():
        bank_cls = SENSORS.get(name)
        assert isinstance(bank_cls(), SensorBank), name
        fields = bank_cls.Params.model_fields
        assert fields["type"].default == name, name
        assert "update_rate" in fields, name


def test_robot_states_built_with_scans_only_name_them_laser():
    scan = np.arange(3.0)
    rs = RobotStates(("r",), ("m",), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)),
                     np.ones(1), (None,), (scan,))
    assert rs.sensors[0]["laser"] is scan
    with pytest.raises(TypeError):
        rs.sensors[0]["x"] = scan  # read-only mapping
