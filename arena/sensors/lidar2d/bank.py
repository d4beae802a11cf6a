"""TEMPORARY reference version (lead replaces at merge): every lidar of every world.

:class:`LidarBank` keeps the interface of the engine design (bind_world / set_sensors / scan /
ranges) and loops in Python over one :class:`~arena.sensors.lidar2d.Lidar2D` per sensor row,
passing each row the circles and segments of its world except those its own robot owns, in
scene order: exactly the scans ``native2d`` took before the engine.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.maps.grid import OccupancyGrid
from arena.sensors.lidar2d.model import Lidar2D
from arena.sensors.spec import LidarSpec

if TYPE_CHECKING:
    from arena.sim.engine.scene import DynamicScene

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


class LidarBank:
    """Every lidar of every world, scanned in one call."""

    def __init__(self) -> None:
        self._static: dict[int, tuple[OccupancyGrid, F64, F64]] = {}
        self._pool: dict[int, list[Lidar2D]] = {}  # by id(spec): reused across episodes
        self._lidars: list[Lidar2D] = []
        self._row_world: list[int] = []
        self._row_robot: list[int] = []
        self._out: list[F64] = []

    def bind_world(self, w: int, grid: OccupancyGrid, segments_a: F64, segments_b: F64) -> None:
        """Static geometry of world ``w`` (call when world ``w`` resets)."""
        self._static[w] = (grid, segments_a, segments_b)

    def set_sensors(
        self, row_world: I64, row_robot: I64, specs: Sequence[LidarSpec]
    ) -> None:
        """Sensor rows: sensor ``s`` is carried by global robot row ``row_robot[s]``."""
        self._row_world = [int(w) for w in row_world]
        self._row_robot = [int(r) for r in row_robot]
        used: dict[int, int] = {}
        lidars = []
        for s, spec in enumerate(specs):
            pool = self._pool.setdefault(id(spec), [])
            k = used.get(id(spec), 0)
            used[id(spec)] = k + 1
            if k == len(pool) or pool[k].spec != spec:
                if k == len(pool):
                    pool.append(Lidar2D(spec))
                else:
                    pool[k] = Lidar2D(spec)
            lidar = pool[k]
            grid, a, b = self._static[self._row_world[s]]
            lidar.bind(grid, a, b)
            lidars.append(lidar)
        self._lidars = lidars
        self._out = [np.full(sp.num_beams, sp.range_max) for sp in specs]

    def scan(
        self, due: NDArray[np.bool_], poses: F64, scene: DynamicScene, *, parallel: bool = False
    ) -> None:
        """Cast the due rows; a row ignores the circles and segments its own robot owns."""
        for s in [i for i, d in enumerate(due.tolist()) if d]:
            w, r = self._row_world[s], self._row_robot[s]
            c0, c1 = int(scene.circ_off[w]), int(scene.circ_off[w + 1])
            k0, k1 = int(scene.seg_off[w]), int(scene.seg_off[w + 1])
            cxy, cr = scene.circ_xy[c0:c1], scene.circ_r[c0:c1]
            own = scene.circ_owner[c0:c1]
            # robots' circles come after the people's: none owned when the last is nobody's
            if c1 > c0 and own[-1] >= 0 and (own == r).any():
                keep = own != r
                cxy, cr = cxy[keep], cr[keep]
            sa: F64 | None = None
            sb: F64 | None = None
            if k1 > k0:
                keep_s = scene.seg_owner[k0:k1] != r
                if keep_s.any():
                    sa, sb = scene.seg_a[k0:k1][keep_s], scene.seg_b[k0:k1][keep_s]
            self._out[s] = self._lidars[s].scan(poses[r], cxy, cr, sa, sb)

    def ranges(self, s: int) -> F64:
        """``(num_beams,)`` ranges (m) of sensor row ``s`` (a view; the next scan replaces it)."""
        return self._out[s]
