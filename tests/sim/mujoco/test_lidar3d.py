"""The 3-D lidar: ranges against known geometry, its own body unseen, range limits, noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.maps.grid import OccupancyGrid
from arena.robots.presets import load_robot
from arena.scene.episode import AgentSpawn
from arena.sensors.spec3d import Lidar3DSpec
from arena.sim.mujoco.lidar3d import Lidar3D, add_noise
from arena.sim.mujoco.mjcf import compile_model
from arena.sim.mujoco.world import build_world
from tests.mujoco_kit import require_mujoco

mujoco = require_mujoco()

ROOM = OccupancyGrid.empty(10.0, 6.0, 0.1)  # inner wall faces at x = 0.1, 9.9 and y = 0.1, 5.9


def world(**kw):
    model = compile_model(build_world(ROOM, **kw))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def spec(**kw) -> Lidar3DSpec:
    base = {"rings": 1, "num_beams": 360, "vertical_min": 0.0, "vertical_max": 0.0,
            "range_max": 30.0, "mount": (0.0, 0.0, 0.5, 0.0)}
    return Lidar3DSpec.model_validate({**base, **kw})


def box_distances(x: float, y: float, angles: np.ndarray) -> np.ndarray:
    """Distance from ``(x, y)`` along each angle to the room's inner wall faces (m)."""
    c, s = np.cos(angles), np.sin(angles)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (9.9 - x) / c, np.where(c < 0, (0.1 - x) / c, np.inf))
        ty = np.where(s > 0, (5.9 - y) / s, np.where(s < 0, (0.1 - y) / s, np.inf))
    return np.minimum(tx, ty)


@pytest.fixture(scope="module")
def room():
    return world()


def test_level_ring_reads_the_wall_distances(room):
    model, data = room
    sp = spec(mount=(0.4, -0.2, 0.5, 0.3))
    pose = (2.0, 3.0, 0.5)
    r = Lidar3D(sp).scan(model, data, pose)
    assert r.shape == (1, 360)
    # sensor at the mount point, beams at robot yaw + mount yaw + beam angle
    ox = 2.0 + math.cos(0.5) * 0.4 + math.sin(0.5) * 0.2
    oy = 3.0 + math.sin(0.5) * 0.4 - math.cos(0.5) * 0.2
    want = box_distances(ox, oy, sp.angles() + 0.8)
    np.testing.assert_allclose(r[0], want, atol=1e-6)


def test_downward_ring_reads_height_over_sine(room):
    model, data = room
    h, down = 0.6, 0.35
    sp = spec(rings=3, num_beams=72, vertical_min=-down, vertical_max=0.35, mount=(0, 0, h, 0))
    r = Lidar3D(sp).scan(model, data, (5.0, 3.0, 0.2))
    np.testing.assert_allclose(r[0], h / math.sin(down), atol=1e-6)  # ring 0: the lowest
    level = box_distances(5.0, 3.0, sp.angles() + 0.2)
    np.testing.assert_allclose(r[1], level, atol=1e-6)
    # the upward ring: to the wall along the slant, unless it passes over the 2 m wall
    slant = level / math.cos(0.35)
    over = level * math.tan(0.35) + h > 2.0
    np.testing.assert_allclose(r[2], np.where(over, 30.0, slant), atol=1e-6)
    assert over.any() and not over.all()


def test_range_limits(room):
    model, data = room
    sp = spec(num_beams=4, range_min=2.0, range_max=5.0)  # beams at -pi, -pi/2, 0, pi/2
    r = Lidar3D(sp).scan(model, data, (2.0, 3.0, 0.0))
    # walls at 1.9 (behind), 2.9 (right), 7.9 (ahead), 2.9 (left)
    np.testing.assert_allclose(r[0], [2.0, 2.9, 5.0, 2.9], atol=1e-6)


def test_own_body_is_invisible_other_things_are_not():
    robot = load_robot("jackal")
    pose = np.array([3.0, 3.0, 0.4])
    agents = AgentSpawn(np.array([[6.0, 3.0]]), np.full(1, 0.3), np.array([1.0]),
                        np.array([[[7.0, 3.0]]]), np.array([1]), np.array([0]),
                        np.array([0]))
    model, data = world(robots=[("r", robot, pose)], agents=agents)
    empty, empty_data = world()
    sp = spec(mount=(0.0, 0.0, 0.1, 0.0))  # inside the jackal's 0.25 m tall body box
    lidar = Lidar3D(sp)
    own = model.body("robot/r").id
    blind = lidar.scan(model, data, pose)
    assert (blind < 0.3).all()  # without exclusion every beam stops in its own body
    seen = lidar.scan(model, data, pose, exclude_body=own)
    alone = lidar.scan(empty, empty_data, pose)
    bearing = np.abs(np.angle(np.exp(1j * (sp.angles() + 0.4))))  # from +x, the person's way
    ahead = bearing < 0.05
    assert ahead.sum() == 5
    # the person's legs (3 m ahead, before the wall at 6.9 m) block the beams, but the gap
    assert ((seen[0, ahead] > 2.8) & (seen[0, ahead] < 3.0)).sum() == 4
    away = bearing > 0.3
    np.testing.assert_array_equal(seen[0, away], alone[0, away])


def test_noise_from_the_given_generator(room):
    model, data = room
    sp = spec(num_beams=90, range_max=5.0, range_min=1.0, noise_std=0.5)
    clean = Lidar3D(sp).scan(model, data, (2.0, 3.0, 0.0))
    a = add_noise(clean, sp, np.random.default_rng(7))
    b = add_noise(clean, sp, np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)
    hit = clean < 5.0
    assert hit.any() and (~hit).any()
    np.testing.assert_array_equal(a[~hit], 5.0)  # max-range returns stay
    assert (a[hit] != clean[hit]).all()
    assert a.min() >= 1.0 and a.max() <= 5.0
    z = np.random.default_rng(7).standard_normal(clean.shape)  # one draw, this shape
    np.testing.assert_allclose(a[hit], np.clip(clean[hit] + 0.5 * z[hit], 1.0, 5.0))
    quiet = spec(num_beams=90)
    rng = np.random.default_rng(3)
    assert np.array_equal(add_noise(clean, quiet, rng), clean)
    assert rng.standard_normal() == np.random.default_rng(3).standard_normal()  # no draw
