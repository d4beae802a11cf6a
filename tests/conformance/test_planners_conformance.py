"""Conformance of every registered global and local planner with its protocol.

Global planners: ``(k, 2)`` finite waypoints from the start to the goal over free cells,
deterministic, inputs untouched, typed failures. Local planners: ``(3,)`` finite commands inside
the velocity box and one tick of acceleration, deterministic after ``reset``, observation
untouched, for every kinematics they declare.
"""

from __future__ import annotations

import copy
import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from arena.core.errors import GoalOccupied, NoPathFound, StartOccupied
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav import (
    GLOBAL_PLANNERS,
    LOCAL_PLANNERS,
    GlobalPlanner,
    LocalObservation,
)
from arena.nav.local_planners.base import limit_command
from arena.testing import check_local_planner
from arena.testing.local_planner import free_road_observation

RES = 0.05


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
    # the checker's observations carry no camera: iplanner plans on an empty floor's depth image
    # (its network, spline and pure-pursuit tracking all run; rendered frames: tests/learn)
    "iplanner": {"missing_frame": "floor"},
}
"""Parameters (besides ``type``) each local planner is built with."""


@pytest.fixture(scope="session")
def random_policy_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A random rosnav_rl policy (jackal, lidar + goal + last_action) that drives forward.

    The first seed whose untrained policy moves toward a free-road goal ahead is kept, so that
    the free-road part of :func:`check_local_planner` checks the plumbing, not luck.
    """
    from arena.learn.config import EnvConfig
    from arena.learn.planners.learned import LearnedPlanner
    from arena.learn.policy import write_random_policy
    from arena.robots.presets import load_robot

    env = EnvConfig.model_validate({"observation": {"pedestrians": {"enabled": False}}})
    robot = load_robot("jackal")
    folder = tmp_path_factory.mktemp("policies")
    for seed in range(100):
        path = write_random_policy(folder / f"random_{seed}.npz", env, robot, rng=seed)
        planner = LearnedPlanner(LearnedPlanner.Params(weights=str(path)))
        if all(planner.compute(free_road_observation(k))[0] > 0 for k in sorted(planner.supports)):
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


def _external(name: str) -> bool:
    """A planner whose commands come from another process (the ROS planners)."""
    return "external" in LOCAL_PLANNERS.entry(name).tags


@pytest.mark.parametrize(("name", "kin"), _cases())
def test_local_planner_conformance(name: str, kin: str, local_spec: Any) -> None:
    assert LOCAL_PLANNERS.entry(name).summary, "a local planner needs a docstring"
    if _external(name):
        # Its partner is another process (a ROS node): an in-memory node answers every tick
        # with a command far outside the limits, so the check covers the planner's clipping.
        # Their episodes over real ROS are tested in tests/ros.
        from arena.testing.ros import attach_loopback

        check_local_planner(
            lambda: attach_loopback(LOCAL_PLANNERS.build(local_spec(name))), kinematics=[kin])
        return
    check_local_planner(lambda: LOCAL_PLANNERS.build(local_spec(name)), kinematics=[kin])


def test_check_local_planner_names_the_broken_rule() -> None:
    """The checker fails with the planner, the kinematics and the rule in its message."""

    class TooFast:
        supports = frozenset({"diff_drive"})

        def reset(self) -> None:
            pass

        def compute(self, obs: LocalObservation) -> np.ndarray:
            return np.array([obs.limits.vx_max + 1.0, 0.0, 0.0])

    class Mutating(TooFast):
        def compute(self, obs: LocalObservation) -> np.ndarray:
            obs.pose[0] += 1.0
            return np.array(obs.twist, copy=True)

    class Standing(TooFast):  # brakes as hard as allowed, never drives
        def compute(self, obs: LocalObservation) -> np.ndarray:
            return limit_command(np.zeros(3), obs.twist, obs.limits, obs.dt)

    with pytest.raises(AssertionError, match=r"TooFast \(diff_drive\), observation 0: command "
                       r"\[2\., 0\., 0\.\] outside the velocity box"):
        check_local_planner(TooFast)
    with pytest.raises(AssertionError, match=r"compute\(\) modified obs\.pose"):
        check_local_planner(Mutating)
    with pytest.raises(AssertionError, match="must drive forward"):
        check_local_planner(Standing)
    check_local_planner(Standing, moves_on_free_road=False)
    with pytest.raises(AssertionError, match="does not implement LocalPlanner"):
        check_local_planner(object)
