"""``native2d``: Arena's default backend, a fast kinematic 2-D simulator in numpy and numba.

Robots move by their kinematics models (exact arcs, velocity and acceleration limits), the
pedestrians by a :class:`~arena.sim.backend.PedestrianDriver`, and each robot's 2-D lidar sees
walls, placed obstacles, pedestrians and the other robots. Contacts are tested on the real
footprints. There is no rigid-body dynamics: a robot whose move would overlap something is held
at its previous pose with zero velocity (``collision_response: stop``), and the contact is
reported; with ``collision_response: record`` it passes through and the contact is only reported.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import SimulationError
from arena.core.types import Pose2D
from arena.robots.kinematics.base import KinematicState, box_step_row
from arena.scene.episode import Episode
from arena.scene.state import AgentStates, Collisions, RobotStates, SimState, StaticWorld
from arena.sensors.lidar2d import Lidar2D
from arena.sim.backend import BACKENDS, PedestrianDriver, split_rng
from arena.sim.native2d.collisions import (
    Footprint,
    ObstacleIndex,
    first_agent_hit,
    first_obstacle_hit,
    footprints_overlap,
    hits_grid,
)


@BACKENDS.register("native2d", tags=("default",))
class Native2DBackend:
    """Fast kinematic 2-D simulator with lidar and footprint collisions (the default backend)."""

    class Params(BaseModel):
        """Parameters of :class:`Native2DBackend`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        collision_response: Literal["stop", "record"] = Field(
            "stop", description="'stop': a colliding move is undone; 'record': only reported"
        )
        lidar: bool = Field(True, description="simulate the robots' laser scanners")
        pedestrians_block_lidar: bool = Field(True, description="pedestrians are seen by lidar")
        pedestrian_body: Literal["circle", "legs"] = Field(
            "circle", description="what lidar sees of a pedestrian: its body circle or two legs"
        )
        leg_radius: float = Field(0.07, gt=0, description="m, radius of one leg (legs body)")
        hip_half_width: float = Field(
            0.1, ge=0, description="m, leg centre offset from the body axis"
        )
        stride_amplitude: float = Field(
            0.25, ge=0, description="m, forward/backward swing of each leg at full walking speed"
        )
        stride_length: float = Field(1.4, gt=0, description="m walked per full gait cycle")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self._world: StaticWorld | None = None
        self._state: SimState | None = None
        self._lidars: dict[int, Lidar2D] = {}  # reused across episodes, keyed by spec identity
        # Footprints by polygon and radius: the hull of the same robot is the same every episode.
        self._footprint_cache: dict[tuple[object, ...], Footprint] = {}

    # -- protocol ------------------------------------------------------------------------------
    @property
    def world(self) -> StaticWorld:
        """The static part of the current episode."""
        if self._world is None:
            raise SimulationError("the backend has not been reset with an episode yet")
        return self._world

    @property
    def state(self) -> SimState:
        """The latest snapshot."""
        if self._state is None:
            raise SimulationError("the backend has not been reset with an episode yet")
        return self._state

    def reset(
        self, episode: Episode, pedestrians: PedestrianDriver | None, rng: np.random.Generator
    ) -> SimState:
        """Start ``episode``; ``pedestrians`` moves the agents.

        ``rng`` is split by :func:`~arena.sim.backend.split_rng`: the pedestrians get the first
        stream, the sensor noise the second.
        """
        world = StaticWorld.build(episode.grid, episode.obstacles)
        self._world = world
        self._grid_bounds = world.grid.bounds  # per episode, for the wall test of every step
        self._obstacles = ObstacleIndex.build(world)
        crowd_rng, self._rng = split_rng(rng)
        robots = episode.robots
        if not robots:
            raise SimulationError("an episode needs at least one robot")
        self._names = tuple(r.name for r in robots)
        self._models = tuple(r.model.name for r in robots)
        self._kinematics = [r.model.build_kinematics() for r in robots]
        # Models whose whole step is the box pipeline are stepped in place by one compiled call
        # (box_step_row), without the per-robot state objects and input checks of Kinematics.step.
        self._boxes = [getattr(k, "box_limits", None) for k in self._kinematics]
        polys = [r.model.footprint_polygon() for r in robots]  # new arrays, one per robot
        self._footprints = [
            self._footprint(p, r.model.circumscribed_radius)
            for p, r in zip(polys, robots, strict=True)
        ]
        self._specs = [r.model.laser for r in robots]
        self._scan_period = [1.0 / s.update_rate for s in self._specs]
        self._lidar = []
        for spec in self._specs:
            lidar = self._lidars.get(id(spec))
            if lidar is None or lidar.spec != spec:
                lidar = Lidar2D(spec)
                self._lidars[id(spec)] = lidar
            lidar.bind(world.grid, world.segments_a, world.segments_b)
            self._lidar.append(lidar)
        n = len(robots)
        self._poses = np.array([r.start.as_array() for r in robots], dtype=np.float64)
        self._twists = np.zeros((n, 3))
        self._steering = np.zeros(n)
        self._commands = np.zeros((n, 3))
        self._radii = np.array([fp.radius for fp in self._footprints])
        self._fp_polys = tuple(polys)
        self._time = 0.0
        self._step = 0
        self._driver = pedestrians
        if pedestrians is not None:
            self._agents = pedestrians.reset(episode.agents, world, crowd_rng)
        else:
            self._agents = _standing_agents(episode)
        self._walked = np.zeros(len(self._agents))
        # the distance walked only feeds the legs' gait phase: not tracked for circle bodies
        self._track_walked = (
            self.params.pedestrians_block_lidar and self.params.pedestrian_body == "legs"
        )
        self._last_scan_time = [-math.inf] * n
        self._scans: list[NDArray[np.float64]] = [np.zeros(0)] * n
        collisions = self._contacts(self._poses)
        self._take_scans()
        self._state = self._snapshot(collisions)
        return self._state

    def _footprint(self, polygon: NDArray[np.float64] | None, radius: float) -> Footprint:
        """``Footprint.make(polygon, radius)``, the same object while the inputs are equal.

        ``polygon``: ``(k, 2)`` m in the robot frame, or ``None`` for a circle of ``radius`` m.
        """
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

    def step(self, commands: NDArray[np.float64], dt: float) -> SimState:
        """Advance the world by ``dt`` seconds with ``(r, 3)`` body-twist commands."""
        if self._state is None:
            raise SimulationError("step() called before reset()")
        n = len(self._names)
        cmd = np.asarray(commands, dtype=np.float64)
        if cmd.shape != (n, 3):
            raise SimulationError(
                f"commands must have shape ({n}, 3) [vx, vy, omega], got {cmd.shape}"
            )
        # math.isfinite over the few values: a fraction of the cost of np.isfinite(...).all()
        if not all(map(math.isfinite, cmd.ravel().tolist())):
            raise SimulationError(f"commands must be finite, got {cmd.tolist()}")
        if not dt > 0:
            raise SimulationError(f"dt must be > 0 s, got {dt}")
        # Pedestrians react to the robots as they were at the start of the step.
        if self._driver is not None:
            before = self._agents.positions
            self._agents = self._driver.step(self._state.robots, dt)
            if self._track_walked and self._agents.positions.shape == before.shape:
                self._walked = self._walked + np.hypot(*(self._agents.positions - before).T)

        new_poses = np.empty_like(self._poses)
        new_twists = np.empty_like(self._twists)
        new_steer = np.empty_like(self._steering)
        for i, kin in enumerate(self._kinematics):
            box = self._boxes[i]
            if box is not None:
                if not math.isfinite(dt):  # the check Kinematics.step would make
                    raise SimulationError(f"dt must be a finite number > 0, got {dt!r}")
                box_step_row(self._poses, self._twists, cmd, box, dt, i, new_poses, new_twists)
                new_steer[i] = 0.0  # box models have no steering
                continue
            s = kin.step(
                KinematicState(
                    self._poses[i : i + 1], self._twists[i : i + 1], self._steering[i : i + 1]
                ),
                cmd[i : i + 1],
                dt,
            )
            new_poses[i], new_twists[i], new_steer[i] = s.poses[0], s.twists[0], s.steering[0]

        collisions, touching = self._contact_flags(new_poses, self._poses)
        if self.params.collision_response == "stop" and touching:
            blocked = collisions.any
            new_poses[blocked] = self._poses[blocked]
            new_twists[blocked] = 0.0
            new_steer[blocked] = self._steering[blocked]
        self._poses, self._twists, self._steering = new_poses, new_twists, new_steer
        self._commands = cmd.copy()
        self._time += dt
        self._step += 1
        self._take_scans()
        self._state = self._snapshot(collisions)
        return self._state

    def teleport(self, robot: int, pose: Pose2D) -> SimState:
        """Move robot ``robot`` to ``pose`` at rest; time does not advance.

        The twist, steering angle and last command of the robot become zero; contacts are
        evaluated at the new pose (without a sweep) and the robot's lidar takes a fresh scan.

        Raises:
            SimulationError: before :meth:`reset`, for an unknown robot index or a non-finite
                pose.
        """
        if self._state is None:
            raise SimulationError("teleport() called before reset()")
        n = len(self._names)
        if not 0 <= robot < n:
            raise SimulationError(f"no robot {robot}: the episode has robots 0..{n - 1}")
        target = np.array([pose.x, pose.y, pose.theta], dtype=np.float64)
        if not np.all(np.isfinite(target)):
            raise SimulationError(f"teleport pose must be finite, got {target.tolist()}")
        self._poses = self._poses.copy()
        self._poses[robot] = target
        self._twists[robot] = 0.0
        self._steering[robot] = 0.0
        # not in place: the last snapshot holds this array (see _snapshot)
        self._commands = self._commands.copy()
        self._commands[robot] = 0.0
        # Every robot sees the moved one (multi-robot lidar), so all scans are taken afresh.
        self._last_scan_time = [-math.inf] * n
        self._take_scans()
        self._state = self._snapshot(self._contacts(self._poses))
        return self._state

    # -- internals -----------------------------------------------------------------------------
    def _contacts(
        self, poses: NDArray[np.float64], previous: NDArray[np.float64] | None = None
    ) -> Collisions:
        """Contacts of each robot at ``poses``.

        Walls are also checked along the way from ``previous``, so that a fast robot cannot
        tunnel through a thin wall in one step.
        """
        return self._contact_flags(poses, previous)[0]

    def _contact_flags(
        self, poses: NDArray[np.float64], previous: NDArray[np.float64] | None = None
    ) -> tuple[Collisions, bool]:
        """:meth:`_contacts` and whether any robot touches anything (``collisions.any.any()``).

        The flags are gathered in Python lists and turned into arrays once: for the usual one
        or two robots that is cheaper than filling preallocated arrays element by element.
        """
        world = self.world
        grid = world.grid
        n = poses.shape[0]
        wall = [False] * n
        obstacle = [-1] * n
        agent = [-1] * n
        robot = [-1] * n
        positions, radii = self._agents.positions, self._agents.radii
        for i, fp in enumerate(self._footprints):
            pose = poses[i]
            for p in _sweep(pose, None if previous is None else previous[i], fp, world):
                if hits_grid(grid, fp, p, bounds=self._grid_bounds):
                    wall[i] = True
                    break
            obstacle[i] = first_obstacle_hit(self._obstacles, fp, pose)
            agent[i] = first_agent_hit(fp, pose, positions, radii)
            for j in range(n):
                if j != i and footprints_overlap(fp, pose, self._footprints[j], poses[j]):
                    robot[i] = j
                    break
        touching = any(wall) or max(obstacle) >= 0 or max(agent) >= 0 or max(robot) >= 0
        collisions = Collisions(
            np.array(wall, dtype=bool),
            np.array(obstacle, dtype=np.int64),
            np.array(agent, dtype=np.int64),
            np.array(robot, dtype=np.int64),
        )
        return collisions, touching

    def _take_scans(self) -> None:
        if not self.params.lidar:
            self._scans = [np.full(s.num_beams, s.range_max) for s in self._specs]
            return
        n = len(self._names)
        agents = self._agents
        for i in range(n):
            # Hold the last scan until the sensor's period has elapsed (10 Hz lidar, faster sim).
            if self._time - self._last_scan_time[i] < self._scan_period[i] - 1e-9:
                continue
            self._last_scan_time[i] = self._time
            cx, cr, seg_a, seg_b = self._dynamic_geometry(i, agents)
            self._scans[i] = self._lidar[i].scan(
                self._poses[i],
                cx,
                cr,
                seg_a,
                seg_b,
                rng=self._rng if self._specs[i].noise_std > 0 else None,
            )

    def _dynamic_geometry(
        self, i: int, agents: AgentStates
    ) -> tuple[
        NDArray[np.float64],
        NDArray[np.float64],
        NDArray[np.float64] | None,
        NDArray[np.float64] | None,
    ]:
        """Circles and segments robot ``i`` sees besides the static world."""
        if self.params.pedestrians_block_lidar and self.params.pedestrian_body == "legs":
            cx, cr = self._legs(agents)
        elif self.params.pedestrians_block_lidar:
            cx, cr = agents.positions, agents.radii
        else:
            cx, cr = np.zeros((0, 2)), np.zeros(0)
        if len(self._names) == 1:
            return cx, cr, None, None
        circ_x, circ_r, seg_a, seg_b = [cx], [cr], [], []
        for j, fp in enumerate(self._footprints):
            if j == i:
                continue
            poly = fp.world_polygon(self._poses[j])
            if poly is None:
                circ_x.append(self._poses[j : j + 1, :2])
                circ_r.append(np.array([fp.radius]))
            else:
                seg_a.append(poly)
                seg_b.append(np.roll(poly, -1, axis=0))
        return (
            np.concatenate(circ_x),
            np.concatenate(circ_r),
            np.concatenate(seg_a) if seg_a else None,
            np.concatenate(seg_b) if seg_b else None,
        )

    def _legs(self, agents: AgentStates) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Two leg circles per pedestrian, swinging with a gait phase from the distance walked.

        Legs sit ``hip_half_width`` either side of the heading axis and swing in antiphase by
        ``stride_amplitude · min(1, speed / 1 m/s) · sin(phase)``; ``phase`` advances 2π per
        ``stride_length`` walked, so a lidar sees the scissor motion trackers rely on.
        """
        p = self.params
        n = len(agents)
        if self._walked.shape[0] != n:
            self._walked = np.zeros(n)
        phase = 2.0 * np.pi * self._walked / p.stride_length
        speed = np.hypot(agents.velocities[:, 0], agents.velocities[:, 1])
        swing = p.stride_amplitude * np.minimum(1.0, speed) * np.sin(phase)
        h = agents.headings
        fwd = np.stack([np.cos(h), np.sin(h)], axis=1)
        lat = np.stack([-np.sin(h), np.cos(h)], axis=1)
        left = agents.positions + p.hip_half_width * lat + swing[:, None] * fwd
        right = agents.positions - p.hip_half_width * lat - swing[:, None] * fwd
        return np.concatenate([left, right]), np.full(2 * n, p.leg_radius)

    def _snapshot(self, collisions: Collisions) -> SimState:
        robots = RobotStates(
            names=self._names,
            models=self._models,
            poses=self._poses.copy(),
            twists=self._twists.copy(),
            # a fresh array of this step (step and teleport replace it, never write into it)
            commands=self._commands,
            radii=self._radii.copy(),
            footprints=self._fp_polys,
            scans=(self._scans[0].copy(),)
            if len(self._scans) == 1
            else tuple(s.copy() for s in self._scans),
        )
        return SimState(self._time, self._step, robots, self._agents, collisions)


def _sweep(
    pose: NDArray[np.float64],
    previous: NDArray[np.float64] | None,
    fp: Footprint,
    world: StaticWorld,
) -> list[NDArray[np.float64]]:
    """Poses to test between ``previous`` and ``pose``.

    They are spaced so that consecutive footprints overlap by at least half a cell (no
    tunnelling through a one-cell wall).
    """
    if previous is None:
        return [pose]
    dist = math.hypot(pose[0] - previous[0], pose[1] - previous[1])
    spacing = max(world.grid.resolution * 0.5, fp.radius * 0.5)
    k = math.ceil(dist / spacing)
    if k <= 1:
        return [pose]
    t = np.linspace(0.0, 1.0, k + 1)[1:]
    dtheta = (pose[2] - previous[2] + math.pi) % (2 * math.pi) - math.pi
    return [
        np.array(
            [
                previous[0] + s * (pose[0] - previous[0]),
                previous[1] + s * (pose[1] - previous[1]),
                previous[2] + s * dtheta,
            ]
        )
        for s in t
    ]


def _standing_agents(episode: Episode) -> AgentStates:
    sp = episode.agents
    n = len(sp)
    return AgentStates(
        ids=np.arange(n, dtype=np.int64),
        positions=sp.positions.astype(np.float64, copy=True),
        velocities=np.zeros((n, 2)),
        headings=np.zeros(n),
        radii=sp.radii.astype(np.float64, copy=True),
        kinds=sp.kinds.astype(np.int64, copy=True),
        states=np.zeros(n, dtype=np.int64),
    )
