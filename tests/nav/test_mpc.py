"""MPC: limits, goal reaching, obstacles, car turning radius, determinism and cycle time."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("casadi")

from arena.config import load_config
from arena.experiment import run_experiment
from arena.nav.local_planners import LOCAL_PLANNERS
from arena.nav.local_planners.mpc import MPCPlanner
from arena.robots.limits import VelocityLimits
from tests.nav.planner_kit import (
    BEHIND_ASIDE,
    CAR,
    DIFF,
    DRIVES,
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


def _mpc(**kw: object) -> MPCPlanner:
    planner = LOCAL_PLANNERS.build({"type": "mpc", **kw})
    assert isinstance(planner, MPCPlanner)
    return planner


def test_missing_casadi_is_a_config_error(monkeypatch: pytest.MonkeyPatch) -> None:
    import builtins

    from arena.core.errors import ConfigError

    real = builtins.__import__

    def fake(name: str, *args: object, **kwargs: object) -> object:
        if name == "casadi":
            raise ImportError(name)
        return real(name, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(builtins, "__import__", fake)
    with pytest.raises(ConfigError, match="arena\\[mpc\\]"):
        MPCPlanner()


@pytest.mark.parametrize("kin", sorted(DRIVES))
def test_commands_stay_within_limits(kin: str) -> None:
    lim = DRIVES[kin]
    rng = np.random.default_rng(3)
    planner = _mpc()
    for _ in range(15):
        twist, pose, path, ranges, angles = random_case(rng, lim, kin)
        cmd = planner.compute(_obs(pose, path, twist, lim, kin, ranges, angles))
        assert_within_limits(cmd, twist, lim, kin)


@pytest.mark.parametrize("kin", ["diff_drive", "omni", "legged"])
def test_reaches_a_goal_behind_and_aside(kin: str) -> None:
    planner = _mpc()
    pose, twist = drive(planner, BEHIND_ASIDE, kin, 300)
    assert np.linalg.norm(pose[:2] - BEHIND_ASIDE[-1]) < 0.1
    assert np.allclose(twist, 0.0, atol=0.3)
    assert planner.failures == 0


def test_stops_before_a_wall() -> None:
    planner = _mpc()
    path = _line(0.0, 6.0)
    pose, twist = np.zeros(3), np.array([0.8, 0.0, 0.0])
    for _ in range(150):
        ranges, angles = _wall_scan(pose, 3.0)
        cmd = planner.compute(_obs(pose, path, twist, DIFF, "diff_drive", ranges, angles))
        pose, twist = _step(pose, cmd), cmd
        assert 3.0 - pose[0] > RADIUS  # never touches the wall
    assert abs(twist[0]) < 0.05
    assert 3.0 - pose[0] - RADIUS < 0.6  # got reasonably close: it did not stop early


@pytest.mark.parametrize("kin", ["diff_drive", "omni"])
def test_steers_around_a_post(kin: str) -> None:
    lim = DRIVES[kin]
    planner = _mpc()
    path = _line(0.0, 5.0)
    centre, post = np.array([2.5, 0.05]), 0.2
    pose, twist = np.zeros(3), np.zeros(3)
    closest = math.inf
    for _ in range(200):
        ranges, angles = _post_scan(pose, centre, post)
        cmd = planner.compute(_obs(pose, path, twist, lim, kin, ranges, angles))
        pose, twist = _step(pose, cmd), cmd
        closest = min(closest, float(np.linalg.norm(pose[:2] - centre)) - post - RADIUS)
    assert closest > 0.0  # never touched the post
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.15  # and got past it to the goal


def test_ackermann_respects_the_turning_radius() -> None:
    planner = _mpc()
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
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.3


def test_deterministic_and_reset() -> None:
    rng = np.random.default_rng(7)
    ranges = rng.uniform(0.5, 4.0, 180)
    angles = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    obs = _obs([0, 0, 0.3], _line(0, 5), (0.3, 0, 0.1), DIFF, "diff_drive", ranges, angles)
    a = _mpc().compute(obs)
    planner = _mpc()
    planner.compute(_obs([1, 1, 0], _line(0, 5)))
    planner.reset()
    np.testing.assert_array_equal(planner.compute(obs), a)


def test_solver_succeeds_every_cycle_in_a_corridor() -> None:
    # A jackal-like 720-beam scan in a corridor, 20 closed-loop cycles: the solver never falls
    # back. (Compute time per cycle is a figure of benchmarks/planners.py, not a test.)
    planner = _mpc()
    angles = np.linspace(-2.356, 2.356, 720)
    ranges = 1.5 / np.maximum(np.abs(np.sin(angles)), 0.2)
    lim = VelocityLimits(-2.0, 2.0, 0.0, 0.0, 4.0, 20.0, 0.0, 25.0)
    pose, twist = np.zeros(3), np.array([0.5, 0.0, 0.0])
    path = _line(0, 10)
    planner.compute(_obs(pose, path, twist, lim, "diff_drive", ranges, angles))  # build
    for _ in range(20):
        cmd = planner.compute(_obs(pose, path, twist, lim, "diff_drive", ranges, angles))
        pose, twist = _step(pose, cmd), cmd
    assert planner.failures == 0
    assert pose[0] > 0.5  # it drove along the corridor


def test_reaches_goals_in_an_empty_room(tmp_path: Path) -> None:
    cfg = load_config(None, [
        "navigation.local_planner.type=mpc", "map.type=empty", "task.obstacles.static=0",
        "task.obstacles.dynamic=0", "task.timeout=40", "output.video=false", "episodes=5",
        "task.robots.min_goal_distance=5",
    ])
    _, results = run_experiment(cfg, tmp_path)
    assert [r.outcome for r in results] == ["success"] * 5
    assert all(r.collisions == 0 for r in results)
