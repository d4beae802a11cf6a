"""The simulator interface every backend implements, and the pedestrian-driver interface.

Data flow per step: the backend asks its :class:`PedestrianDriver` to advance the pedestrians
(given the robots as they are), applies each robot's kinematics to its command, resolves
collisions, then takes the sensor readings, and returns one :class:`SimState` snapshot.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from arena.core.registry import Registry
from arena.scene.state import AgentStates, RobotStates, SimState, StaticWorld

if TYPE_CHECKING:
    from arena.core.types import Pose2D
    from arena.scene.episode import AgentSpawn, Episode


@runtime_checkable
class PedestrianDriver(Protocol):
    """Owns the pedestrians' state and moves them.

    A driver is reset once per episode and stepped once per simulator step. It must draw random
    numbers only from the generator given to :meth:`reset`.
    """

    def reset(self, spawn: AgentSpawn, world: StaticWorld, rng: np.random.Generator) -> AgentStates:
        """Place the pedestrians of an episode; return their initial state."""
        ...

    def step(self, robots: RobotStates, dt: float) -> AgentStates:
        """Advance the pedestrians by ``dt`` seconds, seeing the robots; return the new state."""
        ...


@runtime_checkable
class SimulatorBackend(Protocol):
    """A simulator: reset from an episode, step with robot commands, return snapshots."""

    @property
    def world(self) -> StaticWorld:
        """The static part of the current episode."""
        ...

    @property
    def state(self) -> SimState:
        """The latest snapshot."""
        ...

    def reset(
        self, episode: Episode, pedestrians: PedestrianDriver | None, rng: np.random.Generator
    ) -> SimState:
        """Start ``episode``; ``pedestrians`` moves its agents (``None``: agents stand still)."""
        ...

    def step(self, commands: NDArray[np.float64], dt: float) -> SimState:
        """Apply ``(r, 3)`` body-twist commands for ``dt`` seconds and return the new snapshot."""
        ...

    def teleport(self, robot: int, pose: Pose2D) -> SimState:
        """Move robot ``robot`` to ``pose`` (m, rad) at once, at rest; return the new snapshot.

        Time and step do not advance; the robot's twist and command become zero, and its
        contacts and sensor readings are those at the new pose.
        """
        ...


def split_rng(rng: np.random.Generator) -> tuple[np.random.Generator, np.random.Generator]:
    """The two independent streams a backend makes of its ``reset`` generator.

    Returns ``(pedestrians, sensors)``: the pedestrian driver draws only from the first, sensor
    noise only from the second. Every backend splits this way, so the crowd's random draws do not
    depend on how many scans the robots took; that is what lets
    :mod:`arena.eval.counterfactual` replay an episode's crowd without the robot and get the
    same draws.
    """
    crowd, sensors = rng.spawn(2)
    return crowd, sensors


BACKENDS: Registry[SimulatorBackend] = Registry(
    "simulator backend",
    entry_points="arena.backends",
    # mujoco is an optional extra: a config naming it validates without importing it
    builtins={"mujoco": "arena.sim.mujoco.backend"},
    params={"mujoco": "arena.sim.mujoco.params:MujocoParams"},
)
