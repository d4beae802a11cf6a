"""The episode description: everything a backend needs to reset one episode.

Task generators produce :class:`Episode` objects; backends consume them. Nothing here is random:
all draws happened in the generator, so an episode is a plain, reproducible value.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.core.types import Pose2D
from arena.scene.state import Obstacle

if TYPE_CHECKING:  # held, never called: the scene layer sits below maps and robots
    from arena.maps.grid import OccupancyGrid
    from arena.robots.model import RobotModel

WAYPOINT_LOOP = 0
"""Arena's ``waypoint_mode`` 0: visit the waypoints in order, then start again."""
WAYPOINT_RANDOM = 1
"""Arena's ``waypoint_mode`` 1: after each waypoint pick another one at random."""

MAX_COUNT = 10_000
"""Most obstacles (or people) of one class in an episode: far beyond the dense crowds the 2-D
simulation is used for (1,000 people), while ``dynamic=1e9`` is refused at once instead of
allocating gigabytes."""

MAX_PERSON_SPEED = 3.0
"""m/s, the highest walking speed (``vmax``) a task may give a person: a fast run for an adult.
The crowd models may still scale it (pedsim's running state doubles it); a larger value is a
typo (``agent_speed=[1000, 2000]``), not a person."""


def speed_range_problem(lo: float, hi: float) -> str | None:
    """Why ``[lo, hi]`` (m/s) is not a range of person speeds, or ``None`` if it is one."""
    if not 0 <= lo <= hi <= MAX_PERSON_SPEED:
        return (f"must be [min, max] m/s with 0 <= min <= max <= {MAX_PERSON_SPEED:g} "
                f"(a person's walking speed), got {[lo, hi]}")
    return None


@dataclass(frozen=True, eq=False)
class RobotSpawn:
    """One robot of the episode: its model, start pose and goal pose."""

    name: str
    model: RobotModel
    start: Pose2D
    goal: Pose2D


@dataclass(frozen=True, eq=False)
class AgentSpawn:
    """Pedestrians of the episode as a struct of arrays (``n`` agents, up to ``K`` waypoints).

    Attributes:
        positions: ``(n, 2)`` start positions (m).
        radii: ``(n,)`` body radii (m).
        vmax: ``(n,)`` preferred walking speeds (m/s).
        waypoints: ``(n, K, 2)`` waypoints (m), rows past ``num_waypoints`` are NaN.
        num_waypoints: ``(n,)`` number of valid waypoints per agent (≥ 1).
        waypoint_mode: ``(n,)`` :data:`WAYPOINT_LOOP` or :data:`WAYPOINT_RANDOM`.
        kinds: ``(n,)`` type codes (0 adult, 1 elder, 2 child).
        groups: ``(n,)`` group ids (-1 alone), or ``None`` to let the crowd form groups.
        startup_mode: ``(n,)`` 0 at once, 1 after ``wait_time``, 2 when a robot is within
            ``trigger_radius``; ``None`` means all start at once.
        wait_time: ``(n,)`` s, or ``None``.
        trigger_radius: ``(n,)`` m, or ``None``.
    """

    positions: NDArray[np.float64]
    radii: NDArray[np.float64]
    vmax: NDArray[np.float64]
    waypoints: NDArray[np.float64]
    num_waypoints: NDArray[np.int64]
    waypoint_mode: NDArray[np.int64]
    kinds: NDArray[np.int64]
    groups: NDArray[np.int64] | None = None
    startup_mode: NDArray[np.int64] | None = None
    wait_time: NDArray[np.float64] | None = None
    trigger_radius: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        n = self.positions.shape[0]
        for name in ("radii", "vmax", "num_waypoints", "waypoint_mode", "kinds", "groups",
                     "startup_mode", "wait_time", "trigger_radius"):
            value = getattr(self, name)
            if value is not None and value.shape != (n,):
                raise ValueError(f"AgentSpawn.{name} must have shape ({n},)")
        if self.waypoints.ndim != 3 or self.waypoints.shape[0] != n or self.waypoints.shape[2] != 2:
            raise ValueError(f"AgentSpawn.waypoints must have shape ({n}, K, 2)")
        if n and (
            self.num_waypoints.min() < 1 or self.num_waypoints.max() > self.waypoints.shape[1]
        ):
            raise ValueError("AgentSpawn.num_waypoints must lie in [1, K]")

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    @classmethod
    def empty(cls) -> AgentSpawn:
        """No pedestrians."""
        zi = np.zeros(0, dtype=np.int64)
        return cls(np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros((0, 1, 2)), zi, zi, zi)


@dataclass(frozen=True, eq=False)
class Episode:
    """One episode, fully determined.

    Attributes:
        index: episode number within its run.
        seed: the seed the episode was drawn with (backends derive their noise streams from it).
        map_name: a label for reports.
        grid: the static map.
        obstacles: placed static obstacles with real footprints.
        robots: the robots with start and goal.
        agents: the pedestrians.
        time_limit: seconds of simulated time before the episode ends as a timeout.
        goal_radius: the goal counts as reached within this distance (m).
        goal_tolerance_angle: and with the heading within this (rad); ``None`` ignores heading.
        label: where the episode comes from (a benchmark stage, a curriculum stage), for reports.
    """

    index: int
    seed: int
    map_name: str
    grid: OccupancyGrid
    obstacles: tuple[Obstacle, ...]
    robots: tuple[RobotSpawn, ...]
    agents: AgentSpawn
    time_limit: float
    goal_radius: float = 0.3
    goal_tolerance_angle: float | None = None
    label: str = ""


def episode_digest(episode: Episode) -> str:
    """A short SHA-1 over everything that defines an episode (map, robots, obstacles, people).

    Two episodes with the same digest are the same episode; ``arena tasks preview`` prints it
    so two machines can compare what a suite will run.
    """
    h = hashlib.sha1()
    g = episode.grid
    h.update(np.ascontiguousarray(g.data).tobytes())
    h.update(np.array([g.resolution, *g.origin], dtype=np.float64).tobytes())
    for r in episode.robots:
        h.update(r.name.encode())
        h.update(r.model.name.encode())
        h.update(np.concatenate([r.start.as_array(), r.goal.as_array()]).tobytes())
    for o in episode.obstacles:
        h.update(o.name.encode())
        h.update(np.asarray(o.pose, dtype=np.float64).tobytes())
        h.update(np.asarray(o.footprint, dtype=np.float64).tobytes())
    a = episode.agents
    for arr in (a.positions, a.radii, a.vmax, a.waypoints, a.num_waypoints, a.waypoint_mode,
                a.kinds, a.groups, a.startup_mode, a.wait_time, a.trigger_radius):
        h.update(b"-" if arr is None else np.ascontiguousarray(arr).tobytes())
    h.update(repr((episode.time_limit, episode.goal_radius, episode.goal_tolerance_angle)).encode())
    return h.hexdigest()[:12]
