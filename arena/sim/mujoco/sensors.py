"""The sensor banks of the MuJoCo backend, by sensor type: :data:`MUJOCO_BANKS`.

The backend's engine keeps one bank per sensor type present, as the 2-D engine does
(:class:`~arena.sim.engine.stages.SensorStage`), but takes the bank from this mapping instead of
the :data:`~arena.sensors.base.SENSORS` registry: a MuJoCo bank measures the compiled 3-D world.
The sensor type itself (its YAML ``type:`` and ``Params``) stays registered in ``SENSORS``.

Adding a type is one adapter class and one line here. The class is built as ``cls(handle)``
(:class:`~arena.sim.mujoco.contacts.MjHandle`) and follows the
:class:`~arena.sensors.base.SensorBank` protocol. At each ``scan`` it reads the episode's
:class:`~arena.sim.mujoco.sim.MjWorld` from ``handle.get()``, whose ``data`` already holds this
step's poses (robots where the contact stage committed them, people posed):

* ``world.model`` / ``world.data``: ``MjModel`` and ``MjData``;
* ``world.robot_body[r]``: the MuJoCo body id of robot row ``r`` (exclude it from what the
  robot's own sensors see), ``world.robot_height[r]`` its height (m);
* ``world.person_of_geom``: geom id -> pedestrian index (``-1``: not a person), the per-pixel
  person ids;
* the engine's ``poses`` ``(R, 3)`` are passed to ``scan`` as to every bank; the 2-D
  ``scene`` argument and ``bind_world`` can be ignored.

``set_sensors(row_world, row_robot, specs)`` and ``read(s, rng)`` (noise from the world's
sensor stream) mean what they mean for every bank. A robot carrying a type missing here is
refused at reset with a one-line :class:`~arena.core.errors.ConfigError`
(:func:`check_served`).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING

from arena.core.errors import ConfigError

if TYPE_CHECKING:
    from arena.scene.episode import Episode
    from arena.sensors.base import SensorBank
    from arena.sim.mujoco.contacts import MjHandle

MUJOCO_BANKS: dict[str, str] = {
    "lidar2d": "arena.sim.mujoco.lidar2d:MujocoLidar2DBank",
    "rgbd": "arena.sim.mujoco.banks3d:MujocoRgbdBank",
    "lidar3d": "arena.sim.mujoco.banks3d:MujocoLidar3DBank",
}
"""Sensor type -> ``"module:Class"`` of its MuJoCo bank (imported when a robot carries it)."""


def bank_factory(handle: MjHandle) -> Callable[[str], SensorBank]:
    """``kind -> new bank`` for :class:`~arena.sim.engine.stages.SensorStage`."""

    def make(kind: str) -> SensorBank:
        module, _, name = MUJOCO_BANKS[kind].partition(":")
        cls = getattr(importlib.import_module(module), name)
        bank: SensorBank = cls(handle)
        return bank

    return make


def check_served(episode: Episode) -> None:
    """One-line :class:`ConfigError` for the first sensor of a robot no MuJoCo bank serves."""
    for robot in episode.robots:
        for name, spec in robot.model.sensors.items():
            kind = str(spec.type)
            if kind not in MUJOCO_BANKS:
                raise ConfigError(
                    f"sim.backend: robot {robot.name!r} (model {robot.model.name!r}) carries "
                    f"sensor {name!r} of type {kind!r}, which the mujoco backend cannot "
                    f"simulate; it serves {', '.join(sorted(MUJOCO_BANKS))}"
                )
