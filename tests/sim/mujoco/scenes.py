"""Small hand-made episodes for the MuJoCo backend tests (walls, cuboids, robots, people)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import make_obstacle
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import AgentSpawn, Episode, RobotSpawn
from arena.scene.state import Obstacle

RES = 0.05


def room() -> OccupancyGrid:
    """8 x 6 m at 0.05 m: a border wall two cells thick and an interior wall stub.

    Interior wall: x 4.0..4.1 m, y 0..2.5 m.
    """
    occ = np.zeros((120, 160), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    occ[:50, 80:82] = True
    return OccupancyGrid.from_occupied(occ, RES)


def cuboids() -> tuple[Obstacle, ...]:
    """Two 1 x 1 x 1 m boxes: one axis-aligned at (6, 4.5), one turned 0.3 rad at (2, 4.5)."""
    return (make_obstacle("box_a", "cuboid", [6.0, 4.5, 0.0]),
            make_obstacle("box_b", "cuboid", [2.0, 4.5, 0.3]))


def people(xy: Sequence[tuple[float, float]], vmax: float = 0.0,
           goal: tuple[float, float] | None = None) -> AgentSpawn:
    """Adults at ``xy``; with ``vmax > 0`` each walks to ``goal`` and back (a loop)."""
    n = len(xy)
    pos = np.array(xy, dtype=np.float64).reshape(n, 2)
    wp = np.array([goal if goal is not None else p for p in pos.tolist()], dtype=np.float64)
    zi = np.zeros(n, dtype=np.int64)
    return AgentSpawn(pos, np.full(n, 0.3), np.full(n, vmax), wp.reshape(n, 1, 2),
                      np.ones(n, dtype=np.int64), zi, zi.copy())


def episode(
    robots: Sequence[tuple[str, RobotModel | str, tuple[float, float, float]]] = (
        ("robot", "jackal", (1.0, 1.0, 0.0)),
    ),
    *,
    obstacles: tuple[Obstacle, ...] | None = None,
    agents: AgentSpawn | None = None,
    goal: tuple[float, float] = (7.0, 1.0),
    time_limit: float = 60.0,
) -> Episode:
    """An episode in :func:`room` (goal of every robot: ``goal``)."""
    spawns = tuple(
        RobotSpawn(name, load_robot(m) if isinstance(m, str) else m, Pose2D(*start),
                   Pose2D(goal[0], goal[1], 0.0))
        for name, m, start in robots
    )
    return Episode(0, 0, "room", room(), cuboids() if obstacles is None else obstacles, spawns,
                   agents if agents is not None else AgentSpawn.empty(), time_limit)
