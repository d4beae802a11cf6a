"""Social force and ORCA local planners: limits, goals, obstacles, determinism, cycle time."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from arena.config import load_config
from arena.experiment import run_experiment
from arena.nav.local_planners import LOCAL_PLANNERS
from arena.nav.local_planners.orca_planner import OrcaPlanner, orca_velocity
from arena.nav.local_planners.social_force import SocialForcePlanner
from tests.nav.planner_kit import (
    BEHIND_ASIDE,
    CAR,
    DIFF,
    DRIVES,
    DT,
    OMNI,
    RADIUS,
    assert_within_limits,
    drive,
    random_case,
)
from tests.nav.planner_kit import line as _line
from tests.nav.planner_kit import obs as _obs
from tests.nav.planner_kit import post_scan as _post_scan
from tests.nav.planner_kit import step as _step
from tests.nav.planner_kit import wall_scan as _wall_scan

NAMES = ["social_force", "orca"]


def test_registered_types() -> None:
    assert isinstance(LOCAL_PLANNERS.build({"type": "social_force"}), SocialForcePlanner)
    assert isinstance(LOCAL_PLANNERS.build({"type": "orca"}), OrcaPlanner)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kin", sorted(DRIVES))
def test_commands_stay_within_limits(name: str, kin: str) -> None:
    lim = DRIVES[kin]
    rng = np.random.default_rng(3)
    planner = LOCAL_PLANNERS.build({"type": name})
    for _ in range(30):
        twist, pose, path, ranges, angles = random_case(rng, lim, kin)
        cmd = planner.compute(_obs(pose, path, twist, lim, kin, ranges, angles))
        assert_within_limits(cmd, twist, lim, kin)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kin", ["diff_drive", "omni", "legged"])
def test_reaches_a_goal_behind_and_aside(name: str, kin: str) -> None:
    planner = LOCAL_PLANNERS.build({"type": name})
    pose, twist = drive(planner, BEHIND_ASIDE, kin, 400)
    assert np.linalg.norm(pose[:2] - BEHIND_ASIDE[-1]) < 0.1
    assert np.allclose(twist, 0.0, atol=0.3)


@pytest.mark.parametrize("name", NAMES)
def test_car_reaches_a_goal_with_its_turning_radius(name: str) -> None:
    planner = LOCAL_PLANNERS.build({"type": name})
    t = np.linspace(0.0, math.pi, 60)
    path = np.stack([2.0 * np.sin(t), 2.0 * (1.0 - np.cos(t))], axis=-1)
    pose, twist = np.zeros(3), np.zeros(3)
    for _ in range(250):
        cmd = planner.compute(_obs(pose, path, twist, CAR, "ackermann"))
        assert abs(cmd[2]) <= abs(cmd[0]) / CAR.min_turning_radius + 1e-9
        pose, twist = _step(pose, cmd), cmd
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.5


@pytest.mark.parametrize("name", NAMES)
def test_stops_before_a_wall(name: str) -> None:
    planner = LOCAL_PLANNERS.build({"type": name})
    path = _line(0.0, 6.0)
    pose, twist = np.zeros(3), np.array([0.8, 0.0, 0.0])
    for _ in range(200):
        ranges, angles = _wall_scan(pose, 3.0)
        cmd = planner.compute(_obs(pose, path, twist, DIFF, "diff_drive", ranges, angles))
        pose, twist = _step(pose, cmd), cmd
        assert 3.0 - pose[0] > RADIUS  # never touches the wall
    assert abs(twist[0]) < 0.05
    assert 3.0 - pose[0] - RADIUS < 0.8  # it did not stop far too early


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kin", ["diff_drive", "omni"])
def test_steers_around_a_post(name: str, kin: str) -> None:
    lim = DRIVES[kin]
    planner = LOCAL_PLANNERS.build({"type": name})
    path = _line(0.0, 5.0)
    centre, post = np.array([2.5, 0.05]), 0.2
    pose, twist = np.zeros(3), np.zeros(3)
    closest = math.inf
    for _ in range(300):
        ranges, angles = _post_scan(pose, centre, post)
        cmd = planner.compute(_obs(pose, path, twist, lim, kin, ranges, angles))
        pose, twist = _step(pose, cmd), cmd
        closest = min(closest, float(np.linalg.norm(pose[:2] - centre)) - post - RADIUS)
    assert closest > 0.0
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.15


def test_social_force_is_pushed_by_pedestrians() -> None:
    planner = SocialForcePlanner()
    obs = _obs([0, 0, 0], _line(0, 5), (0.5, 0, 0), OMNI, "omni")
    free = planner.force(obs, np.array([1.0, 0.0]), 0.8)
    pushed = planner.force(obs, np.array([1.0, 0.0]), 0.8, np.array([[0.8, 0.3]]))
    assert pushed[0] < free[0] and pushed[1] < free[1]  # pushed back and to the right
    assert planner.compute(obs, np.array([[0.8, 0.3]])).shape == (3,)


def test_orca_velocity_avoids_a_static_neighbour() -> None:
    # Heading straight at a point 1 m ahead: ORCA deflects and keeps out of its cone.
    v = orca_velocity(np.array([0.8, 0.0]), np.array([0.8, 0.0]), np.array([[1.0, 0.0]]),
                      0.4, 1.0, 2.0, DT)
    assert abs(v[1]) > 1e-3 or v[0] < 0.8
    free = orca_velocity(np.zeros(2), np.array([0.5, 0.2]), np.zeros((0, 2)), 0.4, 1.0, 2.0, DT)
    np.testing.assert_allclose(free, [0.5, 0.2])


@pytest.mark.parametrize("name", NAMES)
def test_deterministic_and_reset(name: str) -> None:
    rng = np.random.default_rng(7)
    ranges = rng.uniform(0.5, 4.0, 180)
    angles = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    obs = _obs([0, 0, 0.3], _line(0, 5), (0.3, 0, 0.1), DIFF, "diff_drive", ranges, angles)
    a = LOCAL_PLANNERS.build({"type": name}).compute(obs)
    planner = LOCAL_PLANNERS.build({"type": name})
    planner.compute(_obs([1, 1, 0], _line(0, 5)))
    planner.reset()
    np.testing.assert_array_equal(planner.compute(obs), a)


@pytest.mark.parametrize("name", NAMES)
def test_reaches_goals_in_an_empty_room(name: str, tmp_path: Path) -> None:
    cfg = load_config(None, [
        f"navigation.local_planner.type={name}", "map.type=empty", "task.obstacles.static=0",
        "task.obstacles.dynamic=0", "task.timeout=40", "output.video=false", "episodes=5",
        "task.robots.min_goal_distance=5",
    ])
    _, results = run_experiment(cfg, tmp_path)
    assert [r.outcome for r in results] == ["success"] * 5
    assert all(r.collisions == 0 for r in results)


@pytest.mark.parametrize("name", ["dwa", "teb", "pure_pursuit", "social_force", "orca"])
def test_inside_the_stack_tolerance_a_wrong_heading_is_turned_not_circled(name):
    import dataclasses

    from arena.core.types import Pose2D
    from arena.nav.local_planners import LOCAL_PLANNERS
    from tests.nav.planner_kit import line, obs

    path = line(0.0, 3.0)
    goal = Pose2D(3.0, 0.0, math.pi / 2)  # the goal wants the robot facing +y
    # 0.15 m short of the goal, facing +x, at rest; the stack accepts 0.27 m and 30°.
    o = dataclasses.replace(obs([2.85, 0.0, 0.0], path), goal=goal,
                            goal_yaw_tolerance=math.radians(30), goal_xy_tolerance=0.27)
    cmd = LOCAL_PLANNERS.build({"type": name}).compute(o)
    assert abs(cmd[0]) < 1e-9 and cmd[2] > 0.1, cmd  # turn left on the spot
    far = dataclasses.replace(o, goal_xy_tolerance=0.1)  # outside: still driving to the goal
    assert LOCAL_PLANNERS.build({"type": name}).compute(far)[0] > 0
