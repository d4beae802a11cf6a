"""The one simulation engine: ``W`` worlds, each with its robots, crowd and obstacles.

:class:`Engine` steps every world through its stages in a fixed order (crowd, kinematics,
contacts, sensors; :mod:`arena.sim.engine.stages`). ``native2d`` is this engine with ``W = 1``
behind the :class:`~arena.sim.backend.SimulatorBackend` protocol, and
:class:`~arena.learn.batched.BatchedSocialNavEnv` the same engine with ``W`` worlds behind the
vector-env face: there is no second simulator, and world ``w`` of a batch steps exactly as a
single run of its episode (``tests/sim/engine/test_equivalence.py``).

Flat layout: the robots of all worlds are global rows ``0..R-1``, world ``w`` owning rows
``robot_off[w]:robot_off[w + 1]`` (poses ``(R, 3)`` ``[x m, y m, θ rad]``, twists and commands
``(R, 3)`` ``[vx m/s, vy m/s, ω rad/s]``); sensors are rows ``0..S-1`` of ``sensor_off`` (per
world, per robot, in the order of the robot's ``sensors`` mapping), each carried by robot row
``sensor_robot[s]``, named ``sensor_name[s]``, of registered type ``sensor_kind[s]``, its latest
reading ``scans[s]``; the pedestrians of world ``w`` are rows
``ag_off[w]:ag_off[w + 1]`` of ``ag_pos`` ``(A, 2)`` m and ``ag_r`` ``(A,)`` m. Indices reported
per world (contacts) are local to it; ``-1`` is none. Every array is replaced by a step, never
written in place, so a caller may keep what it read.

Randomness: world ``w`` gets its own generator at its reset, split by
:func:`~arena.sim.backend.split_rng` into the crowd and sensor streams; nothing draws from the
stream of another world, so world ``w``'s results depend neither on ``W``, the other worlds nor
the thread count.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import TypeVar

import numba
import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from arena.core.errors import SimulationError
from arena.core.records import frozen_record
from arena.core.types import Pose2D
from arena.robots.kinematics.base import Kinematics
from arena.robots.model import RobotModel
from arena.scene.episode import Episode
from arena.scene.state import AgentStates, Collisions, RobotStates, SimState, StaticWorld
from arena.sensors.base import SensorBank, freeze_reading
from arena.sim.backend import PedestrianDriver, split_rng
from arena.sim.contacts import ContactBank, Footprint
from arena.sim.engine.agents import PaddedAgents, pad_agents, standing_agents
from arena.sim.engine.params import EngineParams
from arena.sim.engine.stages import (
    ContactStage,
    CrowdStage,
    KinematicsStage,
    SensorStage,
    Stage,
    check_step,
)

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
B1 = NDArray[np.bool_]
T = TypeVar("T")


_NO_READING = np.zeros(0)
_NO_READING.flags.writeable = False


def robot_sensors(model: RobotModel) -> tuple[tuple[str, str, BaseModel], ...]:
    """``(name, type, params)`` of each sensor a robot model carries, in sensor-row order.

    The one place the engine learns a robot's sensors (``model.sensors``, validated through
    :data:`~arena.sensors.base.SENSORS`, each params declaring its ``type``).
    """
    return tuple((name, str(spec.type), spec) for name, spec in model.sensors.items())


@dataclass(frozen=True)
class _RobotSensors:
    """World-local sensor rows of one robot: ``(name, row)`` each and its primary lidar's row."""

    rows: tuple[tuple[str, int], ...]
    primary: int  # -1: no lidar2d


class Engine:
    """``num_worlds`` worlds stepped together; see the module docstring.

    Usage: :meth:`reset_worlds` (every world once before the first :meth:`step`), then
    :meth:`step` with ``(R, 3)`` commands; :meth:`world_state` is world ``w``'s
    :class:`SimState`; the flat attributes serve batched callers.

    Args:
        num_worlds: ``W``.
        params: engine parameters.
        contact_stage: the contact stage (default :class:`ContactStage`, the exact 2-D
            footprints); another simulator swaps in its own (the MuJoCo backend's).
        sensor_stage: the sensor stage (default :class:`SensorStage` with the registered banks).
    """

    def __init__(
        self, num_worlds: int, params: EngineParams | None = None, *,
        contact_stage: ContactStage | None = None, sensor_stage: SensorStage | None = None,
    ) -> None:
        if num_worlds < 1:
            raise SimulationError(f"num_worlds must be >= 1, got {num_worlds}")
        self.num_worlds = w_n = int(num_worlds)
        self.params = params or EngineParams()
        self.tracks_walked = (
            self.params.pedestrians_block_lidar and self.params.pedestrian_body == "legs"
        )
        self.contacts = ContactBank()
        self.crowd_stage = CrowdStage()
        self.kinematics_stage = KinematicsStage()
        self.contact_stage = contact_stage or ContactStage()
        self.sensor_stage = sensor_stage or SensorStage()
        self.stages: tuple[Stage, ...] = (
            self.crowd_stage, self.kinematics_stage, self.contact_stage, self.sensor_stage,
        )
        # per world
        self.static_worlds: list[StaticWorld | None] = [None] * w_n
        self.drivers: list[PedestrianDriver | None] = [None] * w_n
        self.agents: list[AgentStates] = [AgentStates.empty()] * w_n
        self.crowd_rng: list[np.random.Generator | None] = [None] * w_n
        self.sensor_rng: list[np.random.Generator] = [np.random.default_rng(0)] * w_n
        self.time: list[float] = [0.0] * w_n
        self.step_count: list[int] = [0] * w_n
        self.walked: list[F64] = [np.zeros(0)] * w_n
        self._names: list[tuple[str, ...]] = [()] * w_n
        self._models: list[tuple[str, ...]] = [()] * w_n
        self._polys: list[tuple[F64 | None, ...]] = [()] * w_n
        self._ready = [False] * w_n
        self._all_ready = False
        self._snapshots: list[SimState | None] = [None] * w_n
        # robot rows
        self.robot_off = np.zeros(w_n + 1, dtype=np.int64)
        self._robot_off_l = [0] * (w_n + 1)
        self.row_world = np.zeros(0, dtype=np.int64)
        self.poses = np.zeros((0, 3))
        self.twists = np.zeros((0, 3))
        self.steering = np.zeros(0)
        self.commands = np.zeros((0, 3))
        self.radii = np.zeros(0)
        self.footprints: list[Footprint] = []
        self.kinematics: list[Kinematics] = []
        self.wall = np.zeros(0, dtype=bool)
        self.obstacle = np.zeros(0, dtype=np.int64)
        self.agent = np.zeros(0, dtype=np.int64)
        self.robot = np.zeros(0, dtype=np.int64)
        self._multi = np.zeros(0, dtype=bool)  # the row's world holds several robots
        self._no_polygons: list[F64 | None] | None = []
        self.next_poses = self.poses
        self.next_twists = self.twists
        self.next_steering = self.steering
        # sensor rows
        self.sensor_off = np.zeros(w_n + 1, dtype=np.int64)
        self._sensor_off_l = [0] * (w_n + 1)
        self.sensor_world = np.zeros(0, dtype=np.int64)
        self.sensor_world_list: list[int] = []  # the same as Python ints (per-step loops)
        self.sensor_robot = np.zeros(0, dtype=np.int64)
        self.sensor_name: list[str] = []
        self.sensor_kind: list[str] = []  # registry name of the row's type (its bank)
        self.sensor_local: list[int] = []  # the row's index in its bank
        self.sensor_bank: list[SensorBank] = []  # the row's bank
        self._robot_sensors: list[tuple[_RobotSensors, ...]] = [()] * w_n
        self.specs: list[BaseModel] = []
        self.scan_period: list[float] = []
        self.last_scan: list[float] = []
        self.scans: list[F64] = []
        # pedestrians, flat (gather_agents)
        self.ag_off = np.zeros(w_n + 1, dtype=np.int64)
        self.ag_pos = np.zeros((0, 2))
        self.ag_r = np.zeros(0)
        self._padded: PaddedAgents | None = None
        # caches across episodes: the same robot model gives the same hull and kinematics
        self._footprint_cache: dict[tuple[object, ...], Footprint] = {}
        self._kin_cache: dict[int, tuple[RobotModel, Kinematics]] = {}

    # -- worlds --------------------------------------------------------------------------------
    def world(self, w: int) -> StaticWorld:
        """The static part of world ``w``'s episode."""
        world = self.static_worlds[w]
        if world is None:
            raise SimulationError("the backend has not been reset with an episode yet")
        return world

    def reset_worlds(
        self,
        indices: Sequence[int] | I64,
        episodes: Sequence[Episode],
        drivers: Sequence[PedestrianDriver | None],
        rngs: Sequence[np.random.Generator],
    ) -> None:
        """Start ``episodes[j]`` in world ``indices[j]``; the other worlds are untouched.

        ``drivers[j]`` moves that episode's pedestrians (``None``: they stand still) and draws
        from the first stream of ``split_rng(rngs[j])``; sensor noise from the second.
        """
        idx = [int(i) for i in indices]
        if not (len(idx) == len(episodes) == len(drivers) == len(rngs)):
            raise SimulationError("indices, episodes, drivers and rngs must have the same length")
        for w in idx:
            if not 0 <= w < self.num_worlds:
                raise SimulationError(f"no world {w}: worlds are 0..{self.num_worlds - 1}")
        if len(set(idx)) != len(idx):
            raise SimulationError(f"a world is reset twice in one call: {idx}")
        if not all(ep.robots for ep in episodes):  # before any world changes
            raise SimulationError("an episode needs at least one robot")
        loaded: dict[int, tuple[Episode, list[RobotModel]]] = {}
        for w, ep, driver, rng in zip(idx, episodes, drivers, rngs, strict=True):
            loaded[w] = (ep, self._load(w, ep, driver, rng))
        self._rebuild_rows(loaded)
        self.gather_agents()
        for stage in self.stages:
            stage.reset_worlds(self, idx)
        fresh = np.isin(self.row_world, idx)
        wall, obstacle, agent, robot = self.contact_stage.test(self, fresh, len(idx))
        self._merge_flags(fresh, wall, obstacle, agent, robot)
        self.sensor_stage.scan(self, np.isin(self.sensor_world, idx))

    def _load(
        self, w: int, ep: Episode, driver: PedestrianDriver | None, rng: np.random.Generator
    ) -> list[RobotModel]:
        """Per-world state of episode ``ep`` in world ``w``; returns its robot models."""
        robots = ep.robots
        world = StaticWorld.build(ep.grid, ep.obstacles)
        self.static_worlds[w] = world
        self.contacts.bind_world(w, world)
        self.sensor_stage.bind_world(w, world)
        crowd_rng, self.sensor_rng[w] = split_rng(rng)
        self.crowd_rng[w] = crowd_rng
        self._names[w] = tuple(r.name for r in robots)
        self._models[w] = tuple(r.model.name for r in robots)
        self.drivers[w] = driver
        self.agents[w] = (
            driver.reset(ep.agents, world, crowd_rng) if driver is not None
            else standing_agents(ep)
        )
        self.walked[w] = np.zeros(len(self.agents[w]))
        self.time[w] = 0.0
        self.step_count[w] = 0
        self._snapshots[w] = None
        self._ready[w] = True
        self._all_ready = all(self._ready)
        return [r.model for r in robots]

    def _rebuild_rows(self, loaded: dict[int, tuple[Episode, list[RobotModel]]]) -> None:
        """New flat robot and sensor rows: loaded worlds fresh, the others as they were."""
        poses: list[F64] = []
        twists: list[F64] = []
        steer: list[F64] = []
        cmds: list[F64] = []
        flags: list[tuple[B1, I64, I64, I64]] = []
        fps: list[Footprint] = []
        kins: list[Kinematics] = []
        polys_w: list[tuple[F64 | None, ...]] = []
        s_specs: list[BaseModel] = []
        s_names: list[str] = []
        s_kinds: list[str] = []
        per_robot: list[tuple[_RobotSensors, ...]] = []
        s_last: list[float] = []
        s_scans: list[F64] = []
        s_robot: list[int] = []
        s_world: list[int] = []
        robot_off = np.zeros(self.num_worlds + 1, dtype=np.int64)
        sensor_off = np.zeros(self.num_worlds + 1, dtype=np.int64)
        row0 = 0
        for w in range(self.num_worlds):
            if w in loaded:
                ep, models = loaded[w]
                n = len(models)
                poses.append(np.array([r.start.as_array() for r in ep.robots], dtype=np.float64))
                twists.append(np.zeros((n, 3)))
                steer.append(np.zeros(n))
                cmds.append(np.zeros((n, 3)))
                flags.append(_no_flags(n))
                polys = tuple(m.footprint_polygon() for m in models)  # new arrays per robot
                polys_w.append(polys)
                fps.extend(
                    self._footprint(p, m.circumscribed_radius)
                    for p, m in zip(polys, models, strict=True)
                )
                kins.extend(self._kinematics(m) for m in models)
                first = len(s_specs)
                mine: list[_RobotSensors] = []
                for j, m in enumerate(models):
                    named: list[tuple[str, int]] = []
                    for name, kind, spec in robot_sensors(m):
                        named.append((name, len(s_specs) - first))
                        s_specs.append(spec)
                        s_names.append(name)
                        s_kinds.append(kind)
                        s_last.append(-math.inf)
                        s_scans.append(_NO_READING)  # the bank's initial reading, below
                        s_robot.append(row0 + j)
                        s_world.append(w)
                    primary = m.primary_lidar
                    mine.append(_RobotSensors(
                        tuple(named),
                        dict(named)[primary] if primary is not None else -1,
                    ))
                per_robot.append(tuple(mine))
            else:
                a, b = int(self.robot_off[w]), int(self.robot_off[w + 1])
                poses.append(self.poses[a:b])
                twists.append(self.twists[a:b])
                steer.append(self.steering[a:b])
                cmds.append(self.commands[a:b])
                flags.append((self.wall[a:b], self.obstacle[a:b], self.agent[a:b],
                              self.robot[a:b]))
                polys_w.append(self._polys[w])
                fps.extend(self.footprints[a:b])
                kins.extend(self.kinematics[a:b])
                s0, s1 = int(self.sensor_off[w]), int(self.sensor_off[w + 1])
                s_specs.extend(self.specs[s0:s1])
                s_names.extend(self.sensor_name[s0:s1])
                s_kinds.extend(self.sensor_kind[s0:s1])
                per_robot.append(self._robot_sensors[w])
                s_last.extend(self.last_scan[s0:s1])
                s_scans.extend(self.scans[s0:s1])
                s_robot.extend(int(r) - a + row0 for r in self.sensor_robot[s0:s1])
                s_world.extend([w] * (s1 - s0))
            row0 += len(poses[-1])
            robot_off[w + 1] = row0
            sensor_off[w + 1] = len(s_specs)
        self._polys = polys_w
        self.robot_off = robot_off
        self._robot_off_l = robot_off.tolist()  # the same as Python ints
        counts = np.diff(robot_off)
        self.row_world = np.repeat(np.arange(self.num_worlds, dtype=np.int64), counts)
        self._multi = counts[self.row_world] > 1
        self._no_polygons = None if self._multi.any() else [None] * len(self.row_world)
        self.poses = np.concatenate(poses)
        self.twists = np.concatenate(twists)
        self.steering = np.concatenate(steer)
        self.commands = np.concatenate(cmds)
        self.wall = np.concatenate([f[0] for f in flags])
        self.obstacle = np.concatenate([f[1] for f in flags])
        self.agent = np.concatenate([f[2] for f in flags])
        self.robot = np.concatenate([f[3] for f in flags])
        self.footprints = fps
        self.kinematics = kins
        self.radii = np.array([fp.radius for fp in fps], dtype=np.float64)
        self.sensor_off = sensor_off
        self._sensor_off_l = sensor_off.tolist()
        self.sensor_world = np.array(s_world, dtype=np.int64)
        self.sensor_world_list = s_world
        self.sensor_robot = np.array(s_robot, dtype=np.int64)
        self.specs = s_specs
        self.sensor_name = s_names
        self.sensor_kind = s_kinds
        self._robot_sensors = per_robot
        self.scan_period = [1.0 / float(s.update_rate) for s in s_specs]  # type: ignore[attr-defined]
        self.last_scan = s_last
        self.contacts.set_robots(self.row_world, fps)
        self.sensor_local, self.sensor_bank = self.sensor_stage.set_rows(
            self, s_kinds, s_world, s_robot, s_specs
        )
        for s, reading in enumerate(s_scans):
            if reading is _NO_READING:  # a fresh row: what its bank reads before a scan
                s_scans[s] = freeze_reading(self.sensor_bank[s].read(self.sensor_local[s], None))
        self.scans = s_scans

    def _footprint(self, polygon: F64 | None, radius: float) -> Footprint:
        """``Footprint.make(polygon, radius)``, the same object while the inputs are equal."""
        if polygon is None:
            key: tuple[object, ...] = (None, float(radius))
        else:
            p = np.asarray(polygon, dtype=np.float64)
            key = (p.shape, p.tobytes(), float(radius))
        fp = self._footprint_cache.get(key)
        if fp is None:
            if len(self._footprint_cache) >= 64:  # many robot models: keep it small
                self._footprint_cache.clear()
            fp = Footprint.make(polygon, radius)
            self._footprint_cache[key] = fp
        return fp

    def _kinematics(self, model: RobotModel) -> Kinematics:
        """``model.build_kinematics()``, built once per model object (models are frozen)."""
        hit = self._kin_cache.get(id(model))
        if hit is None or hit[0] is not model:
            if len(self._kin_cache) >= 64:
                self._kin_cache.clear()
            hit = (model, model.build_kinematics())
            self._kin_cache[id(model)] = hit
        return hit[1]

    # -- stepping ------------------------------------------------------------------------------
    def step(self, commands: F64, dt: float) -> None:
        """Advance every world by ``dt`` s with ``(R, 3)`` body-twist commands."""
        if not self._all_ready:
            missing = [w for w, ok in enumerate(self._ready) if not ok]
            raise SimulationError(f"step() called before reset() of worlds {missing}")
        cmd = check_step(self.poses.shape[0], commands, dt)
        for stage in self.stages:
            if stage is self.sensor_stage:  # the clock the sensors read: after the motion
                self._tick(dt)
            stage.step(self, cmd, dt)
        self._snapshots = [None] * self.num_worlds
        self._padded = None

    def _tick(self, dt: float) -> None:
        """Advance every world's clock (lists of the engine's own, never handed out)."""
        time, count = self.time, self.step_count
        for w in range(self.num_worlds):
            time[w] += dt
            count[w] += 1

    def teleport(self, w: int, robot: int, pose: Pose2D) -> None:
        """Move robot ``robot`` of world ``w`` to ``pose`` at rest; time does not advance.

        Its twist, steering and last command become zero; the contacts of world ``w`` are
        evaluated at the new poses (no sweep) and all its sensors scan afresh.
        """
        if not self._ready[w]:
            raise SimulationError("teleport() called before reset()")
        a, b = int(self.robot_off[w]), int(self.robot_off[w + 1])
        n = b - a
        if not 0 <= robot < n:
            raise SimulationError(f"no robot {robot}: the episode has robots 0..{n - 1}")
        target = np.array([pose.x, pose.y, pose.theta], dtype=np.float64)
        if not np.all(np.isfinite(target)):
            raise SimulationError(f"teleport pose must be finite, got {target.tolist()}")
        row = a + robot
        self.poses = self.poses.copy()
        self.poses[row] = target
        self.twists = self.twists.copy()
        self.twists[row] = 0.0
        self.steering = self.steering.copy()
        self.steering[row] = 0.0
        self.commands = self.commands.copy()
        self.commands[row] = 0.0
        mine = self.row_world == w
        wall, obstacle, agent, rob = self.contact_stage.test(self, mine, 1)
        self._merge_flags(mine, wall, obstacle, agent, rob)
        # every robot of the world sees the moved one: all its sensors scan afresh
        self.sensor_stage.scan(self, self.sensor_world == w)
        self._snapshots[w] = None
        self._padded = None

    def _merge_flags(self, rows: B1, wall: B1, obstacle: I64, agent: I64, robot: I64) -> None:
        """Contact flags of ``rows`` from the test results, the others kept (new arrays)."""
        if rows.all():
            self.wall, self.obstacle, self.agent, self.robot = wall, obstacle, agent, robot
            return
        self.wall = np.where(rows, wall, self.wall)
        self.obstacle = np.where(rows, obstacle, self.obstacle)
        self.agent = np.where(rows, agent, self.agent)
        self.robot = np.where(rows, robot, self.robot)

    # -- helpers the stages use ----------------------------------------------------------------
    def parallel(self, worlds: int) -> bool:
        """Run a kernel over ``worlds`` worlds on numba's thread pool (else on this thread).

        A pool launch costs tens of µs (more on busy cores), more than one world's work.
        """
        return worlds >= self.params.parallel_min_worlds and numba.get_num_threads() > 1

    def in_pool(self, worlds: int, call: Callable[[bool], T]) -> T:
        """``call(parallel)``, on numba's thread pool (with ``parallel_chunksize``) if worth it.

        Worlds differ in cost (a scan in a corridor ends sooner than one across a hall) and a
        shared core may stall one thread: with dynamic chunks the other threads take the rest.
        Which thread steps a world never changes its result.
        """
        if not self.parallel(worlds):
            return call(False)
        previous = numba.set_parallel_chunksize(self.params.parallel_chunksize)
        try:
            return call(True)
        finally:
            numba.set_parallel_chunksize(previous)

    def gather_agents(self) -> None:
        """The flat pedestrian arrays from each world's :class:`AgentStates`."""
        self._padded = None
        if self.num_worlds == 1:
            a = self.agents[0]
            if self.ag_off[1] != len(a):
                self.ag_off = np.array([0, len(a)], dtype=np.int64)
            self.ag_pos, self.ag_r = a.positions, a.radii
            return
        counts = [len(a) for a in self.agents]
        self.ag_off = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        self.ag_pos = np.concatenate([a.positions for a in self.agents])
        self.ag_r = np.concatenate([a.radii for a in self.agents])

    def placed_polygons(self) -> list[F64 | None]:
        """Per robot row, its footprint placed at its pose where other robots can see it.

        ``None`` for a circular robot and for the robot of a one-robot world.
        """
        if self._no_polygons is not None:  # one robot per world: nobody sees another robot
            return self._no_polygons
        return [
            fp.world_polygon(self.poses[r]) if multi else None
            for r, (fp, multi) in enumerate(zip(self.footprints, self._multi.tolist(),
                                                strict=True))
        ]

    def robots_at_start(self, w: int) -> RobotStates:
        """World ``w``'s robots now (views of arrays no step writes into)."""
        snap = self._snapshots[w]
        if snap is not None:
            return snap.robots
        a, b = self._robot_off_l[w], self._robot_off_l[w + 1]
        s0, s1 = self._sensor_off_l[w], self._sensor_off_l[w + 1]
        scans, sensors = self._readings(w, self.scans[s0:s1])
        return frozen_record(
            RobotStates,
            names=self._names[w], models=self._models[w], poses=self.poses[a:b],
            twists=self.twists[a:b], commands=self.commands[a:b], radii=self.radii[a:b],
            footprints=self._polys[w], scans=scans, sensors=sensors,
        )

    def _readings(
        self, w: int, readings: list[F64]
    ) -> tuple[tuple[F64, ...], tuple[Mapping[str, F64], ...]]:
        """World ``w``'s per-robot primary lidar scans and sensors by name from its rows."""
        per_robot = self._robot_sensors[w]
        if len(per_robot) == 1 and len(per_robot[0].rows) == 1:  # the usual case, kept cheap
            rs = per_robot[0]
            r = readings[0]
            return (r if rs.primary == 0 else _NO_READING,), (MappingProxyType({rs.rows[0][0]: r}),)
        scans = tuple(readings[rs.primary] if rs.primary >= 0 else _NO_READING
                      for rs in per_robot)
        sensors = tuple(MappingProxyType({name: readings[k] for name, k in rs.rows})
                        for rs in per_robot)
        return scans, sensors

    def sensor_rows(self, name: str) -> I64:
        """``(R,)`` global sensor row of each robot row's sensor ``name`` (``-1``: none)."""
        out = np.full(self.poses.shape[0], -1, dtype=np.int64)
        for s, (n, r) in enumerate(zip(self.sensor_name, self.sensor_robot.tolist(),
                                       strict=True)):
            if n == name:
                out[r] = s
        return out

    # -- views ---------------------------------------------------------------------------------
    def world_state(self, w: int) -> SimState:
        """World ``w``'s snapshot: copies, or arrays the engine never writes into."""
        snap = self._snapshots[w]
        if snap is not None:
            return snap
        if not self._ready[w]:
            raise SimulationError("the backend has not been reset with an episode yet")
        s0, s1 = self._sensor_off_l[w], self._sensor_off_l[w + 1]
        # the readings are read-only arrays the engine replaces, never writes: shared
        readings = self.scans[s0:s1]
        scans, sensors = self._readings(w, readings)
        if self.num_worlds == 1:
            # Every row is world 0's. The commands and contact flags are arrays of this step
            # that the engine replaces and never reads back into the simulation: shared.
            robots = frozen_record(
                RobotStates,
                names=self._names[0], models=self._models[0], poses=self.poses.copy(),
                twists=self.twists.copy(), commands=self.commands, radii=self.radii.copy(),
                footprints=self._polys[0], scans=scans, sensors=sensors,
            )
            collisions = frozen_record(
                Collisions, wall=self.wall, obstacle=self.obstacle, agent=self.agent,
                robot=self.robot,
            )
        else:
            rows = slice(self._robot_off_l[w], self._robot_off_l[w + 1])
            robots = frozen_record(
                RobotStates,
                names=self._names[w], models=self._models[w], poses=self.poses[rows].copy(),
                twists=self.twists[rows].copy(), commands=self.commands[rows].copy(),
                radii=self.radii[rows].copy(), footprints=self._polys[w], scans=scans,
                sensors=sensors,
            )
            collisions = frozen_record(
                Collisions, wall=self.wall[rows].copy(), obstacle=self.obstacle[rows].copy(),
                agent=self.agent[rows].copy(), robot=self.robot[rows].copy(),
            )
        # frozen_record: these records' generated __init__ would cost more than the copies
        snap = frozen_record(
            SimState, time=self.time[w], step=self.step_count[w], robots=robots,
            agents=self.agents[w], collisions=collisions,
        )
        self._snapshots[w] = snap
        return snap

    def collided(self) -> B1:
        """``(R,)`` bool: the robot row touches anything."""
        return self.wall | (np.maximum(np.maximum(self.obstacle, self.agent), self.robot) >= 0)

    def padded_agents(self) -> PaddedAgents:
        """Every world's pedestrians padded to the largest crowd (built once per step)."""
        if self._padded is None:
            self._padded = pad_agents(self.agents, self.ag_off, self.ag_pos, self.ag_r)
        return self._padded

def _no_flags(n: int) -> tuple[B1, I64, I64, I64]:
    neg = np.full(n, -1, dtype=np.int64)
    return np.zeros(n, dtype=bool), neg, neg.copy(), neg.copy()
