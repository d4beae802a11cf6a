"""Shared fixtures: small hand-built worlds and episodes (tests never read ../shared)."""

from __future__ import annotations

import os
from collections.abc import Iterator

import numpy as np
import pytest

from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import AgentSpawn, Episode, RobotSpawn


@pytest.fixture
def room() -> OccupancyGrid:
    """A 10 × 10 m room at 0.05 m/cell with one-cell walls."""
    return OccupancyGrid.empty(10.0, 10.0, 0.05)


def make_episode(grid, robots, *, obstacles=(), agents=None, time_limit=30.0) -> Episode:
    """An episode from ``(model, start, goal)`` triples."""
    spawns = tuple(
        RobotSpawn(f"r{i}", m, Pose2D(*s), Pose2D(*g)) for i, (m, s, g) in enumerate(robots)
    )
    return Episode(
        0, 0, "test", grid, tuple(obstacles), spawns, agents or AgentSpawn.empty(), time_limit
    )


def standing_agents(positions, radius=0.3) -> AgentSpawn:
    """Agents that stand at ``positions`` (their only waypoint is where they are)."""
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    n = len(p)
    return AgentSpawn(
        positions=p,
        radii=np.full(n, radius),
        vmax=np.full(n, 1.0),
        waypoints=p[:, None, :].copy(),
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        kinds=np.zeros(n, dtype=np.int64),
    )


@pytest.fixture(autouse=True)
def _plugins_env_restored() -> Iterator[None]:
    """Each test leaves ``ARENA_PLUGINS`` as it found it.

    ``--plugin`` exports the plugins to the environment for worker processes; a test whose
    ``monkeypatch.delenv`` found the variable unset records nothing to restore, so without this
    the plugin names leak into every later test of that pytest worker (and into the ``arena``
    subprocesses those start, which then fail to import them).
    """
    before = os.environ.get("ARENA_PLUGINS")
    yield
    if before is None:
        os.environ.pop("ARENA_PLUGINS", None)
    else:
        os.environ["ARENA_PLUGINS"] = before
