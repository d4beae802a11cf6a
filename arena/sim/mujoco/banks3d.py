"""The ``rgbd`` and ``lidar3d`` sensor types in the MuJoCo backend (banks of :data:`MUJOCO_BANKS`).

Each bank holds its rows' measuring objects and reads the episode's
:class:`~arena.sim.mujoco.sim.MjWorld` at every scan (see :mod:`arena.sim.mujoco.sensors` for
the interface). Readings:

* ``rgbd``: an :class:`~arena.sensors.spec3d.RgbdFrame` (``rgb`` ``(H, W, 3)`` uint8, ``depth``
  ``(H, W)`` float32 m along the optical axis, ``0`` for no return, ``person`` ``(H, W)`` int32
  pedestrian index, ``-1`` for none), rendered by :class:`~arena.sim.mujoco.camera.RgbdCamera`
  (colour and depth in one pass, person ids in a second). Before its first frame a row reads a
  black image with no depth and no person. The camera draws its own robot's body: mount it
  outside the body (:class:`~arena.sensors.spec3d.RgbdSpec`).
* ``lidar3d``: ``(rings, num_beams)`` ranges (m) from :class:`~arena.sim.mujoco.lidar3d.Lidar3D`,
  the robot's own body excluded; ``range_max`` before the first scan.

Noise comes from the world's sensor stream at :meth:`read`, as for ``lidar2d``: one ``(H, W)``
normal draw per frame with ``depth_noise_std > 0``, one ``(rings, num_beams)`` draw per 3-D scan
with ``noise_std > 0``.

A camera keeps a GL context and render buffers bound to one compiled model: the bank builds its
cameras for the episode's world when a world first scans and frees them when the next episode's
world replaces it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import SimulationError
from arena.sensors.spec3d import Lidar3DSpec, RgbdFrame, RgbdSpec
from arena.sim.mujoco.camera import RgbdCamera, add_depth_noise
from arena.sim.mujoco.contacts import MjHandle
from arena.sim.mujoco.lidar3d import Lidar3D, add_noise
from arena.sim.mujoco.sim import MjWorld


def _rows(row_robot: ArrayLike, specs: Sequence[Any], kind: type, name: str) -> list[int]:
    """The robot row of each sensor row, after checking the specs' type."""
    robots = [int(r) for r in np.asarray(row_robot, dtype=np.int64).reshape(-1)]
    if len(robots) != len(specs):
        raise SimulationError("row_robot and specs must have the same length")
    for spec in specs:
        if not isinstance(spec, kind):
            raise SimulationError(f"a {name} row needs a {kind.__name__}, got "
                                  f"{type(spec).__name__}")
    return robots


class MujocoRgbdBank:
    """Every ``rgbd`` row of the MuJoCo backend (see the module docstring)."""

    Params = RgbdSpec

    def __init__(self, handle: MjHandle) -> None:
        self._handle = handle
        self._robot: list[int] = []
        self._specs: list[RgbdSpec] = []
        self._frames: list[RgbdFrame] = []
        self._cameras: list[RgbdCamera] = []
        self._world: MjWorld | None = None  # the world the cameras render

    def bind_world(self, w: int, grid: Any, segments_a: Any = None, segments_b: Any = None) -> None:
        """Nothing to do: the static world is in the compiled model."""

    def set_sensors(
        self, row_world: ArrayLike, row_robot: ArrayLike, specs: Sequence[RgbdSpec]
    ) -> None:
        """The rows: robot row and spec of each; they read a black frame until rendered."""
        self._robot = _rows(row_robot, specs, RgbdSpec, "rgbd")
        self._specs = list(specs)
        self._frames = [_blank(spec) for spec in self._specs]
        self._close()  # new rows: cameras for the (next) world's model, built at the scan

    def _close(self) -> None:
        for cam in self._cameras:
            cam.close()
        self._cameras, self._world = [], None

    def _cameras_for(self, world: MjWorld) -> list[RgbdCamera]:
        """The cameras on ``world``'s model (built when the world changed)."""
        if world is not self._world:
            self._close()
            self._cameras = [RgbdCamera(world.model, spec) for spec in self._specs]
            self._world = world
        return self._cameras

    def scan(
        self, due: ArrayLike, poses: ArrayLike, scene: Any, *, parallel: bool = False,
        chunksize: int = 1,
    ) -> None:
        """Render the ``due`` rows from the ``(R, 3)`` robot poses (``scene`` is not needed)."""
        world = self._handle.get()
        cameras = self._cameras_for(world)
        q = np.asarray(poses, dtype=np.float64)
        for s in np.flatnonzero(np.asarray(due, dtype=bool)).tolist():
            self._frames[s] = cameras[s].render(world.data, q[self._robot[s]])

    def read(self, s: int, rng: np.random.Generator | None) -> RgbdFrame:
        """Row ``s``'s latest frame as new arrays, depth noise drawn from ``rng``."""
        f, spec = self._frames[s], self._specs[s]
        depth = (add_depth_noise(f.depth, spec, rng) if rng is not None
                 and spec.depth_noise_std > 0.0 else f.depth.copy())
        person = None if f.person is None else f.person.copy()
        return RgbdFrame(f.rgb.copy(), depth, person)


def _blank(spec: RgbdSpec) -> RgbdFrame:
    """A frame before the first render: black, no depth, nobody."""
    h, w = spec.height, spec.width
    return RgbdFrame(np.zeros((h, w, 3), dtype=np.uint8), np.zeros((h, w), dtype=np.float32),
                     np.full((h, w), -1, dtype=np.int32))


class MujocoLidar3DBank:
    """Every ``lidar3d`` row of the MuJoCo backend (see the module docstring)."""

    Params = Lidar3DSpec

    def __init__(self, handle: MjHandle) -> None:
        self._handle = handle
        self._robot: list[int] = []
        self._lidars: list[Lidar3D] = []
        self._out: list[NDArray[np.float64]] = []

    def bind_world(self, w: int, grid: Any, segments_a: Any = None, segments_b: Any = None) -> None:
        """Nothing to do: the static world is in the compiled model."""

    def set_sensors(
        self, row_world: ArrayLike, row_robot: ArrayLike, specs: Sequence[Lidar3DSpec]
    ) -> None:
        """The rows: robot row and spec of each; they read ``range_max`` until scanned."""
        self._robot = _rows(row_robot, specs, Lidar3DSpec, "lidar3d")
        self._lidars = [Lidar3D(spec) for spec in specs]
        self._out = [np.full((spec.rings, spec.num_beams), spec.range_max) for spec in specs]

    def scan(
        self, due: ArrayLike, poses: ArrayLike, scene: Any, *, parallel: bool = False,
        chunksize: int = 1,
    ) -> None:
        """Cast the ``due`` rows from the ``(R, 3)`` robot poses (``scene`` is not needed)."""
        world = self._handle.get()
        q = np.asarray(poses, dtype=np.float64)
        for s in np.flatnonzero(np.asarray(due, dtype=bool)).tolist():
            r = self._robot[s]
            self._out[s] = self._lidars[s].scan(world.model, world.data, q[r],
                                                int(world.robot_body[r]))

    def read(self, s: int, rng: np.random.Generator | None) -> NDArray[np.float64]:
        """Row ``s``'s latest ranges as a new array, noise drawn from ``rng``."""
        spec = self._lidars[s].spec
        if rng is None or spec.noise_std <= 0.0:
            return self._out[s].copy()
        return add_noise(self._out[s], spec, rng)
