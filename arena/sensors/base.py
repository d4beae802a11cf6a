"""The sensor registry and the protocol every sensor type's engine bank follows.

A sensor type is registered under its YAML ``type:`` name as its *bank* class: the object the
engine keeps, one per sensor type present, holding every sensor of that type of every world as
rows. The bank class declares its ``Params`` (a frozen pydantic model with a
``type: Literal["<name>"]`` field defaulting to the name, so that a dumped robot reloads) and
``update_rate`` (Hz) among them; the engine holds a row's reading for ``1 / update_rate`` s.

A robot carries ``sensors: {name: {type: <registered name>, **params}}``
(:attr:`arena.robots.model.RobotModel.sensors`); the engine gives each ``(robot, name)`` a row
of that type's bank and exposes its reading by name
(:attr:`arena.scene.state.RobotStates.sensors`). A new type (rgbd, lidar3d, a test's toy) plugs
in by registering, without touching the engine::

    @SENSORS.register("range_ring")
    class RangeRingBank:
        Params = RangeRingSpec       # type: Literal["range_ring"] = "range_ring", update_rate ...
        def bind_world(self, w, grid, segments_a, segments_b): ...
        def set_sensors(self, row_world, row_robot, specs): ...
        def scan(self, due, poses, scene, *, parallel=False, chunksize=1): ...
        def read(self, s, rng): ...
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike
from pydantic import BaseModel

from arena.core.registry import Registry

if TYPE_CHECKING:
    from arena.maps.grid import OccupancyGrid
    from arena.sensors.lidar2d.bank import DynamicGeometry


@runtime_checkable
class SensorBank(Protocol):
    """Every sensor of one type of every world of an engine, as rows ``0..S-1``.

    Usage by the engine: ``bind_world`` when world ``w`` resets; ``set_sensors`` after any
    reset (row ``s`` carried by global robot row ``row_robot[s]`` of world ``row_world[s]``,
    parameters ``specs[s]``); per step ``scan(due, poses, scene)`` on the due rows, then per
    due row, in row order, ``read(s, rng)`` with that world's sensor stream (the engine keeps
    the array it returns: a new one each time).
    """

    Params: ClassVar[type[BaseModel]]

    def bind_world(
        self, w: int, grid: OccupancyGrid, segments_a: ArrayLike | None = None,
        segments_b: ArrayLike | None = None,
    ) -> None:
        """World ``w``'s static map and obstacle edges ``(s, 2)`` each (m)."""
        ...

    def set_sensors(
        self, row_world: ArrayLike, row_robot: ArrayLike, specs: Sequence[Any]
    ) -> None:
        """The rows of this bank (see the class docstring)."""
        ...

    def scan(
        self, due: ArrayLike, poses: ArrayLike, scene: DynamicGeometry, *,
        parallel: bool = False, chunksize: int = 1,
    ) -> None:
        """Take the readings of the ``(S,)`` bool ``due`` rows from the ``(R, 3)`` robot poses.

        ``scene`` holds every world's moving circles and segments (pedestrians, other robots).
        """
        ...

    def read(self, s: int, rng: np.random.Generator | None) -> Any:
        """Row ``s``'s latest reading, new arrays, its noise drawn from ``rng``.

        A reading is an array (``lidar2d``: ``(beams,)`` ranges) or a frozen dataclass of
        arrays (``rgbd``: :class:`~arena.sensors.spec3d.RgbdFrame`); the engine makes its arrays
        read-only (:func:`freeze_reading`).

        ``rng`` ``None``: without noise (the reading of a row before its first scan).
        """
        ...


def freeze_reading(reading: Any) -> Any:
    """``reading`` with its arrays made read-only (the engine shares readings with snapshots).

    A reading is an array (a lidar's ranges) or a frozen dataclass of arrays (an RGB-D frame);
    returns ``reading`` itself.
    """
    if isinstance(reading, np.ndarray):
        reading.flags.writeable = False
    else:
        for value in vars(reading).values():
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
    return reading


SENSORS: Registry[SensorBank] = Registry(
    "sensor",
    entry_points="arena.sensors",
    builtins={"lidar2d": "arena.sensors.lidar2d.bank", "rgbd": "arena.sensors.needs3d",
              "lidar3d": "arena.sensors.needs3d"},
    # validating a robot does not import the numba scanning code
    params={"lidar2d": "arena.sensors.spec:LidarSpec", "rgbd": "arena.sensors.spec3d:RgbdSpec",
            "lidar3d": "arena.sensors.spec3d:Lidar3DSpec"},
)
"""Sensor types by YAML ``type:`` name; each entry is the type's :class:`SensorBank` class."""
