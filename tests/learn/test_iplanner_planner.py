"""The ``iplanner`` local planner: its errors, and closed loops on rendered depth frames."""

from __future__ import annotations

import math
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.learn.iplanner.geometry import CAMERA
from arena.learn.planners.iplanner import IPlannerPlanner, floor_depth
from arena.maps.grid import OccupancyGrid
from arena.nav.local_planners import LOCAL_PLANNERS, LocalObservation
from arena.robots.presets import load_robot
from arena.sensors.spec import LidarReading
from arena.sensors.spec3d import RgbdFrame

ROBOT = Path(__file__).resolve().parents[2] / "arena/tasks/data/robots/jackal_rgbd.yaml"
LIMITS = load_robot("jackal").limits()


def _frame(depth: np.ndarray) -> RgbdFrame:
    h, w = depth.shape
    return RgbdFrame(np.zeros((h, w, 3), np.uint8), depth.astype(np.float32), None)


def _obs(pose, goal, sensors, twist=(0.0, 0.0, 0.0)) -> LocalObservation:
    pose = np.asarray(pose, dtype=np.float64)
    return LocalObservation(
        pose=pose, twist=np.asarray(twist, dtype=np.float64), goal=Pose2D(*goal, 0.0),
        path=np.array([pose[:2], goal]), limits=LIMITS, robot_radius=0.267, dt=0.1,
        sensors=MappingProxyType(sensors), kinematics="diff_drive")


# -- errors ------------------------------------------------------------------------------------


def test_a_robot_without_its_camera_is_a_one_line_error_naming_the_fix() -> None:
    planner = IPlannerPlanner()
    laser = LidarReading(np.ones(3), np.zeros(3), np.zeros(2))
    with pytest.raises(ConfigError, match=r"rgbd sensor 'camera'.*laser.*mujoco"):
        planner.compute(_obs([0, 0, 0], (3.0, 0.0), {"laser": laser}))
    other = IPlannerPlanner(IPlannerPlanner.Params(sensor="laser"))
    with pytest.raises(ConfigError, match="not an rgbd camera"):
        other.compute(_obs([0, 0, 0], (3.0, 0.0), {"laser": laser}))
    small = _frame(np.ones((30, 40)))
    with pytest.raises(ConfigError, match="whole multiple"):
        planner.compute(_obs([0, 0, 0], (3.0, 0.0), {"camera": small}))


@pytest.mark.parametrize(("spec", "match"), [
    ({"fear_stop": 0.2}, "fear_slow"),
    ({"lookahead": 0.0}, "lookahead"),
    ({"missing_frame": "blind"}, "missing_frame"),
    ({"colour": True}, "colour"),
    ({"weights": "/nonexistent/policy.npz"}, "train one with"),
])
def test_bad_parameters_are_config_errors(spec: dict, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        LOCAL_PLANNERS.build({"type": "iplanner", **spec})


def test_a_blank_frame_brakes_and_an_empty_floor_drives_forward() -> None:
    planner = IPlannerPlanner()
    blank = _frame(np.zeros((48, 80)))
    cmd = planner.compute(_obs([0, 0, 0], (3.0, 0.0), {"camera": blank}, twist=(0.5, 0, 0)))
    assert planner.last_source == "wait" and cmd[0] < 0.5
    # a frame twice the network's size is subsampled
    floor = _frame(np.repeat(np.repeat(floor_depth(), 2, axis=0), 2, axis=1))
    cmd = planner.compute(_obs([0, 0, 0], (3.0, 0.0), {"camera": floor}))
    assert planner.last_source == "network" and cmd[0] > 0 and abs(cmd[2]) < 0.5
    # a goal far to the side: turn toward it on the spot first
    cmd = planner.compute(_obs([0, 0, 0], (0.0, 3.0), {"camera": floor}))
    assert planner.last_source == "turn" and cmd[0] == 0 and cmd[2] > 0


# -- closed loops on MuJoCo frames -------------------------------------------------------------


class _Sim:
    """A jackal with the trained camera on a static map, moved by exact unicycle steps."""

    def __init__(self, grid: OccupancyGrid) -> None:
        from tests.mujoco_kit import require_mujoco

        mj = require_mujoco(module=False)
        from arena.sim.mujoco.camera import RgbdCamera
        from arena.sim.mujoco.mjcf import compile_model
        from arena.sim.mujoco.world import build_world

        self.grid = grid
        model = compile_model(build_world(grid))
        self.data = mj.MjData(model)
        mj.mj_forward(model, self.data)
        self.camera = RgbdCamera(model, CAMERA, segmentation=False)

    def run(self, planner: IPlannerPlanner, start, goal, steps: int
            ) -> tuple[np.ndarray, list[str]]:
        pose, twist = np.asarray(start, dtype=np.float64), np.zeros(3)
        poses, sources = [pose.copy()], []
        for _ in range(steps):
            frame = self.camera.render(self.data, pose)
            cmd = planner.compute(_obs(pose, goal, {"camera": frame}, twist))
            sources.append(planner.last_source)
            v, w = cmd[0], cmd[2]
            pose = pose + 0.1 * np.array([v * math.cos(pose[2] + 0.05 * w),
                                          v * math.sin(pose[2] + 0.05 * w), w])
            twist = cmd
            poses.append(pose.copy())
            if planner.last_source == "goal" and abs(v) < 1e-3:
                break
        return np.array(poses), sources


def _room(wall: bool) -> OccupancyGrid:
    """8 × 6 m room; with ``wall`` a 2.4 m wide wall across the way at x = 3.0 … 3.2 m."""
    occ = np.zeros((120, 160), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    if wall:
        occ[36:84, 60:64] = True
    return OccupancyGrid.from_occupied(occ, 0.05)


def test_it_drives_to_a_goal_in_an_empty_room() -> None:
    sim = _Sim(_room(wall=False))
    poses, sources = sim.run(IPlannerPlanner(), (1.0, 3.0, 0.3), (6.0, 3.0), steps=120)
    assert np.hypot(*(poses[-1, :2] - (6.0, 3.0))) < 0.15
    assert sources.count("network") > 0.6 * len(sources)
    assert sim.grid.distance_at(poses[:, :2]).min() > 0.267


def test_it_stops_or_turns_before_a_wall_right_ahead() -> None:
    sim = _Sim(_room(wall=True))
    planner = IPlannerPlanner()
    # the path leads straight through the wall (as a stale global path would)
    poses, sources = sim.run(planner, (1.5, 3.0, 0.0), (5.0, 3.0), steps=60)
    clearance = sim.grid.distance_at(poses[:, :2])
    assert clearance.min() > 0.267  # never touches the wall
    slowed = {"fear_turn"} & set(sources) or np.any(np.abs(poses[1:, 1] - 3.0) > 0.3)
    assert slowed  # it turned away or steered around, rather than pressing on
