"""A multi-ring (3-D) lidar over a compiled MuJoCo world, cast with ``mj_multiRay``.

Every beam of a scan leaves the one mount point, so one ``mj_multiRay`` call casts them all
against the geoms MuJoCo draws by default (groups 0-2, static ones included), with
``range_max`` as the cutoff. The robot carrying the lidar passes its own body as
``exclude_body``: a sensor mounted inside its body box does not see it. Ranges follow
:class:`~arena.sensors.spec3d.Lidar3DSpec` (and the 2-D lidar): no hit before ``range_max``
reads ``range_max``, a hit nearer than ``range_min`` reads ``range_min``; noise is a separate
step (:func:`add_noise`) drawn from a given generator.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.sensors.lidar2d.kernels import _add_noise
from arena.sensors.spec3d import Lidar3DSpec
from arena.sim.mujoco.mjcf import import_mujoco

VISIBLE_GROUPS = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8)
"""Geom groups a beam sees: those MuJoCo draws by default (what the camera shows)."""


class Lidar3D:
    """Scans of one :class:`~arena.sensors.spec3d.Lidar3DSpec` (reusable for any world)."""

    def __init__(self, spec: Lidar3DSpec) -> None:
        self.spec = spec
        self._mj = import_mujoco()
        self._dirs = spec.directions().reshape(-1, 3)  # sensor frame
        n = len(self._dirs)
        self._vec = np.empty((n, 3))
        self._geom = np.empty(n, dtype=np.int32)
        self._dist = np.empty(n)

    def origin(self, pose: ArrayLike) -> tuple[NDArray[np.float64], float]:
        """``(position (3,) m, heading rad)`` of the sensor for robot base pose ``(x, y, yaw)``."""
        x, y, yaw = (float(v) for v in np.asarray(pose, dtype=np.float64).reshape(3))
        mx, my, mz, myaw = self.spec.mount
        c, s = math.cos(yaw), math.sin(yaw)
        return np.array([x + c * mx - s * my, y + s * mx + c * my, mz]), yaw + myaw

    def scan(
        self, model: Any, data: Any, pose: ArrayLike, exclude_body: int = -1
    ) -> NDArray[np.float64]:
        """``(rings, num_beams)`` ranges (m) from robot base pose ``pose`` ``(x, y, yaw)``.

        Args:
            model: the compiled world (``MjModel``).
            data: its state (``MjData``), current (after ``mj_forward`` or ``mj_step``).
            pose: the robot's base pose (m, m, rad); the mount is applied.
            exclude_body: id of a body the beams pass through (the robot's own), -1 none.

        Returns:
            A new array without noise; ring 0 is the lowest (``vertical_min``).
        """
        spec = self.spec
        pos, heading = self.origin(pose)
        c, s = math.cos(heading), math.sin(heading)
        d = self._dirs
        vec = self._vec
        vec[:, 0] = c * d[:, 0] - s * d[:, 1]
        vec[:, 1] = s * d[:, 0] + c * d[:, 1]
        vec[:, 2] = d[:, 2]
        self._mj.mj_multiRay(model, data, pos, vec.reshape(-1), VISIBLE_GROUPS, 1,
                             int(exclude_body), self._geom, self._dist, None, len(d),
                             spec.range_max)
        r = self._dist
        out = np.where((self._geom < 0) | (r < 0) | (r >= spec.range_max), spec.range_max,
                       np.maximum(r, spec.range_min))
        return out.reshape(spec.rings, spec.num_beams)


def add_noise(
    ranges: NDArray[np.float64], spec: Lidar3DSpec, rng: np.random.Generator
) -> NDArray[np.float64]:
    """A copy of ``ranges`` ``(rings, num_beams)`` with the spec's Gaussian range noise.

    As the 2-D lidar: one ``(rings, num_beams)`` standard normal draw when ``noise_std > 0``
    (none otherwise), added to the hits only (``range_max`` returns stay), clipped to
    ``[range_min, range_max]``.
    """
    out = np.array(ranges, dtype=np.float64, order="C")
    if spec.noise_std > 0.0:
        _add_noise(out, rng.standard_normal(out.shape), spec.noise_std, spec.range_min,
                   spec.range_max)
    return out
