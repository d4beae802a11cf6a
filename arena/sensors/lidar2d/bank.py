"""Every lidar of every world, scanned in one kernel call: :class:`LidarBank`.

A simulation core stepping ``W`` worlds keeps one bank. Per world it binds the static geometry
(:meth:`LidarBank.bind_world`: the grid and the obstacle edges), per robot set-up it lists the
sensor rows (:meth:`LidarBank.set_sensors`: which global robot row carries which
:class:`~arena.sensors.spec.LidarSpec`), and per step it casts the due rows against each world's
static geometry plus its :class:`DynamicGeometry` (pedestrians, robot bodies). Each row runs the
same per-sensor function as :meth:`Lidar2D.scan_many <arena.sensors.lidar2d.Lidar2D.scan_many>`
(:func:`~arena.sensors.lidar2d.kernels._scan_one`), so a row's ranges are bit-identical to a
:class:`~arena.sensors.lidar2d.Lidar2D` scan of the same scene; see :mod:`.model` for what a
beam hits. The bank draws no noise: :meth:`LidarBank.read` applies a row's noise from the
caller's generator.

Static tables are packed in flat buffers (layout: :mod:`.bank_kernels`). A grid is converted
once per grid object and shared by every world showing it; a grid no world shows any more keeps
its slot (a world returning to it costs nothing) until the buffers run out of room, when such
slots are dropped and the live ones compacted.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import SimulationError
from arena.maps.grid import OccupancyGrid
from arena.sensors.base import SENSORS
from arena.sensors.lidar2d.bank_kernels import (
    BAD_POSE,
    BAD_SCENE,
    scan_rows,
    scan_rows_parallel,
)
from arena.sensors.lidar2d.kernels import SCRATCH_F, SCRATCH_I, _add_noise
from arena.sensors.lidar2d.model import (
    _points,
    beam_tables,
    cell_distances,
    polygon_sides,
    use_wall_faces,
    wall_faces,
)
from arena.sensors.spec import LidarSpec

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


class DynamicGeometry(Protocol):
    """What the lidars of ``W`` worlds see besides the static world, per world by offsets.

    World ``w`` owns circles ``circ_off[w]:circ_off[w + 1]`` and segments
    ``seg_off[w]:seg_off[w + 1]``. An owner is the global robot row the shape belongs to (a
    robot's own body is invisible to its sensors) or ``-1`` (nobody, e.g. a pedestrian).
    Arrays are float64 / int64; C-contiguous writeable ones take the compiled fast path
    (others compile another specialisation of the kernels on first use).
    """

    @property
    def circ_off(self) -> I64:
        """``(W + 1,)`` circle offsets per world."""

    @property
    def circ_xy(self) -> F64:
        """``(C, 2)`` circle centres (m)."""

    @property
    def circ_r(self) -> F64:
        """``(C,)`` circle radii (m)."""

    @property
    def circ_owner(self) -> I64:
        """``(C,)`` owning global robot row, or -1."""

    @property
    def seg_off(self) -> I64:
        """``(W + 1,)`` segment offsets per world."""

    @property
    def seg_a(self) -> F64:
        """``(K, 2)`` segment start points (m)."""

    @property
    def seg_b(self) -> F64:
        """``(K, 2)`` segment end points (m)."""

    @property
    def seg_owner(self) -> I64:
        """``(K,)`` owning global robot row, or -1."""


class _Blocks:
    """Variable-length blocks of rows packed into parallel growing arrays (one per column set).

    A block keeps its id for life; its offset changes when :meth:`compact` moves it.
    """

    def __init__(self, *columns: tuple[tuple[int, ...], type]) -> None:
        self.data: list[NDArray[Any]] = [np.zeros((0, *t), dtype=d) for t, d in columns]
        self.off: list[int] = []
        self.size: list[int] = []  # -1: a free id
        self._free: list[int] = []
        self._end = 0

    def room(self, n: int) -> bool:
        """Whether ``n`` more rows fit without :meth:`compact`."""
        return self._end + n <= len(self.data[0])

    def add(self, *arrays: NDArray[Any]) -> int:
        """Append one block (``arrays`` with equal lengths, one per column set); its id.

        The caller makes :meth:`room` first (compacting moves the other blocks, whose offsets
        it must then re-read).
        """
        n = len(arrays[0])
        if not self.room(n):
            raise AssertionError("_Blocks.add without room: compact first")
        for dst, src in zip(self.data, arrays, strict=True):
            dst[self._end : self._end + n] = src
        bid = self._free.pop() if self._free else len(self.off)
        if bid == len(self.off):
            self.off.append(0)
            self.size.append(0)
        self.off[bid] = self._end
        self.size[bid] = n
        self._end += n
        return bid

    def free(self, bid: int) -> None:
        """Release block ``bid`` (its rows are reclaimed by the next :meth:`compact`)."""
        self.size[bid] = -1
        self._free.append(bid)

    def compact(self, extra: int) -> None:
        """Move the live blocks to the front of arrays with room for ``extra`` more rows.

        The capacity doubles the live rows plus ``extra``, so rows are copied a bounded number
        of times on average however many blocks come and go.
        """
        live = sorted((o, b) for b, o in enumerate(self.off) if self.size[b] >= 0)
        used = sum(self.size[b] for _, b in live)
        cap = max(2 * (used + extra), 256)
        new = [np.zeros((cap, *d.shape[1:]), dtype=d.dtype) for d in self.data]
        pos = 0
        for o, b in live:
            n = self.size[b]
            for dst, src in zip(new, self.data, strict=True):
                dst[pos : pos + n] = src[o : o + n]
            self.off[b] = pos
            pos += n
        self.data = new
        self._end = pos


@dataclass(eq=False)
class _MapSlot:
    """One grid's packed distance map and faces, shared by the worlds showing it."""

    grid: OccupancyGrid
    index: int  # row of the map tables
    dist: int  # block id in LidarBank._dist
    faces: int  # block id in LidarBank._faces
    worlds: int = 0  # worlds showing it now




@SENSORS.register("lidar2d")
class LidarBank:
    """Every lidar of every world, scanned in one kernel call: the ``lidar2d`` sensor bank.

    Usage: ``bank = LidarBank()``; when world ``w`` resets, ``bank.bind_world(w, grid, a, b)``;
    after any reset ``bank.set_sensors(row_world, row_robot, specs)``; per step
    ``bank.scan(due, poses, scene)`` and read ``bank.ranges(s)``. One caller at a time: the
    work arrays are per pool thread, not per caller.
    """

    Params = LidarSpec

    def __init__(self) -> None:
        self._dist = _Blocks(((), np.float32))
        self._faces = _Blocks(((4,), np.float64))
        self._segs = _Blocks(((2,), np.float64), ((2,), np.float64), ((), np.float64))
        self._slots: dict[int, _MapSlot] = {}  # by id(grid); the slot holds the grid
        self._free_index: list[int] = []
        self._map_i = np.zeros((0, 5), dtype=np.int64)
        self._map_f = np.zeros((0, 3))
        self._use_faces = np.zeros((0, 0), dtype=bool)
        self._world_slot: list[_MapSlot | None] = []
        self._world_seg: list[int] = []  # block id in _segs per world, -1 none
        self._world_i = np.zeros((0, 3), dtype=np.int64)
        # sensor rows
        self._row_world = np.zeros(0, dtype=np.int64)
        self._row_robot = np.zeros(0, dtype=np.int64)
        self._row_spec = np.zeros(0, dtype=np.int64)
        self._row_specs: tuple[LidarSpec, ...] = ()
        self._max_robot = -1
        self._max_world = -1
        self._bound = True  # every row's world has been bound (checked at the next scan)
        # the kernel's static arguments, gathered once after each bind_world/set_sensors
        self._static: tuple[tuple[Any, ...], tuple[Any, ...]] | None = None
        self._specs: list[LidarSpec] = []  # distinct specs, in order of first use
        self._beam_off = np.zeros(1, dtype=np.int64)
        self._cos = np.zeros(0)
        self._sin = np.zeros(0)
        self._spec_f = np.zeros((0, 7))
        self._out_off = np.zeros(1, dtype=np.int64)
        self._out = np.zeros(0)
        # the pool's size, fixed at start-up: get_thread_id() < it
        threads = int(numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]
        self._scratch_f = np.zeros((threads, SCRATCH_F, 0))
        self._scratch_i = np.zeros((threads, SCRATCH_I, 0), dtype=np.int64)

    # -- static worlds ------------------------------------------------------------------------
    def bind_world(
        self, w: int, grid: OccupancyGrid, segments_a: ArrayLike | None = None,
        segments_b: ArrayLike | None = None,
    ) -> None:
        """Static geometry of world ``w``; call when world ``w`` resets.

        Args:
            w: world index (``>= 0``); the bank grows to hold it.
            grid: the occupancy grid; converted once per grid object (:func:`cell_distances`,
                :func:`wall_faces`) and shared by every world showing it.
            segments_a: ``(s, 2)`` start points of static obstacle edges (m), or ``None``.
            segments_b: ``(s, 2)`` end points (m), or ``None``.
        """
        if w < 0:
            raise SimulationError(f"world index must be >= 0, got {w}")
        self._static = None
        a = _points(segments_a, "segments_a")
        b = _points(segments_b, "segments_b")
        if a.shape != b.shape:
            raise ValueError(f"segments_a {a.shape} and segments_b {b.shape} differ in shape")
        if w >= len(self._world_slot):
            grow = w + 1 - len(self._world_slot)
            self._world_slot += [None] * grow
            self._world_seg += [-1] * grow
            self._world_i = np.concatenate([self._world_i, np.zeros((grow, 3), dtype=np.int64)])
        slot = self._slots.get(id(grid))
        if slot is None or slot.grid is not grid:
            slot = self._add_map(grid)
        slot.worlds += 1  # before the old slot is released: rebinding the same grid keeps it
        old = self._world_slot[w]
        if old is not None:
            old.worlds -= 1
        self._world_slot[w] = slot
        if self._world_seg[w] >= 0:
            self._segs.free(self._world_seg[w])
            self._world_seg[w] = -1
        if len(a):
            if not self._segs.room(len(a)):
                self._segs.compact(len(a))
                self._refresh_segments()
            self._world_seg[w] = self._segs.add(a, b, polygon_sides(a, b))
        self._world_i[w] = (slot.index, *self._segment_span(w))

    def _segment_span(self, w: int) -> tuple[int, int]:
        bid = self._world_seg[w]
        return (self._segs.off[bid], self._segs.size[bid]) if bid >= 0 else (0, 0)

    def _refresh_segments(self) -> None:
        for w in range(len(self._world_seg)):
            self._world_i[w, 1:] = self._segment_span(w)

    def _add_map(self, grid: OccupancyGrid) -> _MapSlot:
        """Pack ``grid`` into a new map slot (dropping unused slots first if out of room)."""
        dist = cell_distances(grid).reshape(-1)
        faces = wall_faces(grid)
        if not (self._dist.room(len(dist)) and self._faces.room(len(faces))):
            for key, slot in list(self._slots.items()):
                if slot.worlds == 0:
                    self._dist.free(slot.dist)
                    self._faces.free(slot.faces)
                    self._free_index.append(slot.index)
                    del self._slots[key]
            self._dist.compact(len(dist))
            self._faces.compact(len(faces))
            for slot in self._slots.values():
                self._map_i[slot.index, 0] = self._dist.off[slot.dist]
                self._map_i[slot.index, 3] = self._faces.off[slot.faces]
        if self._free_index:
            index = self._free_index.pop()
        else:
            index = len(self._map_i)
            self._map_i = np.concatenate([self._map_i, np.zeros((1, 5), dtype=np.int64)])
            self._map_f = np.concatenate([self._map_f, np.zeros((1, 3))])
            grown = np.zeros((index + 1, self._use_faces.shape[1]), dtype=bool)
            grown[:index] = self._use_faces
            self._use_faces = grown
        slot = _MapSlot(grid, index, self._dist.add(dist), self._faces.add(faces))
        self._map_i[index] = (
            self._dist.off[slot.dist], grid.height, grid.width, self._faces.off[slot.faces],
            len(faces),
        )
        self._map_f[index] = (grid.resolution, grid.origin[0], grid.origin[1])
        for k, spec in enumerate(self._specs):
            self._use_faces[index, k] = use_wall_faces(faces, spec.num_beams)
        self._slots[id(grid)] = slot
        return slot

    # -- sensor rows --------------------------------------------------------------------------
    def set_sensors(
        self, row_world: ArrayLike, row_robot: ArrayLike, specs: Sequence[LidarSpec]
    ) -> None:
        """The sensor rows; call after any world reset.

        Row ``s`` is carried by global robot row ``row_robot[s]`` of world ``row_world[s]`` and
        has spec ``specs[s]``. A row keeps its last ranges when its world had a row at the same
        position among its rows with an equal spec (the worlds that did not reset keep their
        held scans); other rows read ``range_max`` until scanned.
        """
        self._static = None
        worlds = np.array(row_world, dtype=np.int64).reshape(-1)
        robots = np.array(row_robot, dtype=np.int64).reshape(-1)
        specs = tuple(specs)
        if not (len(worlds) == len(robots) == len(specs)):
            raise SimulationError(
                f"row_world ({len(worlds)}), row_robot ({len(robots)}) and specs "
                f"({len(specs)}) must have the same length"
            )
        if (
            np.array_equal(worlds, self._row_world)
            and np.array_equal(robots, self._row_robot)
            and len(specs) == len(self._row_specs)
            and all(a is b or a == b for a, b in zip(specs, self._row_specs, strict=True))
        ):
            self._row_specs = specs  # equal specs: the next call matches by identity
            return  # the usual call after a reset: nothing changed
        if len(robots) and (robots.min() < 0 or worlds.min() < 0):
            raise SimulationError("row_world and row_robot must be >= 0")
        for k, spec in enumerate(specs):
            if not isinstance(spec, LidarSpec):
                raise SimulationError(f"specs[{k}] must be a LidarSpec, got {type(spec).__name__}")
        distinct = list(dict.fromkeys(specs))
        if distinct != self._specs:
            self._set_specs(distinct)
        index = {spec: k for k, spec in enumerate(self._specs)}
        row_spec = np.array([index[s] for s in specs], dtype=np.int64)
        beams = np.array([s.num_beams for s in specs], dtype=np.int64)
        out_off = np.zeros(len(specs) + 1, dtype=np.int64)
        np.cumsum(beams, out=out_off[1:])
        out = np.empty(int(out_off[-1]))
        # Carry over the held ranges of rows that stay what they were.
        old: dict[tuple[int, int], int] = {}
        seen: dict[int, int] = {}
        for s, w in enumerate(self._row_world.tolist()):
            seen[w] = seen.get(w, -1) + 1
            old[(w, seen[w])] = s
        seen.clear()
        for s, w in enumerate(worlds.tolist()):
            seen[w] = seen.get(w, -1) + 1
            prev = old.get((w, seen[w]))
            dst = out[out_off[s] : out_off[s + 1]]
            if prev is not None and self._row_specs[prev] == specs[s]:
                dst[:] = self._out[self._out_off[prev] : self._out_off[prev + 1]]
            else:
                dst[:] = specs[s].range_max
        self._row_world, self._row_robot, self._row_spec = worlds, robots, row_spec
        self._max_robot = int(robots.max()) if len(robots) else -1
        self._max_world = int(worlds.max()) if len(worlds) else -1
        self._bound = False
        self._row_specs = specs
        self._out_off, self._out = out_off, out
        most = int(beams.max()) if len(beams) else 0
        if self._scratch_f.shape[2] < most:
            t = self._scratch_f.shape[0]
            self._scratch_f = np.zeros((t, SCRATCH_F, most))
            self._scratch_i = np.zeros((t, SCRATCH_I, most), dtype=np.int64)

    def _set_specs(self, specs: list[LidarSpec]) -> None:
        """Beam tables of the distinct ``specs`` in use and their faces-or-walk choice per map.

        Rebuilt from the specs in use only, so that specs drawn afresh per episode (domain
        randomisation) do not pile up.
        """
        tables = [beam_tables(spec) for spec in specs]
        self._specs = specs
        self._cos = np.concatenate([np.zeros(0), *(t[0] for t in tables)])
        self._sin = np.concatenate([np.zeros(0), *(t[1] for t in tables)])
        self._spec_f = np.array(
            [[*spec.mount, spec.angle_min, t[2], spec.range_min, spec.range_max]
             for spec, t in zip(specs, tables, strict=True)],
            dtype=np.float64,
        ).reshape(len(specs), 7)
        self._beam_off = np.zeros(len(specs) + 1, dtype=np.int64)
        np.cumsum([s.num_beams for s in specs], out=self._beam_off[1:])
        self._use_faces = np.zeros((len(self._map_i), len(specs)), dtype=bool)
        for slot in self._slots.values():
            faces = wall_faces(slot.grid)
            for k, spec in enumerate(specs):
                self._use_faces[slot.index, k] = use_wall_faces(faces, spec.num_beams)

    # -- scanning ------------------------------------------------------------------------------
    @property
    def num_rows(self) -> int:
        """Number of sensor rows."""
        return len(self._row_specs)

    def spec(self, s: int) -> LidarSpec:
        """The spec of row ``s``."""
        return self._row_specs[s]

    def ranges(self, s: int) -> F64:
        """Row ``s``'s latest ranges, ``(num_beams,)`` m: a view into the bank's output.

        The view is overwritten by later scans of the row and detached by :meth:`set_sensors`
        when the row layout changes: copy it to keep it.
        """
        return self._out[self._out_off[s] : self._out_off[s + 1]]

    def scan(
        self, due: ArrayLike, poses: ArrayLike, scene: DynamicGeometry, *,
        parallel: bool = False, chunksize: int = 1,
    ) -> None:
        """Cast the ``due`` rows; the other rows keep their ranges.

        Row ``s`` sees its world's grid, static segments and the scene's circles and segments
        of its world, except those owned by its robot.

        Args:
            due: ``(S,)`` bool, the rows to cast.
            poses: ``(R, 3)`` global robot rows ``[x m, y m, yaw rad]``.
            scene: the dynamic geometry of every world (:class:`DynamicGeometry`).
            parallel: cast the rows on numba's thread pool (dynamic schedule).
            chunksize: rows a thread takes at a time when ``parallel`` (``0``: numba's static
                split). Which thread casts a row never changes its ranges.
        """
        flags = np.asarray(due, dtype=bool)
        if flags.shape != (len(self._row_specs),):
            raise SimulationError(f"due must have shape ({self.num_rows},), got {flags.shape}")
        rows = flags.nonzero()[0]  # (np.flatnonzero costs five times as much per step)
        if rows.shape[0] == 0:
            return
        q = np.asarray(poses, dtype=np.float64)
        if q.ndim != 2 or q.shape[1] != 3 or q.shape[0] <= self._max_robot:
            raise SimulationError(
                f"poses must have shape (R, 3) with a row for every robot, got {q.shape}"
            )
        if not self._bound:
            for w in np.unique(self._row_world).tolist():
                if w >= len(self._world_slot) or self._world_slot[w] is None:
                    raise SimulationError(f"LidarBank.bind_world({w}, ...) was never called")
            self._bound = True  # worlds are never unbound
        circ_off, seg_off = scene.circ_off, scene.seg_off
        need = self._max_world + 1
        if circ_off.ndim != 1 or circ_off.shape[0] <= need:
            raise SimulationError("scene.circ_off must have a row per world plus one")
        if seg_off.ndim != 1 or seg_off.shape[0] <= need:
            raise SimulationError("scene.seg_off must have a row per world plus one")
        static = self._static
        if static is None:
            static = self._static = self._static_args()
        head, tail = static
        args = (
            rows, q, *head,
            circ_off, scene.circ_xy, scene.circ_r, scene.circ_owner,
            seg_off, scene.seg_a, scene.seg_b, scene.seg_owner,
            *tail,
        )
        if parallel:
            previous = numba.set_parallel_chunksize(chunksize)
            try:
                code = scan_rows_parallel(*args)
            finally:
                numba.set_parallel_chunksize(previous)
        else:
            code = scan_rows(*args)
        if code == BAD_SCENE:
            raise SimulationError(
                "scene offsets must rise within the scene's circle and segment arrays"
            )
        if code == BAD_POSE:
            raise SimulationError("LidarBank: the poses of the scanning robots must be finite")

    def _static_args(self) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
        """The kernel's arguments before and after the scene's.

        Valid until the next :meth:`bind_world` or :meth:`set_sensors`, which may replace any.
        """
        head = (
            self._row_robot, self._row_world, self._row_spec, self._out_off,
            self._beam_off, self._cos, self._sin, self._spec_f,
            self._map_i, self._map_f, self._dist.data[0], self._faces.data[0], self._use_faces,
            self._world_i, self._segs.data[0], self._segs.data[1], self._segs.data[2],
        )
        return head, (self._scratch_f, self._scratch_i, self._out)

    def read(self, s: int, rng: np.random.Generator | None) -> F64:
        """Row ``s``'s latest ranges with their noise drawn from ``rng``: a new array.

        The :class:`~arena.sensors.base.SensorBank` reading: the bank's own ranges stay as
        scanned; the noise is :meth:`add_noise`'s (none when ``rng`` is ``None``).
        """
        out = self.ranges(s).copy()  # the bank overwrites its own with the next scan
        if rng is not None and self._row_specs[s].noise_std > 0.0:  # the usual: no call
            self._noise(s, out, rng)
        return out

    def add_noise(self, s: int, rng: np.random.Generator) -> None:
        """Add row ``s``'s range noise, drawn from ``rng``, to its latest ranges.

        One ``(1, num_beams)`` standard normal draw when the spec has noise (as
        :meth:`Lidar2D.scan <arena.sensors.lidar2d.Lidar2D.scan>` draws per scan), nothing
        otherwise; max-range returns stay, the rest is clipped to the range limits.
        """
        self._noise(s, self.ranges(s), rng)

    def _noise(self, s: int, ranges: F64, rng: np.random.Generator) -> None:
        """Row ``s``'s noise added to ``ranges`` ``(num_beams,)`` in place."""
        spec = self._row_specs[s]
        if spec.noise_std > 0.0:
            row = ranges[None]
            _add_noise(row, rng.standard_normal(row.shape), spec.noise_std, spec.range_min,
                       spec.range_max)
