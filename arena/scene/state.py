"""Placed obstacles, the static world and snapshots of the simulated world (structs of arrays).

A :class:`SimState` is returned by every ``reset``/``step`` of a backend. Its arrays are copies
that the backend never mutates afterwards, so a recorder may keep them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.core.geometry import transform_points

if TYPE_CHECKING:  # the scene only holds a grid; maps sits above it (maps makes Obstacles)
    from arena.maps.grid import OccupancyGrid

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A placed static obstacle with a real footprint.

    Attributes:
        name: unique name in the episode.
        model: obstacle model name (``table``, ``shelf``, ``cuboid`` ...).
        pose: ``(3,)`` world pose ``[x, y, theta]``.
        footprint: ``(k, 2)`` polygon in the obstacle's own frame (m).
        height: m (for later 3-D backends and renderers).
    """

    name: str
    model: str
    pose: FloatArray
    footprint: FloatArray
    height: float = 1.0

    @property
    def polygon(self) -> FloatArray:
        """``(k, 2)`` footprint in world coordinates."""
        return transform_points(self.footprint, self.pose)


@dataclass(frozen=True, eq=False)
class StaticWorld:
    """What does not move during an episode: the map and the placed obstacles.

    ``segments_a``/``segments_b`` hold every obstacle edge, ``(s, 2)`` each, and
    ``segment_owner`` ``(s,)`` the index of the obstacle each edge belongs to.
    """

    grid: OccupancyGrid
    obstacles: tuple[Obstacle, ...]
    segments_a: FloatArray
    segments_b: FloatArray
    segment_owner: IntArray

    @classmethod
    def build(cls, grid: OccupancyGrid, obstacles: tuple[Obstacle, ...] = ()) -> StaticWorld:
        """Collect the obstacle edges once per episode."""
        a_list, b_list, owners = [], [], []
        for i, ob in enumerate(obstacles):
            poly = ob.polygon
            a_list.append(poly)
            b_list.append(np.roll(poly, -1, axis=0))
            owners.append(np.full(len(poly), i, dtype=np.int64))
        if a_list:
            a, b, o = np.concatenate(a_list), np.concatenate(b_list), np.concatenate(owners)
        else:
            a, b, o = np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, dtype=np.int64)
        return cls(grid, tuple(obstacles), a, b, o)


@dataclass(frozen=True, eq=False)
class RobotStates:
    """All robots, index ``i`` everywhere.

    Attributes:
        names: robot names (unique in the episode).
        models: preset names (``jackal`` ...).
        poses: ``(r, 3)`` world poses ``[x, y, theta]`` (m, rad).
        twists: ``(r, 3)`` body-frame velocities ``[vx, vy, omega]`` (m/s, rad/s) actually executed.
        commands: ``(r, 3)`` commands received on the last step (before limits).
        radii: ``(r,)`` circumscribed radius of each footprint (m).
        footprints: per robot ``(k, 2)`` body-frame polygon, or ``None`` for a circular robot.
        scans: per robot ``(beams,)`` ranges (m) of its primary lidar
            (:attr:`arena.robots.model.RobotModel.primary_lidar`, the sensor ``laser`` of every
            preset) taken at the end of the step; ``(0,)`` for a robot without a lidar.
        sensors: per robot its sensors' latest readings by name (read-only mapping; the engine
            gives read-only arrays), e.g. ``sensors[0]["rear"]`` ``(beams,)`` m for a lidar.
            Left empty by a caller, it becomes ``{"laser": scans[i]}`` per robot.
    """

    names: tuple[str, ...]
    models: tuple[str, ...]
    poses: FloatArray
    twists: FloatArray
    commands: FloatArray
    radii: FloatArray
    footprints: tuple[FloatArray | None, ...]
    scans: tuple[FloatArray, ...]
    sensors: tuple[Mapping[str, FloatArray], ...] = ()

    def __post_init__(self) -> None:
        if not self.sensors and self.scans:  # built by hand with scans only: Arena's laser
            by_name = tuple(MappingProxyType({"laser": s}) for s in self.scans)
            object.__setattr__(self, "sensors", by_name)

    def __len__(self) -> int:
        return len(self.names)


@dataclass(frozen=True, eq=False)
class AgentStates:
    """All pedestrians (moving circles), as a struct of arrays.

    Attributes:
        ids: ``(n,)`` stable integer ids.
        positions: ``(n, 2)`` (m).
        velocities: ``(n, 2)`` world-frame (m/s).
        headings: ``(n,)`` (rad).
        radii: ``(n,)`` (m).
        kinds: ``(n,)`` integer type codes (0 adult, 1 elder, 2 child; the crowd module owns them).
        states: ``(n,)`` integer social-state codes (0 walking unless a crowd model sets others).
    """

    ids: IntArray
    positions: FloatArray
    velocities: FloatArray
    headings: FloatArray
    radii: FloatArray
    kinds: IntArray
    states: IntArray

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    @classmethod
    def empty(cls) -> AgentStates:
        """No pedestrians."""
        z = np.zeros(0)
        zi = np.zeros(0, dtype=np.int64)
        return cls(zi, np.zeros((0, 2)), np.zeros((0, 2)), z, z, zi, zi)


@dataclass(frozen=True, eq=False)
class Collisions:
    """Contacts of each robot at the end of a step; index arrays hold ``-1`` for "none".

    Attributes:
        wall: ``(r,)`` bool, footprint overlaps a blocking map cell or leaves the map.
        obstacle: ``(r,)`` index into ``StaticWorld.obstacles`` of one touched obstacle.
        agent: ``(r,)`` index into the agents of one touched pedestrian.
        robot: ``(r,)`` index of one touched other robot.
    """

    wall: NDArray[np.bool_]
    obstacle: IntArray
    agent: IntArray
    robot: IntArray

    @property
    def any(self) -> NDArray[np.bool_]:
        """``(r,)`` bool: the robot touches anything."""
        # the indices are >= -1, so one comparison of their maximum tells whether any is set
        touched = np.maximum(np.maximum(self.obstacle, self.agent), self.robot) >= 0
        return self.wall | touched

    @classmethod
    def none(cls, n_robots: int) -> Collisions:
        """No contacts for ``n_robots`` robots."""
        neg = np.full(n_robots, -1, dtype=np.int64)
        return cls(np.zeros(n_robots, dtype=bool), neg, neg.copy(), neg.copy())


@dataclass(frozen=True, eq=False)
class SimState:
    """One snapshot: simulation time (s), step count, robots, pedestrians and contacts."""

    time: float
    step: int
    robots: RobotStates
    agents: AgentStates
    collisions: Collisions
