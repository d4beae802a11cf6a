"""The trail local planner: DRL-VO's CNN policy with TRAIL's rotate-in-place rule."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from arena.config import load_config
from arena.experiment import run_experiment
from arena.learn.config import SemanticObsConfig
from arena.learn.planners.trail import TRAIL_WEIGHTS, TrailPlanner
from arena.learn.policy import NumpyPolicy
from arena.nav.local_planners.base import LOCAL_PLANNERS, LocalObservation
from arena.robots.presets import load_robot

TRAIN_CONFIG = (Path(__file__).resolve().parents[2] / "arena" / "learn" / "data" / "train"
                / "trail.yaml")


def _obs(pose, *, ranges=None, path=None, goal=(8.0, 0.0), peds=None, robot="jackal",
         time=0.0):
    rb = load_robot(robot)
    angles = rb.laser.angles()
    return LocalObservation(
        pose=np.asarray(pose, dtype=np.float64),
        twist=np.zeros(3),
        goal=np.array([goal[0], goal[1], 0.0]),
        path=np.asarray(path if path is not None else [pose[:2], goal], dtype=np.float64),
        limits=rb.limits(),
        robot_radius=rb.radius,
        dt=0.1,
        scan_ranges=np.full(angles.size, 20.0) if ranges is None else ranges,
        scan_angles=angles,
        pedestrians=np.zeros((0, 4)) if peds is None else np.asarray(peds, dtype=np.float64),
        time=time,
    )


def test_registered_learned_with_small_shipped_weights():
    assert "learned" in LOCAL_PLANNERS.entry("trail").tags
    assert TRAIL_WEIGHTS.stat().st_size < 5_000_000
    pol = NumpyPolicy.load(TRAIL_WEIGHTS)
    assert pol.extractor is not None and pol.extractor["type"] == "drlvo_cnn"
    assert set(pol.keys) == {"lidar", "goal", "last_action", "semantic"}
    assert len(pol.shapes["lidar"]) == 2  # stacked scans


def test_pedestrian_map_is_in_the_robot_frame():
    """A person 2 m to the robot's left walking the robot's way shows as such on the grid."""
    planner = TrailPlanner()
    sc = SemanticObsConfig(**planner.policy.meta["observation"]["semantic"])
    heading = 0.7
    left = np.array([-math.sin(heading), math.cos(heading)])
    fwd = np.array([math.cos(heading), math.sin(heading)])
    pos = np.array([3.0, 1.0]) + 2.0 * left
    person = [*pos, *(0.8 * fwd)]
    grid = planner.semantic(_obs([3.0, 1.0, heading], peds=[person]))
    assert grid.shape == (len(sc.channels), sc.size, sc.size)
    col = sc.size // 2 + math.floor(0.0 / sc.roi * sc.size)
    row = sc.size // 2 + math.floor(2.0 / sc.roi * sc.size)
    ch = {c: i for i, c in enumerate(sc.channels)}
    assert np.count_nonzero(grid[ch["pedestrian_vel_x"]]) == 1
    assert grid[ch["pedestrian_vel_x"], row, col] == pytest.approx(0.8, abs=1e-6)
    assert grid[ch["pedestrian_vel_y"], row, col] == pytest.approx(0.0, abs=1e-6)
    if "pedestrian_location" in ch:
        assert grid[ch["pedestrian_location"], row, col] == 1.0
    far = [*(np.array([3.0, 1.0]) + 50.0 * fwd), 0.0, 0.0]
    assert not planner.semantic(_obs([3.0, 1.0, heading], peds=[far])).any()


def test_turns_in_place_toward_a_subgoal_behind_until_aligned():
    planner = TrailPlanner(TrailPlanner.Params(rotate_angle=1.2, align_angle=0.35))
    heading = 0.0
    pose = np.array([5.0, 5.0, heading])
    behind_left = (2.0, 7.0)  # bearing ≈ 2.36 rad: to the left, behind
    turns = 0
    for _ in range(80):
        o = _obs(pose, goal=behind_left)
        cmd = planner.compute(o)
        bearing = math.atan2(behind_left[1] - pose[1], behind_left[0] - pose[0]) - pose[2]
        bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
        if abs(bearing) > 0.35 + 0.15:  # turning: no translation, toward the subgoal
            assert cmd[0] == 0.0 and cmd[2] > 0.0
            turns += 1
        pose = pose + np.array([0.0, 0.0, cmd[2] * 0.1])
        if abs(bearing) < 0.3:
            break
    assert turns > 5
    assert abs(bearing) < 0.35  # it turned until aligned, then the policy drives
    assert planner.should_turn(_obs(pose, goal=behind_left))[0] is False


def test_blocked_front_turns_only_when_the_subgoal_is_off_heading():
    rb = load_robot("jackal")
    angles = rb.laser.angles()
    ranges = np.where(np.abs(angles) < 0.3, rb.radius + 0.1, 20.0)  # a wall 0.1 m ahead
    planner = TrailPlanner()
    off = (5.0 + 3 * math.cos(0.6), 5.0 + 3 * math.sin(0.6))
    turn, bearing = planner.should_turn(_obs([5.0, 5.0, 0.0], ranges=ranges, goal=off))
    assert turn and bearing == pytest.approx(0.6, abs=1e-6)
    planner.reset()
    ahead = (8.0, 5.0)
    assert not planner.should_turn(_obs([5.0, 5.0, 0.0], ranges=ranges, goal=ahead))[0]
    planner.reset()
    assert not planner.should_turn(_obs([5.0, 5.0, 0.0], goal=off))[0]  # free: the policy


def test_car_like_robots_never_turn_in_place():
    o = _obs([5.0, 5.0, 0.0], goal=(2.0, 7.0), robot="f1tenth")
    cmd = TrailPlanner().compute(o)
    lim = o.limits
    assert lim.min_turning_radius > 0
    assert abs(cmd[2]) <= abs(cmd[0]) / lim.min_turning_radius + 1e-9


def test_shipped_policy_reaches_the_goal_of_seeded_barn_episodes(tmp_path):
    cfg = load_config(TRAIN_CONFIG, ["seed=77", "task.obstacles.dynamic=0",
                                     "navigation.local_planner={type: trail}",
                                     "episodes=2"])
    _, results = run_experiment(cfg, tmp_path)
    assert [r.error for r in results] == ["", ""]
    assert [r.outcome for r in results] == ["success", "success"]


def _at(pose, t):
    return _obs(pose, time=t)


def test_dwa_drives_for_fallback_time_after_a_stall_then_the_policy_again():
    planner = TrailPlanner(TrailPlanner.Params(stall_time=3.0, stall_distance=0.1,
                                               fallback_time=2.0))
    pose = np.array([5.0, 5.0, 0.0])
    ticks = [round(0.1 * k, 1) for k in range(0, 95)]
    states = {t: planner.stalled(_at(pose, t)) for t in ticks}
    assert not any(v for t, v in states.items() if t < 3.0)
    assert all(v for t, v in states.items() if 3.0 <= t < 5.0)  # DWA for fallback_time
    assert not any(v for t, v in states.items() if 5.0 <= t < 8.0)  # the policy, watched again
    assert states[8.0]  # still no progress: the next stall
    moving = TrailPlanner(TrailPlanner.Params(stall_time=3.0))
    assert not any(moving.stalled(_at([5.0 + 0.05 * k, 5.0, 0.0], 0.1 * k)) for k in range(100))
    never = TrailPlanner(TrailPlanner.Params(stall_time=0.0))
    assert not any(never.stalled(_at(pose, 0.1 * k)) for k in range(100))
