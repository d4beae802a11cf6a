"""The stages of one engine step, in their fixed order: crowd, kinematics, contacts, sensors.

A stage is an object with ``reset_worlds(engine, worlds)`` (after worlds were (re)loaded: the
robot and sensor rows may have changed) and ``step(engine, commands, dt)``; the engine holds
them in a tuple and calls them in order. A later engine (GPU, 3-D) swaps stages, not the loop.
Each stage reads and replaces the engine's flat arrays (never writes into arrays it handed
out, so a caller may keep them).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel

from arena.core.errors import SimulationError
from arena.robots.kinematics.base import Kinematics, KinematicState, box_step_rows
from arena.scene.state import StaticWorld
from arena.sensors.base import SENSORS, SensorBank, freeze_reading
from arena.sim.engine.scene import DynamicScene, SceneBuilder, pedestrian_circles

if TYPE_CHECKING:
    from arena.sim.engine.engine import Engine

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


class Stage(Protocol):
    """One stage of :meth:`Engine.step`."""

    def reset_worlds(self, engine: Engine, worlds: list[int]) -> None:
        """Worlds ``worlds`` were loaded; rows may have moved."""
        ...

    def step(self, engine: Engine, commands: F64, dt: float) -> None:
        """Advance this stage's part of every world by ``dt`` s."""
        ...


class CrowdStage:
    """Each world's pedestrian driver, in world order, sees its robots as at the step start."""

    def reset_worlds(self, engine: Engine, worlds: list[int]) -> None:
        """Nothing to do: drivers are reset by :meth:`Engine.reset_worlds`."""

    def step(self, engine: Engine, commands: F64, dt: float) -> None:
        """Step every driver; track the distance walked where the legs gait needs it."""
        moved = False
        track = engine.tracks_walked
        for w, driver in enumerate(engine.drivers):
            if driver is None:
                continue
            before = engine.agents[w].positions
            agents = driver.step(engine.robots_at_start(w), dt)
            engine.agents[w] = agents
            moved = True
            if track and agents.positions.shape == before.shape:
                walked = engine.walked[w]
                if walked.shape[0] != len(agents):  # the crowd changed size: a new gait
                    walked = np.zeros(len(agents))
                engine.walked[w] = walked + np.hypot(*(agents.positions - before).T)
        if moved:
            engine.gather_agents()


class KinematicsStage:
    """Robots grouped by kinematics model and parameters, one call per group.

    Box models (velocity box and per-axis acceleration limits: diff drive, omni) step their
    rows in one compiled call built on :func:`~arena.robots.kinematics.base.box_step_rows` (no
    steering); the others through :meth:`Kinematics.step` on their gathered rows.
    """

    def __init__(self) -> None:
        self._groups: list[tuple[Kinematics, I64, tuple[F64, F64, F64] | None]] = []

    def reset_worlds(self, engine: Engine, worlds: list[int]) -> None:
        """Regroup the rows by model (a task generator hands every episode the same model)."""
        groups: dict[tuple[str, str], tuple[Kinematics, list[int]]] = {}
        for row, kin in enumerate(engine.kinematics):
            key = (kin.name, repr(kin.params))
            groups.setdefault(key, (kin, []))[1].append(row)
        self._groups = [
            (kin, np.array(rows, dtype=np.int64), getattr(kin, "box_limits", None))
            for kin, rows in groups.values()
        ]

    def step(self, engine: Engine, commands: F64, dt: float) -> None:
        """Write the unconstrained next poses, twists and steering into the engine."""
        poses, twists, steer = engine.poses, engine.twists, engine.steering
        r = poses.shape[0]
        new_p = np.empty((r, 3))
        new_t = np.empty((r, 3))
        new_s = np.empty(r)
        for kin, rows, box in self._groups:
            if box is not None:
                box_step_rows(poses, twists, commands, box[0], box[1], box[2], dt, rows, new_p,
                              new_t, new_s)
                continue
            s = kin.step(KinematicState(poses[rows], twists[rows], steer[rows]), commands[rows], dt)
            new_p[rows], new_t[rows], new_s[rows] = s.poses, s.twists, s.steering
        engine.next_poses, engine.next_twists, engine.next_steering = new_p, new_t, new_s


class ContactStage:
    """Exact-footprint contacts at the new poses, walls swept from the previous ones.

    With ``collision_response: stop`` a robot in contact is held at its previous pose with zero
    twist (its steering unchanged); the contact is reported either way.
    """

    def reset_worlds(self, engine: Engine, worlds: list[int]) -> None:
        """Nothing to do: the engine tests the contacts of reset worlds through :meth:`test`."""

    def test(
        self, engine: Engine, rows: NDArray[np.bool_], worlds: int
    ) -> tuple[NDArray[np.bool_], I64, I64, I64]:
        """Contacts of robot rows ``rows`` ``(R,)`` (of ``worlds`` worlds) at their poses now.

        No sweep, no response: what a reset or a teleport reports. Returns ``(wall, obstacle,
        agent, robot)`` ``(R,)`` each, the rows outside ``rows`` without contact.
        """
        return engine.in_pool(worlds, lambda parallel: engine.contacts.test(
            engine.poses, None, engine.ag_off, engine.ag_pos, engine.ag_r, rows=rows,
            parallel=parallel,
        ))

    def step(self, engine: Engine, commands: F64, dt: float) -> None:
        """Test, respond, and commit the new robot state."""
        new_p, new_t, new_s = engine.next_poses, engine.next_twists, engine.next_steering
        old = engine.poses
        # The engine's own pose and offset arrays are always C-contiguous float64 / int64 of
        # the bank's shapes (the kinematics stage builds new_p, this stage commits it): the
        # unchecked entry. Drivers' pedestrian arrays are normalised (views when they fit).
        ag_off = engine.ag_off
        ag_pos = np.ascontiguousarray(engine.ag_pos, dtype=np.float64).reshape(-1, 2)
        ag_r = np.ascontiguousarray(engine.ag_r, dtype=np.float64).reshape(-1)
        test = engine.contacts.test_unchecked
        if engine.parallel(engine.num_worlds):
            wall, obstacle, agent, robot = engine.in_pool(
                engine.num_worlds,
                lambda parallel: test(new_p, old, True, ag_off, ag_pos, ag_r, None, parallel),
            )
        else:  # one world (native2d): no pool, no closure
            wall, obstacle, agent, robot = test(new_p, old, True, ag_off, ag_pos, ag_r, None, False)
        # one small compiled test first: contacts are rare, the response's nine arguments
        # cost more to pass than the test
        if engine.params.collision_response == "stop" and _any_contact(wall, obstacle, agent,
                                                                       robot):
            _hold_blocked(wall, obstacle, agent, robot, old, engine.steering, new_p, new_t, new_s)
        engine.poses, engine.twists, engine.steering = new_p, new_t, new_s
        engine.wall, engine.obstacle, engine.agent, engine.robot = wall, obstacle, agent, robot
        engine.commands = commands.copy()  # the caller may reuse its array


@njit(cache=True)
def _any_contact(wall: NDArray[np.bool_], obstacle: I64, agent: I64, robot: I64) -> bool:
    """Whether any row touches anything."""
    for i in range(wall.shape[0]):
        if wall[i] or obstacle[i] >= 0 or agent[i] >= 0 or robot[i] >= 0:
            return True
    return False


@njit(cache=True)
def _hold_blocked(
    wall: NDArray[np.bool_], obstacle: I64, agent: I64, robot: I64, old_p: F64, old_s: F64,
    new_p: F64, new_t: F64, new_s: F64,
) -> None:
    """``collision_response: stop``: rows in contact keep their pose and steering, at rest.

    One compiled pass instead of half a dozen small array operations per step.
    """
    for i in range(wall.shape[0]):
        if wall[i] or obstacle[i] >= 0 or agent[i] >= 0 or robot[i] >= 0:
            for k in range(3):
                new_p[i, k] = old_p[i, k]
                new_t[i, k] = 0.0
            new_s[i] = old_s[i]


class SensorStage:
    """Readings of the sensor rows whose period elapsed; the others hold their last reading.

    One bank per sensor type present (:data:`~arena.sensors.base.SENSORS`: the ``lidar2d``
    :class:`~arena.sensors.lidar2d.LidarBank` for lidars), built when a robot first carries the
    type: a new type plugs in by registering, without touching this stage. Sensor row ``s``
    is row ``engine.sensor_local[s]`` of the bank of type ``engine.sensor_kind[s]``. Noise is
    added per world from that world's sensor stream, per due row in sensor-row order (a lidar
    draws one ``(1, beams)`` normal per scan with ``noise_std > 0``, as ``Lidar2D.scan`` does).

    Args:
        banks: ``kind -> new bank`` (default: the bank class registered in ``SENSORS``); a
            simulator with banks of its own (MuJoCo) passes its factory.
    """

    def __init__(self, banks: Callable[[str], SensorBank] | None = None) -> None:
        self._make_bank = banks or _registered_bank
        self._scene = SceneBuilder()
        self.banks: dict[str, SensorBank] = {}
        self._bank_rows: dict[str, int] = {}
        self._all_due: dict[int, NDArray[np.bool_]] = {}  # every row due (never written)

    def bank(self, engine: Engine, kind: str) -> SensorBank:
        """The bank of sensor type ``kind``, built and bound to every loaded world if new."""
        bank = self.banks.get(kind)
        if bank is None:
            bank = self._make_bank(kind)
            for w, world in enumerate(engine.static_worlds):
                if world is not None:
                    bank.bind_world(w, world.grid, world.segments_a, world.segments_b)
            self.banks[kind] = bank
        return bank

    def bind_world(self, w: int, world: StaticWorld) -> None:
        """World ``w``'s static part, for every bank built so far."""
        for bank in self.banks.values():
            bank.bind_world(w, world.grid, world.segments_a, world.segments_b)

    def set_rows(
        self, engine: Engine, kinds: list[str], worlds: list[int], robots: list[int],
        specs: list[BaseModel],
    ) -> tuple[list[int], list[SensorBank]]:
        """Hand each bank its rows; returns each sensor row's index within its bank and bank."""
        local: list[int] = []
        per: dict[str, tuple[list[int], list[int], list[BaseModel]]] = {k: ([], [], []) for k in
                                                                      self.banks}
        for kind, w, r, spec in zip(kinds, worlds, robots, specs, strict=True):
            if kind not in per:
                self.bank(engine, kind)
                per[kind] = ([], [], [])
            rows = per[kind]
            local.append(len(rows[0]))
            rows[0].append(w)
            rows[1].append(r)
            rows[2].append(spec)
        for kind, (ws, rs, ss) in per.items():
            self.banks[kind].set_sensors(ws, rs, ss)
            self._bank_rows[kind] = len(ws)
        return local, [self.banks[k] for k in kinds]

    def _due(self, n: int, rows: list[int]) -> NDArray[np.bool_]:
        """``(n,)`` bool, true on ``rows``."""
        if len(rows) == n:  # the usual case: every sensor runs at the period of the step
            due = self._all_due.get(n)
            if due is None:
                due = self._all_due[n] = np.ones(n, dtype=bool)
            return due
        due = np.zeros(n, dtype=bool)
        for s in rows:
            due[s] = True
        return due

    def reset_worlds(self, engine: Engine, worlds: list[int]) -> None:
        """Nothing to do: the engine scans reset worlds through :meth:`scan`."""

    def step(self, engine: Engine, commands: F64, dt: float) -> None:
        """Read the due rows (a 10 Hz lidar in a faster simulation holds its scan)."""
        if not engine.params.lidar:
            return
        times = engine.time
        last = engine.last_scan
        period = engine.scan_period
        rows = [
            s for s, w in enumerate(engine.sensor_world_list)
            if not times[w] - last[s] < period[s] - 1e-9
        ]
        if rows:
            self._scan_rows(engine, rows)

    def scan(self, engine: Engine, due: NDArray[np.bool_]) -> None:
        """Read the rows of ``due`` ``(S,)`` now (their hold restarts)."""
        rows = np.flatnonzero(due).tolist()
        if engine.params.lidar and rows:
            self._scan_rows(engine, rows)

    def _scan_rows(self, engine: Engine, rows: list[int]) -> None:
        """Read sensor rows ``rows`` (ascending), add their noise, restart their hold."""
        p = engine.params
        agents, walked = engine.agents, engine.walked
        peds = (
            [pedestrian_circles(agents[0], walked[0], p)] if len(agents) == 1
            else [pedestrian_circles(a, walked[w], p) for w, a in enumerate(agents)]
        )
        scene = self._scene.build(
            peds, engine.robot_off, engine.poses, engine.radii, engine.placed_polygons()
        )
        poses = engine.poses
        local = engine.sensor_local
        banks = self.banks
        for kind in banks:
            bank = banks[kind]
            if len(banks) == 1:  # one type: its rows are the sensor rows, in order
                mine = rows
            else:
                kind_of = engine.sensor_kind
                mine = [local[s] for s in rows if kind_of[s] == kind]
                if not mine:
                    continue
            due = self._due(self._bank_rows[kind], mine)
            if engine.parallel(len(mine)):
                engine.in_pool(len(mine), partial(_scan, bank, due, poses, scene,
                                                  p.parallel_chunksize))
            else:  # the usual single world: no pool, no closure
                bank.scan(due, poses, scene)
        scans = list(engine.scans)
        world_of, row_bank, rngs = engine.sensor_world_list, engine.sensor_bank, engine.sensor_rng
        times, last = engine.time, engine.last_scan
        for s in rows:
            w = world_of[s]
            last[s] = times[w]
            reading = row_bank[s].read(local[s], rngs[w])
            # shared by the snapshots: never written (a lidar's array inline: the usual case)
            if type(reading) is np.ndarray:
                reading.flags.writeable = False
            else:
                freeze_reading(reading)
            scans[s] = reading
        engine.scans = scans


def _registered_bank(kind: str) -> SensorBank:
    """A new bank of the sensor type registered as ``kind`` (the default bank factory)."""
    bank: SensorBank = SENSORS.get(kind)()
    return bank


def _scan(
    bank: SensorBank, due: NDArray[np.bool_], poses: F64, scene: DynamicScene, chunk: int,
    parallel: bool,
) -> None:
    """``bank.scan`` of its ``due`` rows (for :meth:`Engine.in_pool`)."""
    bank.scan(due, poses, scene, parallel=parallel, chunksize=chunk)


def check_step(n: int, commands: F64, dt: float) -> F64:
    """``commands`` as a float64 ``(n, 3)`` array, or :class:`SimulationError`."""
    cmd = np.asarray(commands, dtype=np.float64)
    if cmd.shape != (n, 3):
        raise SimulationError(f"commands must have shape ({n}, 3) [vx, vy, omega], got {cmd.shape}")
    # math.isfinite over the few values: a fraction of the cost of np.isfinite(...).all()
    if not all(map(math.isfinite, cmd.ravel().tolist())):
        raise SimulationError(f"commands must be finite, got {cmd.tolist()}")
    if not dt > 0:
        raise SimulationError(f"dt must be > 0 s, got {dt}")
    if not math.isfinite(dt):
        raise SimulationError(f"dt must be a finite number > 0, got {dt!r}")
    return cmd
