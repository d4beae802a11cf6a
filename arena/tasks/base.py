"""Task generators: turn a map, the robots and a seeded generator into an :class:`Episode`.

The worlds-and-tasks issue splits tasks into robot / obstacle / module roles; every task is
registered in :data:`TASKS` and built from the config's ``task:`` block.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from arena.core.registry import Registry
from arena.maps.sources import MapResult
from arena.robots.model import RobotModel
from arena.tasks.episode import Episode


class Task(Protocol):
    """Samples episodes on a given map."""

    def sample(
        self,
        map_result: MapResult,
        robots: Sequence[RobotModel],
        *,
        index: int,
        seed: int,
        rng: np.random.Generator,
    ) -> Episode:
        """Draw episode ``index``; every random choice comes from ``rng``."""
        ...


TASKS: Registry[Task] = Registry("task", entry_points="arena.tasks")
