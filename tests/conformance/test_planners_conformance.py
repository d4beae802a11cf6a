"""Conformance of every registered global and local planner with its protocol.

Global planners: ``(k, 2)`` finite waypoints from the start to the goal over free cells,
deterministic, inputs untouched, typed failures. Local planners: ``(3,)`` finite commands inside
the velocity box and one tick of acceleration, deterministic after ``reset``, observation
untouched, for every kinematics they declare.
"""

from __future__ import annotations

import copy
import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from arena.core.errors import GoalOccupied, NoPathFound, StartOccupied
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav import (
    GLOBAL_PLANNERS,
    KINEMATICS,
    LOCAL_PLANNERS,
    GlobalPlanner,
    LocalObservation,
    LocalPlanner,
)
from arena.robots.limits import VelocityLimits

RES = 0.05
DT = 0.1

LIMITS = {
    "diff_drive": VelocityLimits(0.0, 1.0, 0.0, 0.0, 1.5, 1.0, 0.0, 3.0),
    "legged": VelocityLimits(-0.3, 0.7, 0.0, 0.0, 1.0, 0.8, 0.0, 2.0),
    "omni": VelocityLimits(-0.8, 0.8, -0.6, 0.6, 1.2, 1.0, 1.0, 2.0),
    "ackermann": VelocityLimits(0.0, 1.5, 0.0, 0.0, 1.5, 1.0, 0.0, 2.0, min_turning_radius=1.2),
}


def _maze() -> OccupancyGrid:
    occ = np.zeros((100, 120), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[:70, 40] = True
    occ[30:, 80] = True
    occ[45:55, 55:65] = True
    return OccupancyGrid.from_occupied(occ, RES, origin=(-1.0, 0.5))


def _free_cells_along(grid: OccupancyGrid, path: np.ndarray) -> bool:
    for a, b in itertools.pairwise(path):
        n = max(2, int(np.ceil(np.linalg.norm(b - a) / grid.resolution * 20)))
        pts = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
        if grid.is_occupied(pts).any():
            return False
    return True


# -- global planners ------------------------------------------------------------------------------


@pytest.fixture(params=GLOBAL_PLANNERS.names())
def global_name(request: pytest.FixtureRequest) -> str:
    return request.param


def test_global_planner_builds_and_matches_protocol(global_name: str) -> None:
    planner = GLOBAL_PLANNERS.build({"type": global_name})
    assert isinstance(planner, GlobalPlanner)
    assert GLOBAL_PLANNERS.entry(global_name).summary


@pytest.mark.parametrize(
    ("start", "goal"),
    [((-0.5, 1.0), (4.5, 4.5)), ((4.7, 4.6), (-0.6, 4.7)), ((0.0, 1.0), (0.4, 1.2))],
)
def test_global_planner_output(global_name: str, start: tuple, goal: tuple) -> None:
    grid = _maze()
    data = grid.data.copy()
    s, g = Pose2D(*start, 0.3), Pose2D(*goal, -1.0)
    s_copy, g_copy = copy.copy(s), copy.copy(g)
    planner = GLOBAL_PLANNERS.build({"type": global_name})
    path = planner.plan(grid, s, g)
    assert isinstance(path, np.ndarray)
    assert path.ndim == 2 and path.shape[1] == 2 and path.shape[0] >= 2
    assert np.all(np.isfinite(path))
    np.testing.assert_allclose(path[0], s.xy, atol=1e-9)
    np.testing.assert_allclose(path[-1], g.xy, atol=1e-9)
    assert _free_cells_along(grid, path)
    # Deterministic: same inputs, fresh or reused planner → same output.
    np.testing.assert_array_equal(planner.plan(grid, s, g), path)
    fresh = GLOBAL_PLANNERS.build({"type": global_name})
    np.testing.assert_array_equal(fresh.plan(grid, s, g), path)
    # Inputs untouched.
    np.testing.assert_array_equal(grid.data, data)
    assert (s, g) == (s_copy, g_copy)


def test_global_planner_typed_failures(global_name: str) -> None:
    grid = _maze()
    planner = GLOBAL_PLANNERS.build({"type": global_name})
    free = Pose2D(-0.5, 1.0)
    wall = Pose2D(-1.0 + 40.5 * RES, 0.5 + 10.5 * RES)  # a cell of the first wall
    with pytest.raises(StartOccupied):
        planner.plan(grid, wall, free)
    with pytest.raises(GoalOccupied):
        planner.plan(grid, free, wall)
    with pytest.raises(GoalOccupied):
        planner.plan(grid, free, Pose2D(100.0, 100.0))
    boxed = np.array(grid.occupied)
    boxed[10:20, 100:110] = True
    boxed[12:18, 102:108] = False  # a free pocket sealed off from the rest
    sealed = OccupancyGrid.from_occupied(boxed, RES, origin=grid.origin)
    pocket = Pose2D(*sealed.cell_to_world(np.array([15, 105])))
    with pytest.raises(NoPathFound):
        planner.plan(sealed, free, pocket)


# -- local planners --------------------------------------------------------------------------------

RANDOM_POLICY = "<random_policy>"
PLANNER_PARAMS: dict[str, dict[str, Any]] = {
    # no packaged weights needed: an untrained policy in the export layout (made without torch)
    "rosnav_rl": {"weights": RANDOM_POLICY},
}
"""Parameters (besides ``type``) each local planner is built with."""


def _free_road_obs(kin: str) -> LocalObservation:
    return LocalObservation(
        pose=np.zeros(3),
        twist=np.zeros(3),
        goal=Pose2D(3.0, 0.0),
        path=np.array([[0, 0], [3, 0]]),
        limits=LIMITS[kin],
        robot_radius=0.3,
        dt=DT,
        kinematics=kin,
    )


@pytest.fixture(scope="session")
def random_policy_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A random rosnav_rl policy (jackal, lidar + goal + last_action) that drives forward.

    The first seed whose untrained policy moves toward a free-road goal ahead is kept, so that
    :func:`test_local_planner_without_scan` checks the plumbing, not luck.
    """
    from arena.learn.config import EnvConfig
    from arena.learn.policy import write_random_policy
    from arena.nav.local_planners.learned import LearnedPlanner
    from arena.robots.presets import load_robot

    env = EnvConfig.model_validate({"observation": {"pedestrians": {"enabled": False}}})
    robot = load_robot("jackal")
    folder = tmp_path_factory.mktemp("policies")
    for seed in range(100):
        path = write_random_policy(folder / f"random_{seed}.npz", env, robot, rng=seed)
        planner = LearnedPlanner(LearnedPlanner.Params(weights=str(path)))
        if all(planner.compute(_free_road_obs(k))[0] > 0 for k in sorted(planner.supports)):
            return path
    raise AssertionError("no random policy drives forward")


@pytest.fixture
def local_spec(request: pytest.FixtureRequest) -> Any:
    """``name -> {"type": name, **PLANNER_PARAMS[name]}`` (random weights resolved)."""

    def spec(name: str) -> dict[str, Any]:
        params = dict(PLANNER_PARAMS.get(name, {}))
        for k, v in params.items():
            if v == RANDOM_POLICY:
                params[k] = str(request.getfixturevalue("random_policy_file"))
        return {"type": name, **params}

    return spec


def _cases() -> list[tuple[str, str]]:
    return [
        (name, kin)
        for name in LOCAL_PLANNERS.names()
        for kin in sorted(LOCAL_PLANNERS.get(name).supports)
    ]


def _random_obs(rng: np.random.Generator, kin: str) -> LocalObservation:
    lim = LIMITS[kin]
    twist = rng.uniform(lim.lower, lim.upper)
    if not lim.holonomic:
        twist[1] = 0.0
    if kin == "ackermann":
        twist[0] = abs(twist[0])
        twist[2] = twist[0] / lim.min_turning_radius * rng.uniform(-1, 1)
    pose = rng.uniform([-2, -2, -math.pi], [2, 2, math.pi])
    steps = rng.normal(0, 1.0, (rng.integers(1, 6), 2))
    path = np.vstack([pose[:2], pose[:2] + np.cumsum(steps, axis=0)])
    beams = int(rng.integers(0, 60))
    return LocalObservation(
        pose=pose,
        twist=twist,
        goal=Pose2D(*path[-1], rng.uniform(-3, 3)),
        path=path,
        limits=lim,
        robot_radius=float(rng.uniform(0.1, 0.5)),
        dt=DT,
        scan_ranges=rng.uniform(0.05, 6.0, beams),
        scan_angles=rng.uniform(-math.pi, math.pi, beams),
        scan_origin=rng.uniform(-0.1, 0.1, 2),
        time=float(rng.uniform(0, 100)),
        kinematics=kin,
    )


def _snapshot(obs: LocalObservation) -> dict[str, np.ndarray]:
    return {
        k: np.array(getattr(obs, k), copy=True)
        for k in ("pose", "twist", "path", "scan_ranges", "scan_angles", "scan_origin")
    }


@pytest.mark.parametrize(("name", "kin"), _cases())
def test_local_planner_conformance(name: str, kin: str, local_spec: Any) -> None:
    assert kin in KINEMATICS
    planner = LOCAL_PLANNERS.build(local_spec(name))
    assert isinstance(planner, LocalPlanner)
    assert planner.supports <= KINEMATICS
    rng = np.random.default_rng(12345)
    observations = []
    for _ in range(20):  # one episode: a sequence of related observations
        observations.append(_random_obs(rng, kin))
    planner.reset()
    first = []
    for obs in observations:
        before = _snapshot(obs)
        cmd = np.asarray(planner.compute(obs))
        first.append(cmd.copy())
        assert cmd.shape == (3,)
        assert np.all(np.isfinite(cmd))
        lim = obs.limits
        assert np.all(cmd >= lim.lower - 1e-9) and np.all(cmd <= lim.upper + 1e-9)
        room = lim.acceleration * obs.dt + 1e-9
        assert abs(cmd[0] - obs.twist[0]) <= room[0]
        assert abs(cmd[1] - obs.twist[1]) <= room[1]
        if kin == "ackermann":
            assert abs(cmd[2]) <= abs(cmd[0]) / lim.min_turning_radius + 1e-9
        else:
            assert abs(cmd[2] - obs.twist[2]) <= room[2]
        if not lim.holonomic:
            assert cmd[1] == 0.0
        for key, value in before.items():
            np.testing.assert_array_equal(getattr(obs, key), value, err_msg=f"{key} mutated")
    # Deterministic: after reset the same sequence gives the same commands.
    planner.reset()
    for obs, cmd in zip(observations, first, strict=True):
        np.testing.assert_array_equal(planner.compute(obs), cmd)
    other = LOCAL_PLANNERS.build(local_spec(name))
    for obs, cmd in zip(observations, first, strict=True):
        np.testing.assert_array_equal(other.compute(obs), cmd)


@pytest.mark.parametrize(("name", "kin"), _cases())
def test_local_planner_without_scan(name: str, kin: str, local_spec: Any) -> None:
    planner = LOCAL_PLANNERS.build(local_spec(name))
    obs = _free_road_obs(kin)
    cmd = planner.compute(obs)
    assert cmd.shape == (3,) and np.all(np.isfinite(cmd))
    assert cmd[0] > 0  # free road ahead: it moves toward the goal
