"""DWA: dynamic-window limits, goal reaching, stopping before obstacles, car turning radius."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from arena.config import load_config
from arena.experiment import run_experiment
from arena.nav.local_planners import LOCAL_PLANNERS
from arena.nav.local_planners.dwa import DWAPlanner
from tests.nav.planner_kit import (
    BEHIND_ASIDE,
    CAR,
    DIFF,
    DRIVES,
    LEGGED,
    RADIUS,
    assert_within_limits,
    drive,
    random_case,
)
from tests.nav.planner_kit import line as _line
from tests.nav.planner_kit import obs as _obs
from tests.nav.planner_kit import step as _step
from tests.nav.planner_kit import wall_scan as _wall_scan


def _dwa(**kw: object) -> DWAPlanner:
    planner = LOCAL_PLANNERS.build({"type": "dwa", **kw})
    assert isinstance(planner, DWAPlanner)
    return planner


@pytest.mark.parametrize("kin", sorted(DRIVES))
def test_commands_stay_in_the_dynamic_window(kin: str) -> None:
    lim = DRIVES[kin]
    rng = np.random.default_rng(3)
    planner = _dwa()
    for _ in range(30):
        twist, pose, path, ranges, angles = random_case(rng, lim, kin)
        cmd = planner.compute(_obs(pose, path, twist, lim, kin, ranges, angles))
        assert_within_limits(cmd, twist, lim, kin)


@pytest.mark.parametrize("kin", ["diff_drive", "omni", "legged"])
def test_reaches_a_goal_behind_and_aside(kin: str) -> None:
    planner = _dwa()
    pose, twist = drive(planner, BEHIND_ASIDE, kin, 400)
    assert np.linalg.norm(pose[:2] - BEHIND_ASIDE[-1]) < 0.1
    assert np.allclose(twist, 0.0, atol=0.3)


def test_stops_before_a_wall() -> None:
    planner = _dwa()
    path = _line(0.0, 6.0)
    pose, twist = np.zeros(3), np.array([0.8, 0.0, 0.0])
    for _ in range(200):
        ranges, angles = _wall_scan(pose, 3.0)
        cmd = planner.compute(_obs(pose, path, twist, DIFF, "diff_drive", ranges, angles))
        pose, twist = _step(pose, cmd), cmd
        assert 3.0 - pose[0] > RADIUS  # never touches the wall
    assert abs(twist[0]) < 1e-9
    assert 3.0 - pose[0] - RADIUS < 0.6  # got reasonably close: it did not stop early


def test_ackermann_respects_the_turning_radius() -> None:
    planner = _dwa()
    # A left turn of radius 2 m (feasible for the car) ending behind the start.
    t = np.linspace(0.0, math.pi, 60)
    path = np.stack([2.0 * np.sin(t), 2.0 * (1.0 - np.cos(t))], axis=-1)
    pose, twist = np.zeros(3), np.zeros(3)
    moved = False
    for _ in range(150):
        cmd = planner.compute(_obs(pose, path, twist, CAR, "ackermann"))
        assert abs(cmd[2]) <= abs(cmd[0]) / CAR.min_turning_radius + 1e-9
        moved |= cmd[0] > 0.1
        pose, twist = _step(pose, cmd), cmd
    assert moved
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.5


def test_samples_of_a_car_follow_curvature_bounds() -> None:
    planner = _dwa()
    samples = planner.samples(_obs(np.zeros(3), _line(0, 3), (0.5, 0, 0), CAR, "ackermann"))
    assert np.all(np.abs(samples[:, 2]) <= samples[:, 0] / CAR.min_turning_radius + 1e-12)
    assert np.all(samples[:, 1] == 0.0)


def test_deterministic_and_reset() -> None:
    rng = np.random.default_rng(7)
    ranges = rng.uniform(0.5, 4.0, 180)
    angles = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    obs = _obs([0, 0, 0.3], _line(0, 5), (0.3, 0, 0.1), DIFF, "diff_drive", ranges, angles)
    a = _dwa().compute(obs)
    planner = _dwa()
    planner.compute(_obs([1, 1, 0], _line(0, 5)))
    planner.reset()
    np.testing.assert_array_equal(planner.compute(obs), a)


def test_reverse_only_when_allowed() -> None:
    path = np.array([[0.0, 0.0], [-3.0, 0.0]])
    cmd = _dwa().compute(_obs([0, 0, 0], path, (0, 0, 0), LEGGED, "legged"))
    assert cmd[0] >= 0.0
    samples = _dwa(allow_reverse=True).samples(_obs([0, 0, 0], path, (0, 0, 0), LEGGED, "legged"))
    assert samples[:, 0].min() < 0.0


def test_jackal_reaches_the_goal_in_an_empty_room(tmp_path: Path) -> None:
    cfg = load_config(None, [
        "navigation.local_planner.type=dwa", "map.type=empty", "task.obstacles.static=0",
        "task.obstacles.dynamic=0", "task.timeout=40", "output.video=false", "episodes=5",
        "task.robots.min_goal_distance=5",
    ])
    _, results = run_experiment(cfg, tmp_path)
    assert [r.outcome for r in results] == ["success"] * 5
    assert all(r.collisions == 0 for r in results)
