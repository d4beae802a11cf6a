"""TEMPORARY reference version (lead replaces at merge): contacts of every robot of every world.

:class:`ContactBank` keeps the interface of the engine design (bind_world / set_robots / test)
and loops in Python over today's single-robot functions of
:mod:`arena.sim.native2d.collisions` (``hits_grid`` with the tunnelling sweep,
``first_obstacle_hit``, ``first_agent_hit``, ``footprints_overlap``), so its flags are exactly
those ``native2d`` reported before the engine.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from arena.scene.state import StaticWorld
from arena.sim.native2d.collisions import (
    Footprint,
    ObstacleIndex,
    first_agent_hit,
    first_obstacle_hit,
    footprints_overlap,
    hits_grid,
)

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


class ContactBank:
    """Exact-footprint contacts of every robot of every world, one call."""

    def __init__(self) -> None:
        self._worlds: dict[int, tuple[StaticWorld, ObstacleIndex, tuple[float, ...]]] = {}
        self._row_world: list[int] = []
        self._footprints: list[Footprint] = []
        self._rows_of: dict[int, list[int]] = {}

    def bind_world(self, w: int, world: StaticWorld) -> None:
        """Static geometry of world ``w`` (grid walls and obstacles)."""
        self._worlds[w] = (world, ObstacleIndex.build(world), world.grid.bounds)

    def set_robots(self, row_world: I64, footprints: Sequence[Footprint]) -> None:
        """The robots (global rows, world of each ``(R,)``) and their footprints."""
        self._row_world = [int(w) for w in row_world]
        self._footprints = list(footprints)
        rows: dict[int, list[int]] = {}
        for r, w in enumerate(self._row_world):
            rows.setdefault(w, []).append(r)
        self._rows_of = rows

    def test(
        self,
        poses: F64,
        previous: F64 | None,
        ag_off: I64,
        ag_pos: F64,
        ag_r: F64,
        *,
        rows: NDArray[np.bool_] | None = None,
        parallel: bool = False,
    ) -> tuple[NDArray[np.bool_], I64, I64, I64]:
        """Contacts at ``poses`` ``(R, 3)``; walls swept from ``previous`` ``(R, 3)`` if given.

        Returns ``(wall (R,) bool, obstacle (R,), agent (R,), robot (R,))``; indices are local
        to the robot's world, ``-1`` none. ``rows``: ``(R,)`` bool, the rows to evaluate.
        """
        n = poses.shape[0]
        wall = [False] * n
        obstacle = [-1] * n
        agent = [-1] * n
        robot = [-1] * n
        for i in range(n):
            if rows is not None and not rows[i]:
                continue
            w = self._row_world[i]
            world, index, bounds = self._worlds[w]
            fp = self._footprints[i]
            pose = poses[i]
            for p in _sweep(pose, None if previous is None else previous[i], fp, world):
                if hits_grid(world.grid, fp, p, bounds=bounds):  # type: ignore[arg-type]
                    wall[i] = True
                    break
            obstacle[i] = first_obstacle_hit(index, fp, pose)
            a0, a1 = int(ag_off[w]), int(ag_off[w + 1])
            agent[i] = first_agent_hit(fp, pose, ag_pos[a0:a1], ag_r[a0:a1])
            mates = self._rows_of[w]
            for k, j in enumerate(mates):
                if j != i and footprints_overlap(fp, pose, self._footprints[j], poses[j]):
                    robot[i] = k
                    break
        return (
            np.array(wall, dtype=bool),
            np.array(obstacle, dtype=np.int64),
            np.array(agent, dtype=np.int64),
            np.array(robot, dtype=np.int64),
        )


def _sweep(pose: F64, previous: F64 | None, fp: Footprint, world: StaticWorld) -> list[F64]:
    """Poses to test between ``previous`` and ``pose``.

    They are spaced so that consecutive footprints overlap by at least half a cell (no
    tunnelling through a one-cell wall).
    """
    if previous is None:
        return [pose]
    dist = math.hypot(pose[0] - previous[0], pose[1] - previous[1])
    spacing = max(world.grid.resolution * 0.5, fp.radius * 0.5)
    k = math.ceil(dist / spacing)
    if k <= 1:
        return [pose]
    t = np.linspace(0.0, 1.0, k + 1)[1:]
    dtheta = (pose[2] - previous[2] + math.pi) % (2 * math.pi) - math.pi
    return [
        np.array(
            [
                previous[0] + s * (pose[0] - previous[0]),
                previous[1] + s * (pose[1] - previous[1]),
                previous[2] + s * dtheta,
            ]
        )
        for s in t
    ]
