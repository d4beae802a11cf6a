"""The ``lidar2d`` sensor in the MuJoCo backend: the same beams, cast into the 3-D world.

Beam ``i`` of a :class:`~arena.sensors.spec.LidarSpec` leaves the sensor origin (the robot pose
composed with ``mount``) at the same angle as in the 2-D engine, horizontally, at the scan
height: ``lidar_height`` (backend parameter) or 0.9 × the carrying robot's height. One
``mujoco.mj_multiRay`` call casts a scan against every geom except the robot's own body; a beam
that hits nothing within ``range_max`` reports ``range_max``, a hit nearer than ``range_min``
reports ``range_min``, and noise is added from the world's sensor stream exactly as the 2-D bank
adds it (:meth:`~arena.sensors.lidar2d.LidarBank.read`).

What a beam sees is the 3-D world at the scan height: wall boxes (the map's cells, as in 2-D),
the obstacle models' parts at that height (a table's legs, not its top), the other robots'
bodies, and of a person what the figure has there (below the hips: two leg capsules swinging
with the gait, instead of the 2-D body circle). With ``pedestrians_block_lidar: false`` the
people's geoms (geom group :data:`~arena.sim.mujoco.sim.PERSON_GROUP`) are skipped. A scan plane
below :data:`~arena.sim.mujoco.sim.HIGH_Z` skips the geoms entirely above it (their group
:data:`~arena.sim.mujoco.sim.HIGH_GROUP`): they cannot be hit, and ``mj_multiRay`` tests every
geom it is given against every beam.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import SimulationError
from arena.sensors.lidar2d.kernels import _add_noise
from arena.sensors.spec import LidarSpec
from arena.sim.mujoco.contacts import MjHandle
from arena.sim.mujoco.sim import HIGH_GROUP, HIGH_Z, PERSON_GROUP

F64 = NDArray[np.float64]

LIDAR_HEIGHT_FRACTION = 0.9
"""Scan height as a fraction of the robot's height when ``lidar_height`` is not set."""


class MujocoLidar2DBank:
    """Every ``lidar2d`` row of the MuJoCo backend (see the module docstring)."""

    Params = LidarSpec

    def __init__(self, handle: MjHandle) -> None:
        self._handle = handle
        self._robot: list[int] = []
        self._specs: list[LidarSpec] = []
        self._cos: list[F64] = []
        self._sin: list[F64] = []
        self._out: list[F64] = []
        self._geomid: list[NDArray[np.int32]] = []
        self._vec: list[F64] = []

    def bind_world(self, w: int, grid: Any, segments_a: Any = None, segments_b: Any = None) -> None:
        """Nothing to do: the static world is in the compiled model."""

    def set_sensors(
        self, row_world: ArrayLike, row_robot: ArrayLike, specs: Sequence[LidarSpec]
    ) -> None:
        """The rows: robot row and spec of each; they read ``range_max`` until scanned."""
        robots = [int(r) for r in np.asarray(row_robot, dtype=np.int64).reshape(-1)]
        specs = list(specs)
        if len(robots) != len(specs):
            raise SimulationError("row_robot and specs must have the same length")
        self._robot, self._specs = robots, specs
        self._cos, self._sin, self._out, self._geomid, self._vec = [], [], [], [], []
        for spec in specs:
            if not isinstance(spec, LidarSpec):
                raise SimulationError(f"a lidar2d row needs a LidarSpec, got {type(spec).__name__}")
            a = spec.angles() + spec.mount[2]
            self._cos.append(np.cos(a))
            self._sin.append(np.sin(a))
            self._out.append(np.full(spec.num_beams, spec.range_max))
            self._geomid.append(np.zeros(spec.num_beams, dtype=np.int32))
            self._vec.append(np.zeros((spec.num_beams, 3)))

    def scan(
        self, due: ArrayLike, poses: ArrayLike, scene: Any, *, parallel: bool = False,
        chunksize: int = 1,
    ) -> None:
        """Cast the ``due`` rows from the ``(R, 3)`` robot poses (``scene`` is not needed)."""
        world = self._handle.get()
        mj = world._mj
        q = np.asarray(poses, dtype=np.float64)
        fixed = self._handle.params.lidar_height
        people = self._handle.params.pedestrians_block_lidar
        for s in np.flatnonzero(np.asarray(due, dtype=bool)).tolist():
            spec, r = self._specs[s], self._robot[s]
            x, y, th = q[r]
            c, si = np.cos(th), np.sin(th)
            mx, my = spec.mount[0], spec.mount[1]
            z = fixed if fixed is not None else LIDAR_HEIGHT_FRACTION * world.robot_height[r]
            group = _GROUPS[(bool(z >= HIGH_Z), people)]
            pnt = np.array([x + c * mx - si * my, y + si * mx + c * my, z])
            vec = self._vec[s]
            ca, sa = self._cos[s], self._sin[s]
            vec[:, 0] = c * ca - si * sa
            vec[:, 1] = si * ca + c * sa
            dist = self._out[s]
            mj.mj_multiRay(world.model, world.data, pnt, vec.reshape(-1), group, 1,
                           int(world.robot_body[r]), self._geomid[s], dist, None, spec.num_beams,
                           spec.range_max)
            # no hit (-1) or beyond the range: range_max; nearer than range_min: range_min
            np.clip(dist, spec.range_min, spec.range_max, out=dist)
            dist[self._geomid[s] < 0] = spec.range_max

    def ranges(self, s: int) -> F64:
        """Row ``s``'s latest ranges (m), the bank's own array: copy to keep."""
        return self._out[s]

    def read(self, s: int, rng: np.random.Generator | None) -> F64:
        """Row ``s``'s latest ranges as a new array, noise drawn from ``rng`` as in 2-D."""
        out = self._out[s].copy()
        spec = self._specs[s]
        if rng is not None and spec.noise_std > 0.0:
            row = out[None]
            _add_noise(row, rng.standard_normal(row.shape), spec.noise_std, spec.range_min,
                       spec.range_max)
        return out


def _groups(high: bool, people: bool) -> NDArray[np.uint8]:
    """The geom groups a ray cast takes (a ``(6,)`` mask).

    The high geoms only from a plane that can reach them; the people only when they are seen.
    """
    mask = np.ones(6, dtype=np.uint8)
    mask[HIGH_GROUP] = high
    mask[PERSON_GROUP] = people
    return mask


_GROUPS = {(h, p): _groups(h, p) for h in (False, True) for p in (False, True)}
