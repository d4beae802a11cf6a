"""``mujoco``: the simulation engine with MuJoCo as the 3-D world, its contacts and its sensors.

The same :class:`~arena.sim.engine.Engine` as ``native2d`` (one world), with two stages
swapped: contacts come from MuJoCo (:class:`~arena.sim.mujoco.contacts.MujocoContactStage`)
and the sensors are measured in the compiled world (:data:`~arena.sim.mujoco.sensors.MUJOCO_BANKS`).
The crowd stage (the pedestrian driver) and the kinematics stage (commands -> next poses) are
the engine's own, so a run differs from ``native2d`` only by what the 3-D world makes different:
the shapes contacts and beams meet (figures instead of circles, obstacle models instead of
footprints). Per episode the 3-D world is built and compiled once
(:class:`~arena.sim.mujoco.sim.MjWorld`); only kinematics and collision detection run in MuJoCo
(no rigid-body dynamics). See ``docs/worlds3d.md``.

Importing this module imports no MuJoCo; building the backend does (one-line error with the
install command when it is missing).
"""

from __future__ import annotations

import numpy as np

from arena.scene.episode import Episode
from arena.scene.state import SimState
from arena.sim.backend import BACKENDS, PedestrianDriver
from arena.sim.engine import Engine
from arena.sim.engine.stages import SensorStage
from arena.sim.mujoco.contacts import MjHandle, MujocoContactStage
from arena.sim.mujoco.mjcf import import_mujoco
from arena.sim.mujoco.params import MujocoParams
from arena.sim.mujoco.sensors import bank_factory, check_served
from arena.sim.mujoco.sim import MjWorld
from arena.sim.mujoco.world import robot_height
from arena.sim.native2d.backend import Native2DBackend


@BACKENDS.register("mujoco")
class MujocoBackend(Native2DBackend):
    """3-D kinematic simulator on MuJoCo: contacts and lidar in the 3-D world (``arena[3d]``)."""

    Params = MujocoParams

    def __init__(self, params: MujocoParams | None = None) -> None:
        import_mujoco()  # the one-line install hint before anything else
        self.params = params or MujocoParams()
        self.handle = MjHandle(self.params)
        self.contact_stage = MujocoContactStage(self.handle)
        self.engine = Engine(
            1, self.params, contact_stage=self.contact_stage,
            sensor_stage=SensorStage(bank_factory(self.handle)),
        )
        self._state: SimState | None = None

    @property
    def world3d(self) -> MjWorld:
        """The current episode's compiled world (:class:`~arena.sim.mujoco.sim.MjWorld`)."""
        return self.handle.get()

    def reset(
        self, episode: Episode, pedestrians: PedestrianDriver | None, rng: np.random.Generator
    ) -> SimState:
        """Start ``episode`` (see :meth:`Native2DBackend.reset`); builds its 3-D world.

        Raises:
            ConfigError: a robot without ``height``, or carrying a sensor type the backend
                cannot simulate (one line each, before anything changes).
        """
        for r in episode.robots:
            robot_height(r.model)
        check_served(episode)
        self.contact_stage.episode = episode
        return super().reset(episode, pedestrians, rng)
