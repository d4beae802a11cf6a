"""``BatchSim``: ``N`` independent single-robot worlds stepped together in array operations.

Built for RL training, where many short episodes run side by side: one call steps every world,
and the heavy parts (lidar, crowd, contacts) are numba kernels running ``prange`` over worlds;
:meth:`BatchSim.step` runs them fused per world in one kernel
(:func:`~arena.sim.batch.kernels.step_worlds`: one thread-pool launch per step), with dynamic
scheduling so that a thread slowed by other load on a shared machine does not hold up the rest.
World ``i`` only ever reads its own slices, so its trajectory does not depend on ``N``, on the
other worlds or on the thread count, and :meth:`BatchSim.reset_world` restarts one finished
world without touching the others (auto-reset).

How it relates to :class:`~arena.sim.native2d.Native2DBackend` (the reference simulator):

* **Kinematics** are Arena's own models (vectorised over a leading axis already), called once
  per robot model over all worlds carrying it: identical poses and twists.
* **Lidar** runs Arena's single-robot scan kernel per world (:mod:`arena.sensors.lidar2d`) and
  holds each scan until the sensor period elapsed, as native2d: identical scans for the same
  scene. Pedestrians are seen as solid circles (native2d's default ``pedestrian_body``).
* **Contacts** use a *circle* footprint (the robot's circumscribed radius by default), tested
  against blocking cells (exactly as native2d tests a circular robot, with the same sweep
  against tunnelling), obstacle polygons and pedestrians. For polygon robots (jackal) this is
  conservative: a contact may be reported up to ``radius − half width`` earlier than native2d.
  ``collision_response`` ``"stop"`` undoes a colliding move as native2d does.
* **Pedestrians** are either ``"static"`` (standing at their spawn, native2d with
  ``pedestrians=None``) or a batched Helbing-style social force
  (:func:`~arena.sim.batch.kernels.crowd_worlds`): goal attraction along the episode's
  waypoints (loop or random mode), exponential repulsion from the other pedestrians of the
  world, the robot, walls (distance-map gradient) and obstacle edges. Unlike the full
  :class:`~arena.crowd.simulator.CrowdSimulator` there is no social-state machine (everyone is
  always walking, ``states == 0``), no groups, no startup modes (everyone walks from t = 0),
  no per-kind speed profiles and no leg model.
* Only one robot per world, and every world's robot must carry the same lidar spec (one
  kernel configuration).

Randomness: ``reset(episodes, rng)`` gives world ``i`` the ``i``-th child of ``rng.spawn(N)``;
each world splits its generator into crowd and sensor-noise streams like native2d. Random
waypoint choices come from a per-world table of uniforms drawn from the crowd stream.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numba
import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import SimulationError
from arena.maps.grid import OccupancyGrid
from arena.robots.kinematics.base import Kinematics, KinematicState
from arena.robots.model import RobotModel
from arena.scene.episode import Episode
from arena.sensors.lidar2d import _add_noise, use_wall_faces, wall_faces
from arena.sensors.spec import LidarSpec
from arena.sim.backend import split_rng
from arena.sim.batch import kernels as K

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

_RAND_TABLE = 256  # uniforms per world for random waypoint choices, refilled when used up


class BatchCrowdParams(BaseModel):
    """Parameters of the batched social-force crowd (accelerations in m/s²)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    relaxation_time: float = Field(0.5, gt=0, description="s, τ of the goal attraction")
    goal_radius: float = Field(0.3, gt=0, description="m, a waypoint counts as reached within")
    ped_factor: float = Field(2.1, ge=0, description="m/s², A of pedestrian repulsion")
    ped_range: float = Field(0.3, gt=0, description="m, B (decay length) of pedestrian repulsion")
    wall_factor: float = Field(
        10.0, ge=0, description="m/s², A of wall and obstacle repulsion (pysocial obstacle_factor)"
    )
    wall_range: float = Field(
        0.2, gt=0, description="m, B of wall repulsion (pysocial obstacle_sigma)"
    )
    robot_factor: float = Field(3.0, ge=0, description="m/s², A of robot repulsion")
    robot_range: float = Field(0.5, gt=0, description="m, B of robot repulsion")
    cutoff: float = Field(3.0, gt=0, description="m, interactions farther than this are ignored")
    max_speed_factor: float = Field(1.3, gt=0, description="speed cap as a multiple of vmax")

    def as_array(self) -> F64:
        """The vector the kernel reads (order of the ``P_*`` indices in ``kernels``)."""
        return np.array([
            self.relaxation_time, self.goal_radius, self.ped_factor, self.ped_range,
            self.wall_factor, self.wall_range, self.robot_factor, self.robot_range,
            self.cutoff, self.max_speed_factor,
        ])


@dataclass(frozen=True, eq=False)
class BatchState:
    """Snapshot of all ``N`` worlds (copies; the simulator never mutates them afterwards).

    Attributes:
        time: ``(N,)`` simulated time of each world since its reset (s).
        step: ``(N,)`` steps since each world's reset.
        poses: ``(N, 3)`` robot poses ``[x, y, theta]``.
        twists: ``(N, 3)`` executed body twists ``[vx, vy, omega]``.
        commands: ``(N, 3)`` commands of the last step.
        scans: ``(N, B)`` lidar ranges (m), the latest scan of each world.
        collided: ``(N,)`` bool, the robot touches something.
        collision_kind: ``(N,)`` int, ``KIND_NONE/WALL/OBSTACLE/PEDESTRIAN`` (first that applies).
        wall: ``(N,)`` bool, footprint on a blocking cell or off the map.
        obstacle: ``(N,)`` index of a touched obstacle, or -1.
        agent: ``(N,)`` index of the nearest touched pedestrian, or -1.
        ped_positions: ``(N, P, 2)`` (m), padded; valid where ``ped_mask``.
        ped_velocities: ``(N, P, 2)`` (m/s).
        ped_headings: ``(N, P)`` (rad).
        ped_radii: ``(N, P)`` (m).
        ped_mask: ``(N, P)`` bool, the slot holds a pedestrian.
        ped_kinds: ``(N, P)`` int type codes (padding -1).
        ped_states: ``(N, P)`` int social-state codes (always 0 here; padding -1).
    """

    time: F64
    step: I64
    poses: F64
    twists: F64
    commands: F64
    scans: F64
    collided: NDArray[np.bool_]
    collision_kind: I64
    wall: NDArray[np.bool_]
    obstacle: I64
    agent: I64
    ped_positions: F64
    ped_velocities: F64
    ped_headings: F64
    ped_radii: F64
    ped_mask: NDArray[np.bool_]
    ped_kinds: I64
    ped_states: I64


class BatchSim:
    """``N`` single-robot worlds stepped together; see the module docstring.

    Args:
        num_worlds: ``N``.
        params: simulator parameters.

    Usage: ``sim.reset(episodes, rng)`` then ``sim.step(commands (N, 3), dt)`` repeatedly;
    ``sim.reset_world(i, episode)`` restarts one world.
    """

    class Params(BaseModel):
        """Parameters of :class:`BatchSim`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        collision_response: Literal["stop", "record"] = Field(
            "stop", description="'stop': a colliding move is undone; 'record': only reported"
        )
        lidar: bool = Field(True, description="simulate the lidar")
        pedestrians: Literal["social_force", "static"] = Field(
            "social_force", description="batched social force, or standing at their spawn"
        )
        crowd: BatchCrowdParams = Field(default_factory=BatchCrowdParams)
        parallel_min_worlds: int = Field(
            2, ge=1, description="kernels use numba's thread pool from this many worlds on"
        )
        robot_radius: float | None = Field(
            None, gt=0, description="m, contact circle; None: the robot's circumscribed radius"
        )
        parallel_chunksize: int = Field(
            1, ge=0, description=(
                "worlds a thread takes at a time in the fused step kernel (dynamic "
                "scheduling: a thread slowed by other load takes fewer); 0: numba's static split"
            ),
        )

    # padded pedestrian arrays, (N, P, ...), allocated by _alloc_peds
    _pos: F64
    _vel: F64
    _heading: F64
    _pradii: F64
    _vmax: F64
    _kinds: I64
    _ped_n: I64
    _wps: F64
    _n_wp: I64
    _wp_mode: I64
    _wp_idx: I64

    def __init__(self, num_worlds: int, params: Params | None = None) -> None:
        if num_worlds < 1:
            raise SimulationError(f"num_worlds must be >= 1, got {num_worlds}")
        self.params = params or self.Params()
        self.num_worlds = n = num_worlds
        self._crowd_prm = self.params.crowd.as_array()
        self._spec: LidarSpec | None = None
        self._episodes: list[Episode | None] = [None] * n
        self._kin: list[Kinematics | None] = [None] * n
        self._models: list[RobotModel | None] = [None] * n  # whose kinematics _kin[i] holds
        self._crowd_rng: list[np.random.Generator | None] = [None] * n
        self._sensor_rng: list[np.random.Generator | None] = [None] * n
        self._world_rng: list[np.random.Generator | None] = [None] * n
        # robots
        self._poses = np.zeros((n, 3))
        self._twists = np.zeros((n, 3))
        self._steer = np.zeros(n)
        self._commands = np.zeros((n, 3))
        self._radius = np.zeros(n)
        self._time = np.zeros(n)
        self._step = np.zeros(n, dtype=np.int64)
        self._last_scan = np.full(n, -math.inf)
        self._scans = np.zeros((n, 1))
        self._scratch_f = np.zeros((n, 6, 0))  # per-world lidar work arrays (_set_spec sizes)
        self._scratch_i = np.zeros((n, 2, 0), dtype=np.int64)
        self._wall = np.zeros(n, dtype=bool)
        self._obstacle = np.full(n, -1, dtype=np.int64)
        self._agent = np.full(n, -1, dtype=np.int64)
        # maps: per-world slots of ``_cap_cells`` in one flat buffer
        self._cap_cells = 0
        # Worlds showing the same grid object share one slot (fewer cache misses in the kernels).
        self._slot_of = [-1] * n
        self._slot_grid: list[OccupancyGrid | None] = [None] * n
        self._slot_refs = [0] * n
        self._dist = np.zeros(0, dtype=np.float32)
        self._offs = np.zeros(n, dtype=np.int64)
        self._shapes = np.ones((n, 2), dtype=np.int64)
        self._res = np.ones(n)
        self._origin = np.zeros((n, 2))
        # wall faces (Lidar2D's "Wall faces"): (N, F, 4) padded, ``face_n[i] = -1``: walk the grid
        self._faces = np.zeros((n, 0, 4))
        self._face_n = np.full(n, -1, dtype=np.int64)
        # obstacle edges
        self._seg_a = np.zeros((n, 0, 2))
        self._seg_b = np.zeros((n, 0, 2))
        self._seg_owner = np.zeros((n, 0), dtype=np.int64)
        self._seg_n = np.zeros(n, dtype=np.int64)
        # pedestrians
        self._alloc_peds(0, 1)
        self._rand = np.zeros((n, _RAND_TABLE))
        self._rand_k = np.zeros(n, dtype=np.int64)
        # (ped_mask, ped_states) of the snapshots, read-only; None: rebuild (after a load)
        self._ped_view: tuple[NDArray[np.bool_], I64] | None = None
        self._all = np.ones(n, dtype=bool)  # the crowd kernels' "active" flags

    # -- public API ------------------------------------------------------------------------------
    @property
    def lidar_spec(self) -> LidarSpec:
        """The lidar spec shared by every world's robot."""
        if self._spec is None:
            raise SimulationError("BatchSim has not been reset yet")
        return self._spec

    def reset(
        self,
        episodes: Sequence[Episode],
        rng: np.random.Generator | Sequence[np.random.Generator],
    ) -> BatchState:
        """Start ``N`` episodes; world ``i`` gets ``episodes[i]`` and ``rng.spawn(N)[i]``.

        ``rng`` may also be a sequence of ``N`` generators, one per world (then a world's
        stream does not depend on ``N``).
        """
        if len(episodes) != self.num_worlds:
            raise SimulationError(f"need {self.num_worlds} episodes, got {len(episodes)}")
        if isinstance(rng, np.random.Generator):
            rngs: Sequence[np.random.Generator] = rng.spawn(self.num_worlds)
        else:
            rngs = rng
            if len(rngs) != self.num_worlds:
                raise SimulationError(f"need {self.num_worlds} generators, got {len(rngs)}")
        self._spec = None
        self._ensure_capacity(episodes)
        for i, (ep, child) in enumerate(zip(episodes, rngs, strict=True)):
            self._load(i, ep, child)
        self._scan(np.ones(self.num_worlds, dtype=bool))
        self._contacts(sweep=False)
        return self._snapshot()

    def reset_world(
        self, i: int, episode: Episode, rng: np.random.Generator | None = None
    ) -> BatchState:
        """Restart world ``i`` with ``episode``; the other worlds are untouched.

        Args:
            i: world index.
            episode: the new episode (its robot must carry the same lidar spec).
            rng: the world's new generator; ``None`` spawns one from its previous generator.
        """
        if not 0 <= i < self.num_worlds:
            raise SimulationError(f"no world {i}: worlds are 0..{self.num_worlds - 1}")
        prev = self._world_rng[i]
        if rng is None:
            if prev is None:
                raise SimulationError("reset_world() before reset() needs an rng")
            rng = prev.spawn(1)[0]
        self._ensure_capacity([episode])
        self._load(i, episode, rng)
        only = np.zeros(self.num_worlds, dtype=bool)
        only[i] = True
        self._scan(only)
        self._contacts(sweep=False, only=i)
        return self._snapshot()

    def reset_worlds(
        self,
        indices: Sequence[int] | I64,
        episodes: Sequence[Episode],
        rngs: Sequence[np.random.Generator],
    ) -> BatchState:
        """Restart several worlds at once (one scan and one snapshot for all of them).

        World ``indices[j]`` gets ``episodes[j]`` and ``rngs[j]``; the others are untouched.
        """
        idx = [int(i) for i in indices]
        if not (len(idx) == len(episodes) == len(rngs)):
            raise SimulationError("indices, episodes and rngs must have the same length")
        if self._spec is None:
            raise SimulationError("reset_worlds() called before reset()")
        if not idx:
            return self._snapshot()
        for i in idx:
            if not 0 <= i < self.num_worlds:
                raise SimulationError(f"no world {i}: worlds are 0..{self.num_worlds - 1}")
        self._ensure_capacity(episodes)
        for i, ep, rng in zip(idx, episodes, rngs, strict=True):
            self._load(i, ep, rng)
        only = np.zeros(self.num_worlds, dtype=bool)
        only[idx] = True
        self._scan(only)
        self._contacts(sweep=False, mask=only)
        return self._snapshot()

    def step(self, commands: F64, dt: float) -> BatchState:
        """Advance every world by ``dt`` s with ``(N, 3)`` body-twist commands."""
        if self._spec is None:
            raise SimulationError("step() called before reset()")
        n = self.num_worlds
        cmd = np.asarray(commands, dtype=np.float64)
        if cmd.shape != (n, 3):
            raise SimulationError(f"commands must have shape ({n}, 3), got {cmd.shape}")
        if not np.isfinite(cmd).all():
            raise SimulationError("commands must be finite")
        if not dt > 0:
            raise SimulationError(f"dt must be > 0 s, got {dt}")
        # The stages of _crowd, _kinematics, _contacts, the collision response and _scan, in
        # that order, but with everything after the (vectorised) kinematics fused per world in
        # one kernel: one thread-pool launch per step instead of three. The kinematics do not
        # read the pedestrians, so running them first changes nothing.
        spec = self.lidar_spec
        new_p, new_t, new_s = self._kinematics(cmd, dt)
        old = self._poses
        crowd = self.params.pedestrians != "static" and self._pos.shape[1] > 0
        if crowd:
            out_pos = np.empty_like(self._pos)
            out_vel = np.empty_like(self._vel)
        else:
            out_pos, out_vel = self._pos, self._vel
        self._time += dt
        self._step += 1
        if self.params.lidar:
            due = self._time - self._last_scan >= 1.0 / spec.update_rate - 1e-9
            self._last_scan[due] = self._time[due]
        else:
            due = np.zeros(n, dtype=bool)
        wall = np.zeros(n, dtype=bool)
        obstacle = np.full(n, -1, dtype=np.int64)
        agent = np.full(n, -1, dtype=np.int64)
        parallel = self._parallel(n)
        kernel = K.step_worlds if parallel else K.step_worlds_serial
        chunk = self.params.parallel_chunksize if parallel else 0
        # Worlds differ in cost (a scan in a corridor ends sooner than one across a hall) and a
        # shared core may stall one thread; with dynamic chunks the other thread picks up the
        # rest. Which thread steps a world never changes its result.
        previous_chunk = numba.set_parallel_chunksize(chunk)
        try:
            kernel(
                crowd, self.params.collision_response == "stop",
                self._all, self._pos, self._vel, self._heading, self._pradii, self._vmax,
                self._ped_n, self._wps, self._n_wp, self._wp_mode, self._wp_idx, self._rand,
                self._rand_k, self._dist, self._offs, self._shapes, self._res, self._origin,
                self._seg_a, self._seg_b, self._seg_owner, self._seg_n, self._radius,
                self._crowd_prm, float(dt), out_pos, out_vel,
                old, new_p, new_t, new_s, self._steer, wall, obstacle, agent,
                due, self._mount, self._cos, self._sin, spec.angle_min, self._inc,
                spec.range_min, spec.range_max, self._scans, self._scratch_f,
                self._scratch_i, self._faces, self._face_n,
            )
        finally:
            numba.set_parallel_chunksize(previous_chunk)
        if crowd:
            self._pos, self._vel = out_pos, out_vel
            self._refill_rand()
        self._poses = new_p
        self._wall, self._obstacle, self._agent = wall, obstacle, agent
        self._twists, self._steer = new_t, new_s
        self._commands = cmd.copy()
        if spec.noise_std > 0.0 and due.any():
            self._noise(due)
        return self._snapshot()

    # -- stages (called one by one by benchmarks/batch_step.py for its breakdown) ----------------
    def _crowd(self, dt: float) -> None:
        if self.params.pedestrians == "static" or self._pos.shape[1] == 0:
            return
        out_pos = np.empty_like(self._pos)
        out_vel = np.empty_like(self._vel)
        kernel = K.crowd_worlds if self._parallel(self.num_worlds) else K.crowd_worlds_serial
        kernel(
            self._all, self._pos, self._vel, self._heading,
            self._pradii, self._vmax, self._ped_n, self._wps, self._n_wp, self._wp_mode,
            self._wp_idx, self._rand, self._rand_k,
            self._dist, self._offs, self._shapes, self._res, self._origin,
            self._seg_a, self._seg_b, self._seg_n, self._poses[:, :2].copy(), self._radius,
            self._crowd_prm, float(dt), out_pos, out_vel,
        )
        self._pos, self._vel = out_pos, out_vel
        self._refill_rand()

    def _refill_rand(self) -> None:
        """Redraw the random-waypoint uniforms of the worlds that used half of them."""
        if self._rand_k.max() <= _RAND_TABLE // 2:
            return
        for i in np.flatnonzero(self._rand_k > _RAND_TABLE // 2):
            rng = self._crowd_rng[i]
            assert rng is not None
            self._rand[i] = rng.random(_RAND_TABLE)
            self._rand_k[i] = 0

    def _kinematics(self, cmd: F64, dt: float) -> tuple[F64, F64, F64]:
        if len(self._groups) == 1 and self._groups[0][1].shape[0] == self.num_worlds:
            # Every world in one group (worlds 0..N-1 in order): no gather and scatter. The
            # results are copied so the step may write them in place, whatever the model returns.
            s = self._groups[0][0].step(
                KinematicState(self._poses, self._twists, self._steer), cmd, dt
            )
            return (
                np.array(s.poses, dtype=np.float64), np.array(s.twists, dtype=np.float64),
                np.array(s.steering, dtype=np.float64),
            )
        new_p = np.empty_like(self._poses)
        new_t = np.empty_like(self._twists)
        new_s = np.empty_like(self._steer)
        for kin, idx in self._groups:
            s = kin.step(
                KinematicState(self._poses[idx], self._twists[idx], self._steer[idx]),
                cmd[idx], dt,
            )
            new_p[idx], new_t[idx], new_s[idx] = s.poses, s.twists, s.steering
        return new_p, new_t, new_s

    def _contacts(
        self, sweep: bool, previous: F64 | None = None, only: int | None = None,
        mask: NDArray[np.bool_] | None = None,
    ) -> None:
        prev = self._poses if previous is None else previous
        wall = np.zeros(self.num_worlds, dtype=bool)
        obstacle = np.full(self.num_worlds, -1, dtype=np.int64)
        agent = np.full(self.num_worlds, -1, dtype=np.int64)
        kernel = K.contacts_worlds if self._parallel(self.num_worlds) else K.contacts_worlds_serial
        kernel(
            self._poses, prev, sweep, self._radius,
            self._dist, self._offs, self._shapes, self._res, self._origin,
            self._seg_a, self._seg_b, self._seg_owner, self._seg_n,
            self._pos, self._pradii, self._ped_n, wall, obstacle, agent,
        )
        if mask is not None:
            self._wall[mask], self._obstacle[mask], self._agent[mask] = (
                wall[mask], obstacle[mask], agent[mask]
            )
        elif only is None:
            self._wall, self._obstacle, self._agent = wall, obstacle, agent
        else:
            self._wall[only], self._obstacle[only], self._agent[only] = (
                wall[only], obstacle[only], agent[only]
            )

    def _scan(self, due: NDArray[np.bool_]) -> None:
        spec = self.lidar_spec
        if not self.params.lidar or not due.any():
            return
        self._last_scan[due] = self._time[due]
        kernel = K.scan_worlds if self._parallel(int(due.sum())) else K.scan_worlds_serial
        kernel(
            due, self._poses, self._mount, self._cos, self._sin, spec.angle_min, self._inc,
            spec.range_min, spec.range_max,
            self._dist, self._offs, self._shapes, self._res, self._origin,
            self._pos, self._pradii, self._ped_n, self._seg_a, self._seg_b, self._seg_n,
            self._scans, self._scratch_f, self._scratch_i, self._faces, self._face_n,
        )
        if spec.noise_std > 0.0:
            self._noise(due)

    def _noise(self, due: NDArray[np.bool_]) -> None:
        """Add the sensor noise to the fresh scans of the ``due`` worlds."""
        spec = self.lidar_spec
        for i in np.flatnonzero(due):
            rng = self._sensor_rng[i]
            assert rng is not None
            row = self._scans[i : i + 1]
            z = rng.standard_normal(row.shape)
            _add_noise(row, z, spec.noise_std, spec.range_min, spec.range_max)

    # -- internals -------------------------------------------------------------------------------
    def _parallel(self, worlds: int) -> bool:
        """Run a kernel over ``worlds`` worlds on the thread pool (else on the calling thread).

        A pool launch costs tens of µs (more on busy cores), more than one world's work.
        """
        return worlds >= self.params.parallel_min_worlds and numba.get_num_threads() > 1

    def _alloc_peds(self, p: int, k: int) -> None:
        n = self.num_worlds
        self._pos = np.zeros((n, p, 2))
        self._vel = np.zeros((n, p, 2))
        self._heading = np.zeros((n, p))
        self._pradii = np.zeros((n, p))
        self._vmax = np.zeros((n, p))
        self._kinds = np.full((n, p), -1, dtype=np.int64)
        self._ped_n = np.zeros(n, dtype=np.int64)
        self._ped_view = None
        self._wps = np.zeros((n, p, k, 2))
        self._n_wp = np.ones((n, p), dtype=np.int64)
        self._wp_mode = np.zeros((n, p), dtype=np.int64)
        self._wp_idx = np.zeros((n, p), dtype=np.int64)

    def _ensure_capacity(self, episodes: Sequence[Episode]) -> None:
        """Grow the padded buffers (keeping every world's content) to fit ``episodes``."""
        n = self.num_worlds
        cells = max(ep.grid.width * ep.grid.height for ep in episodes)
        if cells > self._cap_cells:
            old, old_cap = self._dist, self._cap_cells
            self._dist = np.zeros(n * cells, dtype=np.float32)
            for i in range(n if old_cap else 0):
                self._dist[i * cells : i * cells + old_cap] = old[i * old_cap : (i + 1) * old_cap]
            self._cap_cells = cells
            self._offs = np.array([max(k, 0) for k in self._slot_of], dtype=np.int64) * cells
        segs = max(sum(len(ob.footprint) for ob in ep.obstacles) for ep in episodes)
        if segs > self._seg_a.shape[1]:
            for name in ("_seg_a", "_seg_b", "_seg_owner"):
                old_a = getattr(self, name)
                new = np.zeros((n, segs, *old_a.shape[2:]), dtype=old_a.dtype)
                new[:, : old_a.shape[1]] = old_a
                setattr(self, name, new)
        p = max(len(ep.agents) for ep in episodes)
        k = max(ep.agents.waypoints.shape[1] for ep in episodes)
        if p > self._pos.shape[1] or k > self._wps.shape[2]:
            keep = {name: getattr(self, name) for name in (
                "_pos", "_vel", "_heading", "_pradii", "_vmax", "_kinds", "_ped_n", "_wps",
                "_n_wp", "_wp_mode", "_wp_idx")}
            self._alloc_peds(max(p, self._pos.shape[1]), max(k, self._wps.shape[2]))
            for name, old_a in keep.items():
                new = getattr(self, name)
                if name == "_ped_n":
                    new[:] = old_a
                elif name == "_wps":
                    new[:, : old_a.shape[1], : old_a.shape[2]] = old_a
                else:
                    new[:, : old_a.shape[1]] = old_a

    def _load(self, i: int, ep: Episode, rng: np.random.Generator) -> None:
        """Write episode ``ep`` into world slot ``i`` (capacity already ensured)."""
        if len(ep.robots) != 1:
            raise SimulationError(f"BatchSim worlds hold one robot, episode has {len(ep.robots)}")
        robot = ep.robots[0]
        model = robot.model
        spec = model.laser
        if self._spec is None:
            self._set_spec(spec)
        elif spec is not self._spec and spec != self._spec:
            raise SimulationError("every world's robot must carry the same lidar spec")
        self._episodes[i] = ep
        self._world_rng[i] = rng
        self._crowd_rng[i], self._sensor_rng[i] = split_rng(rng)
        # A task generator hands every episode the same model object: build its kinematics and
        # regroup the worlds only when world i gets another model (models are frozen).
        if model is not self._models[i]:
            self._models[i] = model
            self._kin[i] = model.build_kinematics()
            self._radius[i] = self.params.robot_radius or model.circumscribed_radius
            self._regroup()
        # robot
        self._poses[i] = robot.start.as_array()
        self._twists[i] = 0.0
        self._steer[i] = 0.0
        self._commands[i] = 0.0
        self._time[i] = 0.0
        self._step[i] = 0
        self._last_scan[i] = -math.inf
        # map (cells, float32, capped: exactly what Lidar2D.bind stores)
        g = ep.grid
        self._offs[i] = self._map_slot(i, g) * self._cap_cells
        self._shapes[i] = (g.height, g.width)
        self._res[i] = g.resolution
        self._origin[i] = g.origin[0], g.origin[1]
        faces = wall_faces(g)
        if use_wall_faces(faces, spec.num_beams):
            if len(faces) > self._faces.shape[1]:
                grown = np.zeros((self.num_worlds, len(faces), 4))
                grown[:, : self._faces.shape[1]] = self._faces
                self._faces = grown
            self._faces[i, : len(faces)] = faces
            self._face_n[i] = len(faces)
        else:
            self._face_n[i] = -1
        # obstacles
        s = 0
        for j, ob in enumerate(ep.obstacles):
            poly = ob.polygon
            m = len(poly)
            if m == 0:
                continue
            self._seg_a[i, s : s + m] = poly
            self._seg_b[i, s : s + m - 1] = poly[1:]  # np.roll(poly, -1, axis=0), unallocated
            self._seg_b[i, s + m - 1] = poly[0]
            self._seg_owner[i, s : s + m] = j
            s += m
        self._seg_n[i] = s
        # pedestrians
        a = ep.agents
        p = len(a)
        self._ped_n[i] = p
        self._ped_view = None
        for arr, fill in ((self._pos, 0.0), (self._vel, 0.0), (self._heading, 0.0),
                          (self._pradii, 0.0), (self._vmax, 0.0), (self._kinds, -1),
                          (self._wps, 0.0), (self._n_wp, 1), (self._wp_mode, 0),
                          (self._wp_idx, 0)):
            arr[i] = fill
        self._pos[i, :p] = a.positions
        self._pradii[i, :p] = a.radii
        self._vmax[i, :p] = a.vmax
        self._kinds[i, :p] = a.kinds
        kw = a.waypoints.shape[1]
        self._wps[i, :p, :kw] = np.nan_to_num(a.waypoints)
        self._n_wp[i, :p] = a.num_waypoints
        self._wp_mode[i, :p] = a.waypoint_mode
        crowd_rng = self._crowd_rng[i]
        assert crowd_rng is not None
        self._rand[i] = crowd_rng.random(_RAND_TABLE)
        self._rand_k[i] = 0

    def _map_slot(self, i: int, g: OccupancyGrid) -> int:
        """Slot holding ``g``'s distance map for world ``i``, writing it into a free slot if new."""
        prev = self._slot_of[i]
        if prev >= 0:
            self._slot_refs[prev] -= 1
            if self._slot_refs[prev] == 0:
                self._slot_grid[prev] = None
        shared = [k for k, sg in enumerate(self._slot_grid) if sg is g]
        if shared:
            slot = shared[0]
        else:
            slot = self._slot_refs.index(0)
            # Cells as float32, capped: exactly what Lidar2D.bind stores.
            cap = float(g.width + g.height + 4)
            d = np.minimum(np.asarray(g.distance) / g.resolution, cap).astype(np.float32)
            o = slot * self._cap_cells
            self._dist[o : o + d.size] = d.reshape(-1)
            self._slot_grid[slot] = g
        self._slot_refs[slot] += 1
        self._slot_of[i] = slot
        return slot

    def _set_spec(self, spec: LidarSpec) -> None:
        self._spec = spec
        angles = spec.angles()
        self._cos = np.cos(angles)
        self._sin = np.sin(angles)
        self._inc = float(spec.angle_increment) if spec.num_beams > 1 else 0.0
        self._mount = np.asarray(spec.mount, dtype=np.float64)
        if self._scans.shape[1] != spec.num_beams:
            self._scans = np.full((self.num_worlds, spec.num_beams), spec.range_max)
        b = spec.num_beams
        if self._scratch_f.shape[2] != b:
            self._scratch_f = np.zeros((self.num_worlds, 6, b))
            self._scratch_i = np.zeros((self.num_worlds, 2, b), dtype=np.int64)

    def _regroup(self) -> None:
        """Group the worlds by kinematics parameters (one vectorised call per group)."""
        groups: dict[tuple[str, str], tuple[Kinematics, list[int]]] = {}
        for i, kin in enumerate(self._kin):
            if kin is None:
                continue
            key = (kin.name, repr(kin.params))
            groups.setdefault(key, (kin, []))[1].append(i)
        self._groups = [(kin, np.array(idx, dtype=np.int64)) for kin, idx in groups.values()]

    def _snapshot(self) -> BatchState:
        # Same values as nested np.where(wall, WALL, where(obstacle, OBSTACLE, where(agent, ...)))
        # but in place on one array (the lowest-priority kind first, overwritten by higher ones).
        kind = np.full(self.num_worlds, K.KIND_NONE, dtype=np.int64)
        kind[self._agent >= 0] = K.KIND_PEDESTRIAN
        kind[self._obstacle >= 0] = K.KIND_OBSTACLE
        kind[self._wall] = K.KIND_WALL
        if self._ped_view is None:  # changes only when a world is loaded: built once then
            mask = np.arange(self._pos.shape[1])[None, :] < self._ped_n[:, None]
            states = mask.astype(np.int64)  # np.where(mask, 0, -1) as 1/0 minus 1
            states -= 1
            mask.setflags(write=False)  # shared by the snapshots until the next load
            states.setflags(write=False)
            self._ped_view = (mask, states)
        mask, states = self._ped_view
        return BatchState(
            time=self._time.copy(), step=self._step.copy(), poses=self._poses.copy(),
            twists=self._twists.copy(), commands=self._commands.copy(),
            scans=self._scans.copy(), collided=kind != K.KIND_NONE, collision_kind=kind,
            wall=self._wall.copy(), obstacle=self._obstacle.copy(), agent=self._agent.copy(),
            ped_positions=self._pos.copy(), ped_velocities=self._vel.copy(),
            ped_headings=self._heading.copy(), ped_radii=self._pradii.copy(), ped_mask=mask,
            ped_kinds=self._kinds.copy(), ped_states=states,
        )
