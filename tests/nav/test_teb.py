"""TEB: command limits, goal reaching, obstacle avoidance, band feasibility, determinism, speed."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from arena.config import load_config
from arena.core.types import Pose2D
from arena.experiment import run_experiment
from arena.nav.local_planners import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.teb import TEBPlanner
from tests.nav.planner_kit import (
    BEHIND_ASIDE,
    CAR,
    DIFF,
    DRIVES,
    DT,
    RADIUS,
    assert_within_limits,
    drive,
    random_case,
)
from tests.nav.planner_kit import line as _line
from tests.nav.planner_kit import step as _step


def _teb(**kw: object) -> TEBPlanner:
    planner = LOCAL_PLANNERS.build({"type": "teb", **kw})
    assert isinstance(planner, TEBPlanner)
    return planner


def _obs(pose, path, twist=(0.0, 0.0, 0.0), limits=DIFF, kin="diff_drive", ranges=None,
         angles=None, peds=None) -> LocalObservation:
    path = np.asarray(path, dtype=float)
    return LocalObservation(
        pose=np.asarray(pose, dtype=float), twist=np.asarray(twist, dtype=float),
        goal=Pose2D(*path[-1]), path=path, limits=limits, robot_radius=RADIUS, dt=DT,
        scan_ranges=np.zeros(0) if ranges is None else np.asarray(ranges, dtype=float),
        scan_angles=np.zeros(0) if angles is None else np.asarray(angles, dtype=float),
        kinematics=kin,
        pedestrians=np.zeros((0, 4)) if peds is None else np.asarray(peds, dtype=float),
    )


def _post_scan(pose: np.ndarray, centre: np.ndarray, r: float, n: int = 360) -> tuple[
    np.ndarray, np.ndarray
]:
    """Ranges (robot frame, 8 m max) of a round post of radius ``r`` at world ``centre``."""
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    rel = centre - pose[:2]
    q = np.array([c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1]])
    b = np.cos(angles) * q[0] + np.sin(angles) * q[1]
    disc = b * b - (q @ q - r * r)
    t = np.where(disc >= 0, b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
    return np.where((t > 0) & (t < 8.0), t, np.inf), angles


@pytest.mark.parametrize("kin", sorted(DRIVES))
def test_commands_stay_in_limits(kin: str) -> None:
    lim = DRIVES[kin]
    rng = np.random.default_rng(3)
    planner = _teb()
    for _ in range(20):
        twist, pose, path, ranges, angles = random_case(rng, lim, kin)
        peds = rng.uniform([-3, -3, -1, -1], [3, 3, 1, 1], (2, 4))
        cmd = planner.compute(_obs(pose, path, twist, lim, kin, ranges, angles, peds))
        assert_within_limits(cmd, twist, lim, kin)


@pytest.mark.parametrize("kin", ["diff_drive", "omni", "legged"])
def test_reaches_a_goal_behind_and_aside(kin: str) -> None:
    planner = _teb()
    pose, twist = drive(planner, BEHIND_ASIDE, kin, 300)
    assert np.linalg.norm(pose[:2] - BEHIND_ASIDE[-1]) < 0.1
    assert np.allclose(twist, 0.0, atol=0.3)


def test_steers_around_an_obstacle() -> None:
    planner = _teb()
    post, r = np.array([3.0, 0.05]), 0.15
    path = _line(0.0, 6.0)
    pose, twist = np.zeros(3), np.zeros(3)
    closest, lateral = np.inf, 0.0
    for _ in range(150):
        ranges, angles = _post_scan(pose, post, r)
        cmd = planner.compute(_obs(pose, path, twist, DIFF, "diff_drive", ranges, angles))
        pose, twist = _step(pose, cmd), cmd
        closest = min(closest, float(np.hypot(*(pose[:2] - post))) - r)
        lateral = max(lateral, abs(float(pose[1])))
    assert closest > RADIUS  # never touched the post
    assert lateral > 0.3  # it went around, not through
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.1


def _band_velocities(planner: TEBPlanner) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    assert planner.band is not None
    poses, dt = planner.band.poses, planner.band.dt
    d = np.diff(poses[:, :2], axis=0)
    ds = np.hypot(d[:, 0], d[:, 1])
    return ds / dt, np.diff(poses[:, 2]) / dt, ds


def test_band_respects_velocity_limits() -> None:
    planner = _teb()
    path = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 3.0]])
    pose, twist = np.zeros(3), np.zeros(3)
    for _ in range(15):
        cmd = planner.compute(_obs(pose, path, twist, DIFF, "diff_drive"))
        pose, twist = _step(pose, cmd), cmd
        v, w, _ = _band_velocities(planner)
        assert np.all(v <= DIFF.vx_max * 1.05)
        assert np.all(np.abs(w) <= DIFF.omega_max * 1.05)
    assert twist[0] > 0.5  # it accelerates toward the cruise speed


def test_ackermann_band_keeps_the_turning_radius() -> None:
    planner = _teb()
    t = np.linspace(0.0, math.pi, 60)
    path = np.stack([2.0 * np.sin(t), 2.0 * (1.0 - np.cos(t))], axis=-1)
    pose, twist = np.zeros(3), np.zeros(3)
    for k in range(150):
        cmd = planner.compute(_obs(pose, path, twist, CAR, "ackermann"))
        assert abs(cmd[2]) <= abs(cmd[0]) / CAR.min_turning_radius + 1e-9
        if k == 5:
            assert planner.band is not None
            _, _, ds = _band_velocities(planner)
            dth = np.abs(np.diff(planner.band.poses[:, 2]))
            # Curvature of every segment within 1/R_min (10 % slack for the soft constraint).
            assert np.all(dth <= ds / CAR.min_turning_radius * 1.1 + 1e-3)
        pose, twist = _step(pose, cmd), cmd
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.5


def test_deterministic_and_reset() -> None:
    rng = np.random.default_rng(7)
    ranges = rng.uniform(0.5, 4.0, 180)
    angles = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    peds = np.array([[2.0, 1.0, 0.0, -0.5]])
    obs = _obs([0, 0, 0.3], _line(0, 5), (0.3, 0, 0.1), DIFF, "diff_drive", ranges, angles, peds)
    a = _teb().compute(obs)
    planner = _teb()
    planner.compute(_obs([1, 1, 0], _line(0, 5)))
    planner.reset()
    np.testing.assert_array_equal(planner.compute(obs), a)


def test_dynamic_obstacle_moves_the_band() -> None:
    # A pedestrian predicted to stand on the path in 2 s pushes the band aside there.
    path = _line(0.0, 5.0)
    peds = np.array([[2.0, -1.0, 0.0, 0.5]])
    plain, aware = _teb(), _teb()
    for _ in range(5):  # the band is warm-started: repeated cycles keep optimising it
        plain.compute(_obs([0, 0, 0], path, (0.8, 0, 0)))
        aware.compute(_obs([0, 0, 0], path, (0.8, 0, 0), peds=peds))
    assert plain.band is not None and aware.band is not None
    assert np.max(np.abs(plain.band.poses[:, 1])) < 0.05
    assert np.max(np.abs(aware.band.poses[:, 1])) > 0.2


def test_jackal_reaches_the_goal_in_an_empty_room(tmp_path: Path) -> None:
    cfg = load_config(None, [
        "navigation.local_planner.type=teb", "map.type=empty", "task.obstacles.static=0",
        "task.obstacles.dynamic=0", "task.timeout=40", "output.video=false", "episodes=5",
        "task.robots.min_goal_distance=5",
    ])
    _, results = run_experiment(cfg, tmp_path)
    assert [r.outcome for r in results] == ["success"] * 5
    assert all(r.collisions == 0 for r in results)
