"""CoHAN: human-aware TEB keeps more distance, stays in view, deterministic, fast enough."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from arena.config import load_config
from arena.core.types import Pose2D
from arena.experiment import run_experiment
from arena.nav.local_planners import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.cohan import CohanPlanner
from arena.nav.local_planners.teb_band import BandContext
from arena.robots.kinematics import integrate_twist
from tests.nav.planner_kit import DIFF, DT, RADIUS

PED_RADIUS = 0.3


def _ped_scan(pose: np.ndarray, ped: np.ndarray, n: int = 360) -> tuple[np.ndarray, np.ndarray]:
    """Laser ranges (robot frame) of a round pedestrian at world ``ped``."""
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    rel = ped - pose[:2]
    q = np.array([c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1]])
    b = np.cos(angles) * q[0] + np.sin(angles) * q[1]
    disc = b * b - (q @ q - PED_RADIUS**2)
    t = np.where(disc >= 0, b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
    return np.where(t > 0, t, np.inf), angles


def _crossing(name: str, start: tuple[float, float], vel: tuple[float, float]) -> tuple[
    float, int, np.ndarray
]:
    """Drive 8 m along +x past a pedestrian walking at constant ``vel`` from ``start``.

    Returns the closest centre distance (m), the number of ticks spent within 2 m of the
    pedestrian outside its 120° field of view, and the final pose.
    """
    planner = LOCAL_PLANNERS.build({"type": name})
    path = np.stack([np.linspace(0, 8, 80), np.zeros(80)], axis=-1)
    pose, twist = np.zeros(3), np.zeros(3)
    ped, v = np.array(start, dtype=float), np.array(vel, dtype=float)
    closest, behind = math.inf, 0
    for _ in range(120):
        ranges, angles = _ped_scan(pose, ped)
        obs = LocalObservation(
            pose=pose, twist=twist, goal=Pose2D(8.0, 0.0), path=path, limits=DIFF,
            robot_radius=RADIUS, dt=DT, scan_ranges=ranges, scan_angles=angles,
            kinematics="diff_drive", pedestrians=np.array([[*ped, *v]]),
        )
        cmd = planner.compute(obs)
        pose, twist = integrate_twist(pose[None], cmd[None], DT)[0], cmd
        ped = ped + v * DT
        rel = pose[:2] - ped
        d = float(np.hypot(*rel))
        closest = min(closest, d)
        bearing = math.remainder(math.atan2(rel[1], rel[0]) - math.atan2(v[1], v[0]), math.tau)
        behind += int(d < 2.0 and abs(bearing) > math.pi / 3)
    return closest, behind, pose


@pytest.mark.parametrize("start_y", [-2.5, 2.5])
def test_keeps_more_distance_than_teb_from_a_crossing_pedestrian(start_y: float) -> None:
    vel = (0.0, -0.6 * math.copysign(1.0, start_y))
    teb = _crossing("teb", (4.0, start_y), vel)
    cohan = _crossing("cohan", (4.0, start_y), vel)
    assert teb[0] > RADIUS + PED_RADIUS  # TEB does not collide either
    assert cohan[0] > teb[0] + 0.4  # measured: ~1.56 m vs ~0.78 m
    assert np.linalg.norm(cohan[2][:2] - (8.0, 0.0)) < 0.1  # and still reaches the goal
    assert cohan[1] < teb[1]  # and spends less time close behind the person


def _ctx(planner: CohanPlanner, band_xy: np.ndarray, ped: np.ndarray) -> tuple[
    BandContext, np.ndarray, np.ndarray, np.ndarray
]:
    n = len(band_xy) - 1
    times = np.arange(n + 1) * 0.5
    ctx = BandContext(
        n=n, start=np.array([*band_xy[0], 0.0]), end=band_xy[-1], twist=np.zeros(3),
        final=False, drive="diff_drive", limits=DIFF, radius=RADIUS, obstacles=np.zeros((0, 2)),
        obstacle_idx=np.zeros((n - 1, 0), dtype=np.int64), max_segment=1.0,
        path=band_xy, times=times, peds=ped[None, :],
        ped_pred=ped[None, None, :2] + times[:, None, None] * ped[None, None, 2:],
    )
    th = np.zeros(n + 1)
    return ctx, band_xy, th, np.full(n, 0.5)


def test_visibility_prefers_passing_in_front_of_a_walking_person() -> None:
    # A person at the origin walks along +x at 1 m/s (time stamps 0.5 s apart). Two candidate
    # bands run parallel to the walker, 1.5 m ahead of it (in its view) or 1.5 m behind it.
    planner = LOCAL_PLANNERS.build({"type": "cohan"})
    assert isinstance(planner, CohanPlanner)
    ped = np.array([0.0, 0.0, 1.0, 0.0])
    k = np.arange(6) * 0.5
    front = np.stack([1.5 + k, np.zeros(6)], axis=-1)
    back = np.stack([-1.5 + k, np.zeros(6)], axis=-1)
    costs = []
    for band in (front, back):
        ctx, pos, th, dt = _ctx(planner, band, ped)
        safety, vis, ttc = planner.extra_residuals(pos, th, dt, ctx)
        costs.append((float(safety @ safety), float(vis @ vis), float(ttc @ ttc)))
    (s_f, v_f, t_f), (s_b, v_b, t_b) = costs
    assert s_f == s_b == 0.0  # both keep the 1.2 m safety distance
    assert v_f == 0.0  # in view: no visibility cost
    # Behind: |α| = π, (π − π/3)/π = 2/3, closeness 1 − 1.5/3 = 0.5 → 30 · (1/3)² per pose.
    assert v_b == pytest.approx(4 * 30.0 * (1.0 / 3.0) ** 2)
    assert t_f == t_b == 0.0  # same velocity as the person: nothing closes in


def test_ttc_penalises_closing_in_fast() -> None:
    planner = LOCAL_PLANNERS.build({"type": "cohan"})
    assert isinstance(planner, CohanPlanner)
    ped = np.array([3.0, 0.0, 0.0, 0.0])  # standing 3 m ahead
    slow = np.stack([np.arange(5) * 0.1, np.zeros(5)], axis=-1)  # 0.2 m/s toward it
    fast = np.stack([np.arange(5) * 0.4, np.zeros(5)], axis=-1)  # 0.8 m/s toward it
    out = []
    for band in (slow, fast):
        ctx, pos, th, dt = _ctx(planner, band, ped)
        out.append(float(np.sum(planner.extra_residuals(pos, th, dt, ctx)[2] ** 2)))
    assert out[0] == 0.0
    assert out[1] > 0.0


def test_without_pedestrians_it_is_teb() -> None:
    rng = np.random.default_rng(5)
    ranges = rng.uniform(0.5, 4.0, 180)
    angles = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    path = np.stack([np.linspace(0, 5, 20), np.zeros(20)], axis=-1)
    obs = LocalObservation(
        pose=np.array([0.0, 0.0, 0.2]), twist=np.array([0.3, 0.0, 0.0]), goal=Pose2D(5.0, 0.0),
        path=path, limits=DIFF, robot_radius=RADIUS, dt=DT, scan_ranges=ranges,
        scan_angles=angles, kinematics="diff_drive",
    )
    teb = LOCAL_PLANNERS.build({"type": "teb"}).compute(obs)
    cohan = LOCAL_PLANNERS.build({"type": "cohan"}).compute(obs)
    np.testing.assert_array_equal(teb, cohan)


def test_deterministic() -> None:
    angles = np.linspace(-2.356, 2.356, 720)
    ranges = 2.0 / np.maximum(np.abs(np.cos(angles)), 0.3)
    path = np.stack([np.linspace(0, 5, 20), np.zeros(20)], axis=-1)
    peds = np.array([[2.0, -1.0, 0.0, 0.6], [3.0, 1.0, -0.5, 0.0], [1.5, 0.5, 0.3, 0.3]])
    obs = LocalObservation(
        pose=np.zeros(3), twist=np.array([0.5, 0.0, 0.0]), goal=Pose2D(5.0, 0.0), path=path,
        limits=DIFF, robot_radius=RADIUS, dt=DT, scan_ranges=ranges, scan_angles=angles,
        kinematics="diff_drive", pedestrians=peds,
    )
    planner = LOCAL_PLANNERS.build({"type": "cohan"})
    first = planner.compute(obs)
    for _ in range(3):  # warm-started from its own previous band: not the first answer
        planner.compute(obs)
    planner.reset()
    np.testing.assert_array_equal(planner.compute(obs), first)
    np.testing.assert_array_equal(LOCAL_PLANNERS.build({"type": "cohan"}).compute(obs), first)


def test_reaches_the_goal_in_an_empty_room(tmp_path: Path) -> None:
    cfg = load_config(None, [
        "navigation.local_planner.type=cohan", "map.type=empty", "task.obstacles.static=0",
        "task.obstacles.dynamic=0", "task.timeout=40", "output.video=false", "episodes=5",
        "task.robots.min_goal_distance=5",
    ])
    _, results = run_experiment(cfg, tmp_path)
    assert [r.outcome for r in results] == ["success"] * 5
    assert all(r.collisions == 0 for r in results)
