""":class:`ContactBank`: the contacts of every robot of every world in one kernel call.

Flat layout (``docs/architecture.md``, the engine's): worlds ``w = 0..W-1``; the robots of all
worlds are global rows ``0..R-1``, world ``w`` owning the consecutive rows
``robot_off[w]:robot_off[w+1]``; the pedestrians of world ``w`` are rows ``ag_off[w]:ag_off[w+1]``
of ``ag_pos``/``ag_r``. Reported indices are local to the world: obstacle ``o`` is
``world.obstacles[o]``, agent ``k`` the world's ``k``-th pedestrian, robot ``j`` its ``j``-th
robot; ``-1`` is none. A row reads only its own world's slices, so world ``w``'s flags depend
neither on ``W``, nor on the other worlds, nor on the thread count.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import SimulationError
from arena.maps.grid import OccupancyGrid
from arena.scene.state import StaticWorld
from arena.sim.contacts.checks import grid_params
from arena.sim.contacts.footprint import Footprint, ObstacleIndex
from arena.sim.contacts.kernels import contacts_rows

ContactFlags = tuple[NDArray[np.bool_], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]
"""``(wall, obstacle, agent, robot)``, each ``(R,)``: the fields of a ``Collisions``."""

_MIN_COMPACT_CELLS = 1 << 20
"""Cells of unused grids tolerated in the pack before it is compacted (~9 MB)."""


@dataclass
class _GridSlot:
    """Where one grid's cells lie in the bank's flat arrays."""

    grid: OccupancyGrid  # held, so that its id is not reused while the slot exists
    start: int
    params: NDArray[np.float64]  # (7,), see kernels.grid_hit


class ContactBank:
    """Exact-footprint contacts of every robot of every world, one kernel call.

    Static geometry is packed once per object: worlds (and episodes) sharing a grid share its
    cells; the cells of grids no world uses any more are dropped when they outgrow the used ones.
    """

    def __init__(self) -> None:
        self._grid_of: list[OccupancyGrid | None] = []  # per world
        self._obstacles_of: list[ObstacleIndex | None] = []
        self._slots: dict[int, _GridSlot] = {}  # id(grid) -> slot
        self._occ = np.zeros(0, dtype=np.bool_)
        self._dist = np.zeros(0)
        self._used = 0  # cells filled in _occ/_dist
        self._g_off = np.zeros(0, dtype=np.int64)
        self._g_shape = np.zeros((0, 2), dtype=np.int64)
        self._g_par = np.zeros((0, 7))
        self._obstacle_cache: dict[int, tuple[tuple[object, ...], ObstacleIndex]] = {}
        self._obstacles_packed: tuple[NDArray, ...] | None = None
        self._row_world = np.zeros(0, dtype=np.int64)
        self._robot_off = np.zeros(1, dtype=np.int64)
        self._fp: tuple[NDArray, ...] = (
            np.zeros(0),
            np.zeros(0),
            np.zeros(1, dtype=np.int64),
            np.zeros((0, 2)),
        )
        self._all_rows = np.zeros(0, dtype=np.bool_)

    @property
    def num_worlds(self) -> int:
        """``W``: one more than the highest world bound so far."""
        return len(self._grid_of)

    # -- static worlds -------------------------------------------------------------------------
    def bind_world(self, w: int, world: StaticWorld) -> None:
        """Static geometry of world ``w`` (grid walls and obstacles); call when ``w`` resets."""
        if w < 0:
            raise SimulationError(f"world index must be >= 0, got {w}")
        while len(self._grid_of) <= w:
            self._grid_of.append(None)
            self._obstacles_of.append(None)
        grid = world.grid
        slot = self._slots.get(id(grid))
        if slot is None or slot.grid is not grid:
            slot = self._pack_grid(grid)
        self._grid_of[w] = grid
        self._obstacles_of[w] = self._obstacle_index(world)
        self._obstacles_packed = None
        if self._maybe_compact() or self._g_off.shape[0] != len(self._grid_of):
            self._world_grid_arrays()
        else:  # only world w changed
            self._g_off[w] = slot.start
            self._g_shape[w] = grid.height, grid.width
            self._g_par[w] = slot.params

    def _pack_grid(self, grid: OccupancyGrid) -> _GridSlot:
        """Append ``grid``'s blocking cells and distance map to the flat arrays."""
        n = grid.height * grid.width
        if self._used + n > self._occ.shape[0]:
            cap = max(2 * self._occ.shape[0], self._used + n)
            occ, dist = np.zeros(cap, dtype=np.bool_), np.zeros(cap)
            occ[: self._used] = self._occ[: self._used]
            dist[: self._used] = self._dist[: self._used]
            self._occ, self._dist = occ, dist
        self._occ[self._used : self._used + n] = grid.occupied.ravel()
        self._dist[self._used : self._used + n] = grid.distance.ravel()
        slot = _GridSlot(grid, self._used, grid_params(grid))
        self._used += n
        self._slots[id(grid)] = slot
        return slot

    def _maybe_compact(self) -> bool:
        """Repack only the grids some world uses once the unused cells outnumber them.

        Returns whether it did (the grids moved).
        """
        live = {id(g) for g in self._grid_of if g is not None}
        live_cells = sum(s.grid.height * s.grid.width for k, s in self._slots.items() if k in live)
        if self._used - live_cells <= max(live_cells, _MIN_COMPACT_CELLS):
            return False
        slots = [s for k, s in self._slots.items() if k in live]
        self._slots, self._used = {}, 0
        self._occ, self._dist = np.zeros(live_cells, dtype=np.bool_), np.zeros(live_cells)
        for s in slots:
            self._pack_grid(s.grid)
        return True

    def _world_grid_arrays(self) -> None:
        """Per world: its grid's start in the flat arrays, ``(h, w)`` and parameters."""
        n = len(self._grid_of)
        self._g_off = np.zeros(n, dtype=np.int64)
        self._g_shape = np.zeros((n, 2), dtype=np.int64)
        self._g_par = np.zeros((n, 7))
        for w, grid in enumerate(self._grid_of):
            if grid is None:
                continue
            slot = self._slots[id(grid)]
            self._g_off[w] = slot.start
            self._g_shape[w] = grid.height, grid.width
            self._g_par[w] = slot.params

    def _obstacle_index(self, world: StaticWorld) -> ObstacleIndex:
        """``ObstacleIndex.build(world)``, the same object for the same obstacle tuple."""
        hit = self._obstacle_cache.get(id(world.obstacles))
        if hit is not None and hit[0] is world.obstacles:
            return hit[1]
        if len(self._obstacle_cache) >= 4 * max(len(self._grid_of), 16):
            self._obstacle_cache.clear()  # episodes with fresh obstacles: keep it small
        index = ObstacleIndex.build(world)
        self._obstacle_cache[id(world.obstacles)] = (world.obstacles, index)
        return index

    def _packed_obstacles(self) -> tuple[NDArray, ...]:
        """``(o_off (W+1,), centers (O, 2), radii (O,), vstart (O+1,), verts (V, 2))``."""
        if self._obstacles_packed is None:
            idx = [i for i in self._obstacles_of if i is not None]
            o_off = np.zeros(len(self._obstacles_of) + 1, dtype=np.int64)
            o_off[1:] = np.cumsum([0 if i is None else len(i.polygons) for i in self._obstacles_of])
            base = np.cumsum([0] + [i.verts.shape[0] for i in idx])  # first vertex per world
            vstart = np.concatenate(
                [i.vstart[:-1] + b for i, b in zip(idx, base[:-1], strict=True)]
                + [base[-1:]]
            ).astype(np.int64)
            self._obstacles_packed = (
                o_off,
                np.concatenate([np.zeros((0, 2))] + [i.centers for i in idx]),
                np.concatenate([np.zeros(0)] + [i.radii for i in idx]),
                vstart,
                np.ascontiguousarray(np.concatenate([np.zeros((0, 2))] + [i.verts for i in idx])),
            )
        return self._obstacles_packed

    # -- robots --------------------------------------------------------------------------------
    def set_robots(self, row_world: NDArray[np.int64], footprints: Sequence[Footprint]) -> None:
        """The robots (global rows, grouped by world) and their footprints; call after resets.

        Raises:
            SimulationError: rows not grouped by ascending world, a world never bound, or
                not one footprint per row.
        """
        rw = np.ascontiguousarray(row_world, dtype=np.int64).reshape(-1)
        if len(footprints) != rw.shape[0]:
            raise SimulationError(
                f"set_robots: {rw.shape[0]} rows but {len(footprints)} footprints"
            )
        if rw.size and (np.any(np.diff(rw) < 0) or rw[0] < 0):
            raise SimulationError("set_robots: row_world must be ascending world indices >= 0")
        known = self.num_worlds
        unbound = [int(w) for w in np.unique(rw) if w >= known or self._grid_of[w] is None]
        if unbound:
            raise SimulationError(f"set_robots: world(s) {unbound} not bound (bind_world first)")
        self._row_world = rw
        self._robot_off = np.searchsorted(rw, np.arange(self.num_worlds + 1)).astype(np.int64)
        vstart = np.zeros(rw.shape[0] + 1, dtype=np.int64)
        vstart[1:] = np.cumsum([fp.body.shape[0] for fp in footprints])
        bodies = [np.zeros((0, 2)), *(fp.body for fp in footprints)]
        self._fp = (
            np.array([fp.radius for fp in footprints], dtype=np.float64),
            np.array([fp.reach for fp in footprints], dtype=np.float64),
            vstart,
            np.ascontiguousarray(np.concatenate(bodies)),
        )
        self._all_rows = np.ones(rw.shape[0], dtype=np.bool_)

    # -- the test ------------------------------------------------------------------------------
    def test(
        self,
        poses: NDArray[np.float64],
        previous: NDArray[np.float64] | None,
        ag_off: NDArray[np.int64],
        ag_pos: NDArray[np.float64],
        ag_r: NDArray[np.float64],
        *,
        rows: NDArray[np.bool_] | None = None,
        parallel: bool = False,
    ) -> ContactFlags:
        """Contacts of every robot at ``poses``.

        Args:
            poses: ``(R, 3)`` ``[x, y, θ]`` (m, rad) of the global rows.
            previous: ``(R, 3)`` the poses before the move, or ``None``: walls are also tested
                along the way from them (tunnelling sweep); obstacles, pedestrians and robots
                only at ``poses``.
            ag_off: ``(W + 1,)`` int64 (``W`` at least the worlds bound), world ``w``'s
                pedestrians are rows ``ag_off[w]:ag_off[w+1]`` of ``ag_pos`` and ``ag_r``.
            ag_pos: ``(A, 2)`` m, the pedestrians' positions.
            ag_r: ``(A,)`` m, their radii.
            rows: ``(R,)`` bool, the rows to test (the others get ``False``/``-1``); ``None``:
                all.
            parallel: spread the rows over numba's threads (the same flags).

        Returns:
            ``(wall, obstacle, agent, robot)``, each ``(R,)``, indices local to the world.
        """
        n = self._row_world.shape[0]
        p = np.ascontiguousarray(poses, dtype=np.float64)
        if p.shape != (n, 3):
            raise SimulationError(f"poses must have shape ({n}, 3), got {p.shape}")
        prev = p if previous is None else np.ascontiguousarray(previous, dtype=np.float64)
        if prev.shape != (n, 3):
            raise SimulationError(f"previous poses must have shape ({n}, 3), got {prev.shape}")
        off = np.ascontiguousarray(ag_off, dtype=np.int64)
        if off.ndim != 1 or off.shape[0] < self.num_worlds + 1:  # unbound worlds may follow
            raise SimulationError(
                f"ag_off must have shape (W + 1,) for W >= {self.num_worlds} worlds, "
                f"got {off.shape}"
            )
        pos = np.ascontiguousarray(ag_pos, dtype=np.float64).reshape(-1, 2)
        rad = np.ascontiguousarray(ag_r, dtype=np.float64).reshape(-1)
        if pos.shape[0] != rad.shape[0] or (n and off[-1] > pos.shape[0]):
            raise SimulationError(
                f"ag_pos {pos.shape} and ag_r {rad.shape} must hold the ag_off[-1] = "
                f"{int(off[-1])} pedestrians"
            )
        do = self._all_rows if rows is None else np.ascontiguousarray(rows, dtype=np.bool_)
        if do.shape != (n,):
            raise SimulationError(f"rows must have shape ({n},), got {do.shape}")
        return self.test_unchecked(p, prev, previous is not None, off, pos, rad, do, parallel)

    def test_unchecked(
        self,
        poses: NDArray[np.float64],
        previous: NDArray[np.float64],
        sweep: bool,
        ag_off: NDArray[np.int64],
        ag_pos: NDArray[np.float64],
        ag_r: NDArray[np.float64],
        rows: NDArray[np.bool_] | None,
        parallel: bool,
    ) -> ContactFlags:
        """:meth:`test` on arguments already in the kernel's form, without checking them.

        For a caller that guarantees them every step (the engine): C-contiguous ``(R, 3)``
        float64 ``poses`` and ``previous`` (``poses`` itself when not ``sweep``), int64
        ``ag_off`` of at least ``W + 1`` entries, ``(A, 2)`` and ``(A,)`` float64 pedestrians,
        ``rows`` ``(R,)`` bool or ``None`` (all). Anything else is undefined: use :meth:`test`.
        """
        n = self._row_world.shape[0]
        do = self._all_rows if rows is None else rows
        wall = np.empty(n, dtype=np.bool_)  # the kernel writes every row
        obstacle = np.empty(n, dtype=np.int64)
        agent = np.empty(n, dtype=np.int64)
        robot = np.empty(n, dtype=np.int64)
        o_off, o_c, o_r, o_vs, o_v = self._packed_obstacles()
        fp_r, fp_reach, fp_vs, fp_v = self._fp
        contacts_rows(parallel)(
            do, poses, previous, sweep, self._row_world, self._robot_off,
            self._g_off, self._g_shape, self._g_par, self._occ, self._dist,
            o_off, o_c, o_r, o_vs, o_v, fp_r, fp_reach, fp_vs, fp_v, ag_off, ag_pos, ag_r,
            wall, obstacle, agent, robot,
        )  # fmt: skip
        return wall, obstacle, agent, robot
