"""The MuJoCo backend's contact stage: MuJoCo's contacts are the collision truth.

:class:`MujocoContactStage` replaces the engine's 2-D
:class:`~arena.sim.engine.stages.ContactStage`. It owns the episode's
:class:`~arena.sim.mujoco.sim.MjWorld` (through an :class:`MjHandle` the sensor banks share),
builds it when the engine resets, and each step places the people where the crowd stage moved
them and the robots where the kinematics stage wants them, asks MuJoCo for contacts and
applies ``collision_response`` exactly as the 2-D stage does.

Tunnelling: a step's move is tested at ``ceil(d / max_substep)`` evenly spaced poses between
the previous and the next pose (``d``: the largest distance a point of a footprint travels,
translation plus circumscribed radius × rotation), so a robot cannot pass a wall thicker than
``max_substep`` within one step. The first substep in contact gives the reported contact; with
``stop`` the robot is held at its previous pose.

Leaving the map counts as touching a wall (as in the 2-D engine): a robot whose footprint
leaves the map's extent is reported against the wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import SimulationError
from arena.sim.engine.stages import ContactStage
from arena.sim.mujoco.params import MujocoParams
from arena.sim.mujoco.sim import MjWorld

if TYPE_CHECKING:
    from arena.scene.episode import Episode
    from arena.sim.engine.engine import Engine

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
B1 = NDArray[np.bool_]
Flags = tuple[B1, I64, I64, I64]


@dataclass
class MjHandle:
    """The current episode's :class:`MjWorld` (``None`` before the first reset).

    Shared by the contact stage (which rebuilds it) and the sensor banks (which read it at each
    scan): a bank never keeps a world across episodes.
    """

    params: MujocoParams
    world: MjWorld | None = None

    def get(self) -> MjWorld:
        """The world, or :class:`SimulationError` before the first reset."""
        if self.world is None:
            raise SimulationError("the mujoco backend has not been reset with an episode yet")
        return self.world


class MujocoContactStage(ContactStage):
    """Contacts from MuJoCo for a one-world engine (see the module docstring).

    Args:
        handle: where the world is kept for the sensor banks, with the backend's parameters
            (world build, ``max_substep``).
    """

    def __init__(self, handle: MjHandle) -> None:
        self.params = handle.params
        self.handle = handle
        self.episode: Episode | None = None  # set by the backend before each reset

    def reset_worlds(self, engine: Engine, worlds: list[int]) -> None:
        """Build and compile the world of the episode just loaded (world 0)."""
        if engine.num_worlds != 1:
            raise SimulationError("the mujoco contact stage runs one world")
        ep = self.episode
        if ep is None:
            raise SimulationError("MujocoContactStage.episode must be set before a reset")
        self.handle.world = None  # a failed build leaves no stale world behind
        self.handle.world = self._build(engine, ep)

    def _build(self, engine: Engine, ep: Episode) -> MjWorld:
        robots = [(r.name, r.model, engine.poses[k]) for k, r in enumerate(ep.robots)]
        world = MjWorld(ep.grid, ep.obstacles, robots, engine.agents[0], self.params.world,
                        name=ep.map_name, source=f"map {ep.map_name!r}",
                        people_in_lidar=self.params.pedestrians_block_lidar)
        world.place_people(engine.agents[0])
        return world

    def _world(self, engine: Engine) -> MjWorld:
        """The world, rebuilt when the crowd changed size (new figures, new ids)."""
        world = self.handle.get()
        if world.num_people != len(engine.agents[0]):
            if self.episode is None:
                raise SimulationError("the crowd changed size before any reset")
            world = self.handle.world = self._build(engine, self.episode)
        return world

    def test(self, engine: Engine, rows: B1, worlds: int) -> Flags:
        """MuJoCo's contacts of the robots at their poses now (reset, teleport: no sweep)."""
        world = self._world(engine)
        world.place_people(engine.agents[0])
        world.place_robots(engine.poses)
        flags = world.collide()
        self._off_map(engine, engine.poses, flags[0])
        wall, obstacle, agent, robot = flags
        return (np.where(rows, wall, False), np.where(rows, obstacle, -1),
                np.where(rows, agent, -1), np.where(rows, robot, -1))

    def step(self, engine: Engine, commands: F64, dt: float) -> None:
        """Place, test (in substeps), respond, and commit the new robot state."""
        world = self._world(engine)
        world.place_people(engine.agents[0])
        old = engine.poses
        new_p, new_t, new_s = engine.next_poses, engine.next_twists, engine.next_steering
        n = self._substeps(engine, old, new_p)
        first: Flags | None = None
        if n == 1:
            world.place_robots(new_p)
            first = world.collide()
            self._off_map(engine, new_p, first[0])
        else:
            d_yaw = np.angle(np.exp(1j * (new_p[:, 2] - old[:, 2])))  # the short way round
            for k in range(1, n + 1):
                f = k / n
                at = old + f * np.column_stack([new_p[:, :2] - old[:, :2], d_yaw])
                world.place_robots(at)
                flags = world.collide()
                self._off_map(engine, at, flags[0])
                first = flags if first is None else _keep_first(first, flags)
        assert first is not None
        wall, obstacle, agent, robot = first
        hit = wall | (obstacle >= 0) | (agent >= 0) | (robot >= 0)
        if engine.params.collision_response == "stop" and hit.any():
            new_p, new_t, new_s = new_p.copy(), new_t.copy(), new_s.copy()
            new_p[hit] = old[hit]
            new_t[hit] = 0.0
            new_s[hit] = engine.steering[hit]
        if n > 1 or (engine.params.collision_response == "stop" and hit.any()):
            world.place_robots(new_p)  # what the sensors see: the committed poses
            world.forward()
        engine.poses, engine.twists, engine.steering = new_p, new_t, new_s
        engine.wall, engine.obstacle, engine.agent, engine.robot = wall, obstacle, agent, robot
        engine.commands = commands.copy()  # the caller may reuse its array

    def _substeps(self, engine: Engine, old: F64, new: F64) -> int:
        """Contact tests this step needs so that no footprint point moves more than a substep."""
        move = np.hypot(new[:, 0] - old[:, 0], new[:, 1] - old[:, 1])
        turn = np.abs(np.angle(np.exp(1j * (new[:, 2] - old[:, 2])))) * engine.radii
        far = float(np.max(move + turn)) if len(move) else 0.0
        return max(1, math.ceil(far / self.params.max_substep - 1e-9))

    @staticmethod
    def _off_map(engine: Engine, poses: F64, wall: B1) -> None:
        """Set ``wall`` for robots whose footprint leaves the map (in place)."""
        x0, y0, x1, y1 = _extent(engine)
        r = engine.radii
        near = ((poses[:, 0] - r < x0) | (poses[:, 0] + r > x1)
                | (poses[:, 1] - r < y0) | (poses[:, 1] + r > y1))
        for row in np.flatnonzero(near).tolist():  # the bounding circle leaves: look closer
            poly = engine.footprints[row].world_polygon(poses[row])
            if poly is None:
                wall[row] = True
                continue
            lo, hi = poly.min(axis=0), poly.max(axis=0)
            wall[row] |= bool(lo[0] < x0 or lo[1] < y0 or hi[0] > x1 or hi[1] > y1)


def _extent(engine: Engine) -> tuple[float, float, float, float]:
    """``(xmin, ymin, xmax, ymax)`` of world 0's map (m)."""
    grid = engine.world(0).grid
    ox, oy = grid.origin
    w, h = grid.size_m
    return ox, oy, ox + w, oy + h


def _keep_first(first: Flags, later: Flags) -> Flags:
    """Per robot, the flags of the earlier substep if it had any contact, else the later's."""
    w0, o0, a0, r0 = first
    had = w0 | (o0 >= 0) | (a0 >= 0) | (r0 >= 0)
    w1, o1, a1, r1 = later
    return (np.where(had, w0, w1), np.where(had, o0, o1), np.where(had, a0, a1),
            np.where(had, r0, r1))
