"""The ``rgbd`` and ``lidar3d`` sensor types in the registry: measured by the 3-D backend only.

A robot YAML may declare them (their ``Params`` validate with the robot); the 2-D engine, which
builds a sensor type's bank when a robot carries it, gets a bank that refuses to bind with a
one-line :class:`~arena.core.errors.ConfigError`: images and 3-D scans need the MuJoCo world
(:mod:`arena.sim.mujoco.camera`, :mod:`arena.sim.mujoco.lidar3d`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar, NoReturn

from numpy.typing import ArrayLike
from pydantic import BaseModel

from arena.core.errors import ConfigError
from arena.sensors.base import SENSORS
from arena.sensors.spec3d import Lidar3DSpec, RgbdSpec


class _Needs3D:
    """A 2-D engine bank for a sensor type that only the 3-D backend measures."""

    Params: ClassVar[type[BaseModel]]
    kind: ClassVar[str]

    def _refuse(self) -> NoReturn:
        raise ConfigError(
            f"sensor type {self.kind!r} needs the 3-D backend (sim.backend.type: mujoco)"
        )

    def bind_world(self, w: int, grid: Any, segments_a: ArrayLike | None = None,
                   segments_b: ArrayLike | None = None) -> None:
        """Refused: see the module docstring."""
        self._refuse()

    def set_sensors(self, row_world: ArrayLike, row_robot: ArrayLike,
                    specs: Sequence[Any]) -> None:
        """Refused: see the module docstring."""
        self._refuse()

    def scan(self, due: ArrayLike, poses: ArrayLike, scene: Any, *, parallel: bool = False,
             chunksize: int = 1) -> None:
        """Refused: see the module docstring."""
        self._refuse()

    def read(self, s: int, rng: Any) -> NoReturn:
        """Refused: see the module docstring."""
        self._refuse()


@SENSORS.register("rgbd")
class RgbdNeeds3D(_Needs3D):
    """RGB-D camera (colour, depth, person ids): measured by the MuJoCo backend."""

    Params = RgbdSpec
    kind = "rgbd"


@SENSORS.register("lidar3d")
class Lidar3DNeeds3D(_Needs3D):
    """Multi-ring 3-D lidar: measured by the MuJoCo backend."""

    Params = Lidar3DSpec
    kind = "lidar3d"
