"""``native2d``: Arena's default backend, the simulation engine with one world.

Robots move by their kinematics models (exact arcs, velocity and acceleration limits), the
pedestrians by a :class:`~arena.sim.backend.PedestrianDriver`, and each robot's 2-D lidar sees
walls, placed obstacles, pedestrians and the other robots. Contacts are tested on the real
footprints. There is no rigid-body dynamics: a robot whose move would overlap something is held
at its previous pose with zero velocity (``collision_response: stop``), and the contact is
reported; with ``collision_response: record`` it passes through and the contact is only reported.

The simulation itself is :class:`~arena.sim.engine.Engine` (``W = 1``): the batched training
env steps the very same code with ``W`` worlds.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import SimulationError
from arena.core.types import Pose2D
from arena.scene.episode import Episode
from arena.scene.state import SimState, StaticWorld
from arena.sim.backend import BACKENDS, PedestrianDriver
from arena.sim.engine import Engine, EngineParams


@BACKENDS.register("native2d", tags=("default",))
class Native2DBackend:
    """Fast kinematic 2-D simulator with lidar and footprint collisions (the default backend)."""

    Params = EngineParams

    def __init__(self, params: EngineParams | None = None) -> None:
        self.params = params or EngineParams()
        self.engine = Engine(1, self.params)
        self._state: SimState | None = None

    @property
    def world(self) -> StaticWorld:
        """The static part of the current episode."""
        return self.engine.world(0)

    @property
    def state(self) -> SimState:
        """The latest snapshot."""
        if self._state is None:
            raise SimulationError("the backend has not been reset with an episode yet")
        return self._state

    def reset(
        self, episode: Episode, pedestrians: PedestrianDriver | None, rng: np.random.Generator
    ) -> SimState:
        """Start ``episode``; ``pedestrians`` moves the agents.

        ``rng`` is split by :func:`~arena.sim.backend.split_rng`: the pedestrians get the first
        stream, the sensor noise the second.
        """
        self.engine.reset_worlds([0], [episode], [pedestrians], [rng])
        self._state = self.engine.world_state(0)
        return self._state

    def step(self, commands: NDArray[np.float64], dt: float) -> SimState:
        """Advance the world by ``dt`` seconds with ``(r, 3)`` body-twist commands."""
        if self._state is None:
            raise SimulationError("step() called before reset()")
        self.engine.step(commands, dt)
        self._state = self.engine.world_state(0)
        return self._state

    def teleport(self, robot: int, pose: Pose2D) -> SimState:
        """Move robot ``robot`` to ``pose`` at rest; time does not advance.

        The twist, steering angle and last command of the robot become zero; contacts are
        evaluated at the new pose (without a sweep) and every lidar takes a fresh scan.

        Raises:
            SimulationError: before :meth:`reset`, for an unknown robot index or a non-finite
                pose.
        """
        if self._state is None:
            raise SimulationError("teleport() called before reset()")
        self.engine.teleport(0, robot, pose)
        self._state = self.engine.world_state(0)
        return self._state
