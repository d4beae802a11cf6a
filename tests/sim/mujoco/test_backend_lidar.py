"""``lidar2d`` in the MuJoCo backend: the same beams as native2d on the same walls and boxes."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.rng import derive_rng
from arena.core.types import Pose2D
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.sim.mujoco.backend import MujocoBackend
from arena.sim.mujoco.params import MujocoParams
from arena.sim.native2d import Native2DBackend
from tests.mujoco_kit import require_mujoco
from tests.sim.mujoco.scenes import episode, people

require_mujoco()


# free poses in scenes.room(): around the wall stub, facing both boxes, near corners
POSES = [(1.0, 1.0, 0.0), (3.0, 2.0, 0.7), (5.5, 1.2, 2.0), (2.5, 3.0, -1.2),
         (7.0, 5.2, 3.0), (6.0, 3.0, 1.5707963), (3.3, 4.0, 0.1234)]

EDGE_JUMP = 0.05
"""m: a beam is at a grazing edge when native2d's range differs from a neighbour's by more than
this plus :data:`EDGE_REL` of its range (a box's corner, a face seen nearly edge-on)."""
EDGE_REL = 0.02


def scan(backend, ep, pose) -> np.ndarray:
    backend.reset(ep, None, derive_rng(0, "lidar"))
    return backend.teleport(0, Pose2D(*pose)).robots.scans[0]


def edge_beams(ranges: np.ndarray) -> np.ndarray:
    """Grazing beams: a neighbour (cyclic: a full circle) differs by the edge threshold."""
    jump = np.abs(np.diff(ranges, append=ranges[:1]))
    return np.maximum(jump, np.roll(jump, 1)) > EDGE_JUMP + EDGE_REL * ranges


@pytest.mark.parametrize("pose", POSES)
def test_ranges_agree_with_native2d_within_1cm_off_grazing_edges(pose):
    ep = episode()
    flat = scan(Native2DBackend(), ep, pose)
    deep = scan(MujocoBackend(), ep, pose)
    assert flat.shape == deep.shape == (720,)
    edges = edge_beams(flat)
    assert edges.mean() < 0.05  # a few beams per edge, not the scan
    err = np.abs(deep - flat)[~edges]
    assert err.max() < 0.01
    assert (flat < 30.0).all()  # a closed room: every beam hits something


def test_a_person_is_seen_by_its_legs_at_scan_height():
    # A standing adult 2 m ahead, facing +x (legs 0.09 m either side of the line of sight).
    ep = episode(agents=people([(3.0, 3.0)]))
    pose = (1.0, 3.0, 0.0)
    flat = scan(Native2DBackend(), ep, pose)
    deep = scan(MujocoBackend(), ep, pose)
    blind = scan(MujocoBackend(MujocoParams(pedestrians_block_lidar=False)), ep, pose)
    angles = ep.robots[0].model.laser.angles()
    ahead = np.abs(angles) < np.radians(10)
    straight = int(np.argmin(np.abs(angles)))
    assert flat[ahead].min() == pytest.approx(2.0 - 0.3, abs=1e-3)  # the 2-D body circle
    # 3-D: a leg capsule (radius 0.065 m) 2 m ahead, 0.09 m off the axis; the beam straight
    # ahead passes between the legs
    hit = np.sqrt(2.0**2 + 0.09**2) - 0.065
    assert deep[ahead].min() == pytest.approx(hit, abs=0.01)
    assert deep[straight] > 2.5
    assert blind[ahead].min() > 2.5  # the same scene without people in the lidar
    assert np.array_equal(deep[~ahead], blind[~ahead])


def test_scan_height_and_own_body():
    ep = episode()
    b = MujocoBackend()
    b.reset(ep, None, derive_rng(0, "lidar"))
    # the jackal is 0.25 m tall: its own body is invisible to its lidar, which scans at 0.225 m
    assert b.world3d.robot_height[0] == pytest.approx(0.25)
    assert (b.state.robots.scans[0] > 0.3).all()
    # a scan plane above the 1 m boxes no longer sees them
    high = MujocoBackend(MujocoParams(lidar_height=1.2))
    low = scan(b, ep, (6.0, 3.0, 1.5707963))
    up = scan(high, ep, (6.0, 3.0, 1.5707963))
    front = int(np.argmin(np.abs(ep.robots[0].model.laser.angles())))  # at box_a, 1 m away
    assert low[front] == pytest.approx(1.0, abs=1e-4)  # the nearest beam is 0.19° off
    assert up[front] == pytest.approx(5.9 - 3.0, abs=1e-4)  # the top wall (rows 118..119)


def test_noise_is_drawn_from_the_sensor_stream_as_in_native2d():
    data = load_robot("jackal").model_dump()
    data["sensors"]["laser"]["noise_std"] = 0.02
    noisy = RobotModel.model_validate(data)
    ep_noisy = episode([("robot", noisy, (1.0, 1.0, 0.0))])
    ep_clean = episode()
    diff = []
    for cls in (Native2DBackend, MujocoBackend):
        n = cls().reset(ep_noisy, None, derive_rng(3, "noise")).robots.scans[0]
        c = cls().reset(ep_clean, None, derive_rng(3, "noise")).robots.scans[0]
        diff.append(n - c)
    assert np.std(diff[0]) > 0.01
    assert np.allclose(diff[0], diff[1], atol=1e-9)


def test_a_10_hz_lidar_holds_its_scan_between_updates():
    b = MujocoBackend()
    first = b.reset(episode(), None, derive_rng(0, "rate")).robots.scans[0]
    cmd = np.array([[0.5, 0.0, 0.0]])
    held = b.step(cmd, 0.05)  # 0.05 s after the scan: the 10 Hz lidar holds it
    assert held.robots.poses[0, 0] > 1.0
    assert np.array_equal(held.robots.scans[0], first)
    fresh = b.step(cmd, 0.05).robots.scans[0]  # 0.1 s: a new scan from the moved robot
    assert not np.array_equal(fresh, first)
