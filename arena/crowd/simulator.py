"""The crowd simulator: owns the pedestrians and moves them with a crowd model.

It is the native2d backend's :class:`~arena.sim.backend.PedestrianDriver`. One step:

1. start-up modes (``wait_timer``, ``trigger_zone``) release waiting agents;
2. waypoints advance with Arena's tolerant switch (an agent within ``waypoint_tolerance`` of its
   waypoint takes the next one at once, so it never circles its goal);
3. destinations: own waypoint, or, for group members, the leader's waypoint offset on a ring
   (Arena's group fix), then social states may redirect them (talking, interacting);
4. the crowd model returns accelerations (or velocities) from one :class:`CrowdFrame`;
5. social states post-process the accelerations (standing still, arriving gently);
6. one integrator: ``v += a·dt``, hard cap ``|v| ≤ vmax·vmax_factor``, ``p += v·dt``, with
   walls as hard constraints (:mod:`arena.crowd.integrator`).
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.records import frozen_record
from arena.crowd.base import CrowdFrame, CrowdModel, RobotView
from arena.crowd.clearance import crowd_clearance
from arena.crowd.integrator import integrate_guarded, wall_guard
from arena.crowd.neighbors import find_neighbors
from arena.crowd.social import SocialStates
from arena.crowd.state import CrowdState, StartupMode, leaders_of
from arena.crowd.walls import WallIndex, grid_walls
from arena.maps.distance import grid_memo
from arena.scene.episode import WAYPOINT_RANDOM, AgentSpawn
from arena.scene.state import AgentStates, RobotStates, StaticWorld

FloatArray = NDArray[np.float64]


class PedestrianConfig(BaseModel):
    """How pedestrians behave beyond their motion model (the config's ``pedestrians:`` block)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    social_states: bool = Field(True, description="run Arena's human statechart")
    initial_levels: Literal["arena", "random"] = Field(
        "arena",
        description="'arena': stress 0, energy and social 0.5 for everyone (Arena); 'random': "
        "uniform in [0, 1] per agent, so a short episode already shows every social state",
    )
    waypoint_tolerance: float = Field(
        0.5, gt=0, description="m, a waypoint counts as reached within this distance (Arena fix #2)"
    )
    group_fraction: float = Field(
        0.3, ge=0, le=1, description="share of agents put into groups when the episode gives none"
    )
    max_group_size: int = Field(3, ge=2, description="largest group formed automatically")
    group_radius: float = Field(3.0, gt=0, description="m, groups form among agents this close")
    group_offset: float = Field(
        0.5, ge=0, description="m, ring spacing of members around the leader's waypoint (Arena)"
    )
    wall_clearance: float = Field(
        1.0,
        ge=0,
        le=1,
        description="pedestrian centres keep this fraction of their radius "
        "from walls, a hard constraint in the integrator (1: bodies never overlap walls)",
    )
    elder_speed_factor: float = Field(
        0.7, gt=0, le=1, description="elders walk at this fraction of their vmax (pedsim)"
    )


class CrowdSimulator:
    """Moves pedestrians with a registered crowd model; implements ``PedestrianDriver``.

    Args:
        model: the crowd model (an entry of :data:`~arena.crowd.base.CROWD_MODELS`).
        config: pedestrian behaviour settings.
    """

    def __init__(self, model: CrowdModel, config: PedestrianConfig | None = None) -> None:
        self.model = model
        self.config = config or PedestrianConfig()
        self.social: Any = None
        self._state: CrowdState | None = None

    @property
    def state(self) -> CrowdState:
        """The crowd's current state (read it, do not modify it)."""
        if self._state is None:
            raise RuntimeError("CrowdSimulator used before reset()")
        return self._state

    # -- PedestrianDriver -----------------------------------------------------------------------
    def reset(self, spawn: AgentSpawn, world: StaticWorld, rng: np.random.Generator) -> AgentStates:
        """Place the episode's pedestrians and prepare the model and social states."""
        cfg = self.config
        self._rng = rng
        self._world = world
        state = CrowdState.from_spawn(spawn)
        elder = state.kinds == 1
        state.vmax = np.where(elder, state.vmax * cfg.elder_speed_factor, state.vmax)
        if spawn.groups is None and len(state) > 1 and cfg.group_fraction > 0:
            state.group = form_groups(state.positions, cfg, rng)
            state.leader = leaders_of(state.group)
        self._walls_a, self._walls_b = episode_segments(world)
        # WallIndex(walls_a, walls_b): the map's part indexed once per map
        grid_index = grid_memo(world.grid, "crowd wall index", lambda: _grid_wall_index(world))
        self._wall_index = grid_index.extended(world.segments_a, world.segments_b)
        # Distance from each cell to the nearest wall, obstacle or map edge, for the wall
        # guard's fast path (agents far from everything skip the exact segment test).
        self._clearance = crowd_clearance(world.grid, [o.polygon for o in world.obstacles])
        # The integrator's wall arguments, gathered once per episode.
        self._guard = wall_guard(
            self._wall_index, self._clearance, world.grid.origin, world.grid.resolution
        )
        self._state = state
        self._rows = np.arange(len(state))
        self._members = np.flatnonzero(state.leader != self._rows)
        rank = _member_rank(state.group, state.leader)
        self._offsets = self._ring_offsets(rank[self._members], cfg.group_offset)
        self.model.reset(state, world, rng)
        if cfg.initial_levels == "random":
            state.stress, state.energy, state.social = rng.random((3, len(state)))
        if cfg.social_states:
            self.social = SocialStates()
            self.social.reset(state, world, rng)
        self._update_destinations()
        return self._snapshot(state)

    def step(self, robots: RobotStates, dt: float) -> AgentStates:
        """Advance the crowd by ``dt`` seconds, seeing ``robots``."""
        s = self.state
        if len(s) == 0:
            s.time += dt
            return self._snapshot(s)
        view = robot_view(robots)
        # The helpers take the state from here: one property check per step.
        self._start_up(s, view)
        self._advance_waypoints(s)
        if self.social is not None:
            self.social.pre(s, view, self._world, dt)
        active = s.started.copy()
        neighbors = find_neighbors(s.positions, self.model.neighbor_cutoff())
        frame = frozen_record(  # CrowdFrame(...) without its slower generated __init__
            CrowdFrame,
            state=s,
            destinations=s.destinations.copy(),
            active=active,
            robots=view,
            walls_a=self._walls_a,
            walls_b=self._walls_b,
            neighbors=neighbors,
            dt=dt,
            rng=self._rng,
        )
        out = self.model.compute(frame)
        if self.model.output == "velocity":
            if out.velocities is None:
                raise RuntimeError(f"{type(self.model).__name__} returned no velocities")
            update = np.asarray(out.velocities, dtype=np.float64)
            if self.social is not None:
                # Only for its vmax-factor side effects (arriving, standing): the cap in the
                # integrator then stops velocity models too.
                self.social.post(s, np.zeros_like(update), dt)
        else:
            if out.accelerations is None:
                raise RuntimeError(f"{type(self.model).__name__} returned no accelerations")
            update = np.asarray(out.accelerations, dtype=np.float64)
            if self.social is not None:
                update = self.social.post(s, update, dt)
        s.positions, v = integrate_guarded(
            self._guard,
            s.positions,
            s.velocities,
            update,
            self.model.output == "velocity",
            active,
            s.vmax,
            s.radii,
            dt,
            vmax_factor=s.vmax_factor,  # after post: it may lower the factors
            clearance_scale=self.config.wall_clearance,
        )
        s.velocities = v
        # NumPy's arctan2 on these strided views, as always (its SIMD and scalar paths differ).
        headings = np.empty(v.shape[0])  # allocated here: cheaper than boxing a returned array
        _face_motion(v, np.arctan2(v[:, 1], v[:, 0]), s.headings, headings)
        s.headings = headings
        if self.social is not None:
            self.social.orient(s)
        s.forces = out.forces
        s.time += dt
        return self._snapshot(s)

    # -- steps ----------------------------------------------------------------------------------
    def _start_up(self, s: CrowdState, robots: RobotView) -> None:
        # The common case once every agent has started (count_nonzero: a fraction of the cost
        # of .all() on a few dozen flags).
        if np.count_nonzero(s.started) == s.started.shape[0]:
            return
        waiting = ~s.started
        timer = waiting & (s.startup_mode == StartupMode.WAIT_TIMER) & (s.time >= s.wait_time)
        trigger = np.zeros_like(waiting)
        zone = waiting & (s.startup_mode == StartupMode.TRIGGER_ZONE)
        if zone.any() and len(robots):
            d = np.hypot(
                *(s.positions[zone, None, :] - robots.positions[None, :, :]).transpose(2, 0, 1)
            )
            trigger[zone] = np.any(d <= s.trigger_radius[zone, None], axis=1)
        s.started = s.started | timer | trigger

    def _advance_waypoints(self, s: CrowdState) -> None:
        """Tolerant switch, then destinations (see :meth:`_update_destinations`).

        Leaders and loners within tolerance of their waypoint take the next. Usually nobody
        arrives, and the destinations computed with the arrival test stand.
        """
        n = s.positions.shape[0]
        # outputs allocated here: cheaper than boxing arrays a compiled function returns
        arrived = np.empty(n, dtype=np.bool_)
        dest = np.empty((n, 2))
        _arrivals(
            s.positions,
            s.waypoints,
            s.waypoint_index,
            s.leader,
            s.started,
            s.radii,
            self.config.waypoint_tolerance,
            self._members,
            self._offsets,
            arrived,
            dest,
        )
        if not np.count_nonzero(arrived):
            s.destinations = dest
            return
        nwp = s.num_waypoints
        nxt = (s.waypoint_index + 1) % nwp
        rand = arrived & (s.waypoint_mode == WAYPOINT_RANDOM) & (nwp > 1)
        if rand.any():
            shift = self._rng.integers(1, nwp[rand])
            nxt[rand] = (s.waypoint_index[rand] + shift) % nwp[rand]
        s.waypoint_index = np.where(arrived, nxt, s.waypoint_index)
        self._update_destinations()

    def _update_destinations(self) -> None:
        """Own waypoint for leaders and loners; the leader's, offset on a ring, for members."""
        s = self.state
        dest = np.empty((s.waypoints.shape[0], 2))
        _destinations(s.waypoints, s.waypoint_index, s.leader, self._members, self._offsets, dest)
        s.destinations = dest

    @staticmethod
    def _ring_offsets(rank: NDArray[np.int64], spacing: float) -> FloatArray:
        """Slots around the leader's waypoint: ring i holds 6·i members at radius i·spacing."""
        ring = np.maximum(np.ceil((np.sqrt(1 + 4 * rank / 3) - 1) / 2).astype(np.int64), 1)
        slot = rank - (3 * ring * (ring - 1) + 1)
        angle = 2 * np.pi * slot / (6 * ring)
        r = ring * spacing
        return np.stack([r * np.cos(angle), r * np.sin(angle)], axis=1)

    def _snapshot(self, s: CrowdState) -> AgentStates:
        return frozen_record(
            AgentStates,
            ids=s.ids.copy(),
            positions=s.positions.copy(),
            velocities=s.velocities.copy(),
            headings=s.headings.copy(),
            radii=s.radii.copy(),
            kinds=s.kinds.copy(),
            states=s.social_state.copy(),
        )


def _grid_wall_index(world: StaticWorld) -> WallIndex:
    """The :class:`WallIndex` of the map's walls alone (shared by the map's episodes)."""
    return WallIndex(*grid_walls(world.grid))


def episode_segments(world: StaticWorld) -> tuple[FloatArray, FloatArray]:
    """:func:`~arena.crowd.walls.world_segments` of ``world``, the map's part cached."""
    ga, gb = grid_walls(world.grid)
    return np.concatenate([ga, world.segments_a]), np.concatenate([gb, world.segments_b])


def robot_view(robots: RobotStates) -> RobotView:
    """Robots as pedestrians perceive them: world-frame positions and velocities."""
    if len(robots) == 0:
        return RobotView.empty()
    th = robots.poses[:, 2]
    # NumPy's cos and sin (their SIMD results are what the crowd has always seen); the
    # rotation, and copies of the poses, in one compiled call.
    cos, sin = np.cos(th), np.sin(th)
    # Outputs allocated here: cheaper than boxing arrays a numba function returns.
    r = th.shape[0]
    view = frozen_record(
        RobotView, positions=np.empty((r, 2)), headings=np.empty(r),
        velocities=np.empty((r, 2)), radii=robots.radii.copy(),
    )
    _robot_frame(robots.poses, robots.twists, cos, sin, view.positions, view.headings,
                 view.velocities)
    return view


@njit(cache=True)
def _robot_frame(
    poses: FloatArray,
    twists: FloatArray,
    cos: FloatArray,
    sin: FloatArray,
    pos: FloatArray,
    heading: FloatArray,
    vel: FloatArray,
) -> None:
    """Robot positions, headings and world-frame velocities from poses and body-frame twists.

    Args:
        poses: ``(r, 3)`` ``(x, y, θ)`` (m, rad).
        twists: ``(r, ≥ 2)`` body-frame velocities (m/s).
        cos: ``(r,)`` ``cos θ``.
        sin: ``(r,)`` ``sin θ``.
        pos: ``(r, 2)`` out: positions (m).
        heading: ``(r,)`` out: headings (rad).
        vel: ``(r, 2)`` out: world-frame velocities (m/s).
    """
    r = poses.shape[0]
    for k in range(r):
        pos[k, 0] = poses[k, 0]
        pos[k, 1] = poses[k, 1]
        heading[k] = poses[k, 2]
        vx = twists[k, 0]
        vy = twists[k, 1]
        vel[k, 0] = cos[k] * vx - sin[k] * vy
        vel[k, 1] = sin[k] * vx + cos[k] * vy


@njit(cache=True)
def _arrivals(
    positions: FloatArray,
    waypoints: FloatArray,
    waypoint_index: NDArray[np.int64],
    leader: NDArray[np.int64],
    started: NDArray[np.bool_],
    radii: FloatArray,
    tolerance: float,
    members: NDArray[np.int64],
    offsets: FloatArray,
    arrived: NDArray[np.bool_],
    dest: FloatArray,
) -> None:
    """Leaders and loners that have reached their waypoint, and :func:`_destinations`.

    Reached: started and within ``max(tolerance, radius)`` (m) of the waypoint; ``hypot`` is
    libm's, as NumPy's, so the test is the NumPy expression's to the bit.

    Args:
        positions: ``(n, 2)`` m.
        waypoints: ``(n, K, 2)`` m.
        waypoint_index: ``(n,)`` the waypoint each agent walks to.
        leader: ``(n,)`` group leader index (itself for leaders and loners).
        started: ``(n,)`` bool.
        radii: ``(n,)`` m.
        tolerance: m.
        members: ``(g,)`` the agents that follow a leader.
        offsets: ``(g, 2)`` their ring offsets (m).
        arrived: ``(n,)`` bool, written: reached.
        dest: ``(n, 2)`` m, written: the destinations for the current waypoints (stale for
            the agents that arrived).
    """
    n = positions.shape[0]
    for i in range(n):
        arrived[i] = False
        if leader[i] != i or not started[i]:
            continue
        k = waypoint_index[i]
        r = radii[i]
        tol = r if (r > tolerance or r != r) else tolerance  # np.maximum: NaN wins
        d = math.hypot(positions[i, 0] - waypoints[i, k, 0], positions[i, 1] - waypoints[i, k, 1])
        arrived[i] = d < tol
    _destinations(waypoints, waypoint_index, leader, members, offsets, dest)


@njit(cache=True)
def _destinations(
    waypoints: FloatArray,
    waypoint_index: NDArray[np.int64],
    leader: NDArray[np.int64],
    members: NDArray[np.int64],
    offsets: FloatArray,
    dest: FloatArray,
) -> None:
    """Each agent's current waypoint; group members take their leader's plus a ring offset.

    Args:
        waypoints: ``(n, K, 2)`` m.
        waypoint_index: ``(n,)``.
        leader: ``(n,)`` group leader index.
        members: ``(g,)`` the agents that follow a leader.
        offsets: ``(g, 2)`` their ring offsets (m).
        dest: ``(n, 2)`` m, written.
    """
    n = waypoints.shape[0]
    for i in range(n):
        k = waypoint_index[i]
        dest[i, 0] = waypoints[i, k, 0]
        dest[i, 1] = waypoints[i, k, 1]
    for q in range(members.shape[0]):  # leaders are never members: their rows are final
        m = members[q]
        dest[m, 0] = dest[leader[m], 0] + offsets[q, 0]
        dest[m, 1] = dest[leader[m], 1] + offsets[q, 1]


@njit(cache=True)
def _face_motion(
    velocities: FloatArray, angles: FloatArray, headings: FloatArray, out: FloatArray
) -> None:
    """Headings after a step: the motion's direction for agents faster than 1 mm/s.

    Args:
        velocities: ``(n, 2)`` m/s.
        angles: ``(n,)`` their directions (rad).
        headings: ``(n,)`` the previous headings (rad).
        out: ``(n,)`` rad, written: the new headings.
    """
    for i in range(out.shape[0]):
        moving = math.hypot(velocities[i, 0], velocities[i, 1]) > 1e-3  # libm's, as NumPy's
        out[i] = angles[i] if moving else headings[i]


def form_groups(
    positions: FloatArray, cfg: PedestrianConfig, rng: np.random.Generator
) -> NDArray[np.int64]:
    """Group ids (-1 alone): random seeds pull their nearest ungrouped neighbours in.

    About ``group_fraction`` of the agents end up in groups of 2..``max_group_size``, formed
    among agents within ``group_radius`` of the group's first member (people who walk together
    start together). Runs once per episode.
    """
    n = positions.shape[0]
    groups = np.full(n, -1, dtype=np.int64)
    target = round(cfg.group_fraction * n)
    near = find_neighbors(positions, cfg.group_radius)
    placed, gid = 0, 0
    for i in rng.permutation(n):  # once per episode, over group seeds only
        if placed >= target:
            break
        if groups[i] >= 0:
            continue
        cand = near.of(int(i))
        cand = cand[groups[cand] < 0]
        if cand.size == 0:
            continue
        size = int(rng.integers(2, cfg.max_group_size + 1))
        dist = np.hypot(*(positions[cand] - positions[i]).T)
        take = cand[np.lexsort((cand, dist))[: size - 1]]
        groups[i] = gid
        groups[take] = gid
        placed += 1 + take.size
        gid += 1
    return groups


def _member_rank(group: NDArray[np.int64], leader: NDArray[np.int64]) -> NDArray[np.int64]:
    """0 for leaders and loners; 1, 2, … for the members of each group in index order."""
    n = group.shape[0]
    rank = np.zeros(n, dtype=np.int64)
    members = np.flatnonzero(leader != np.arange(n))
    if members.size:
        order = members[np.argsort(group[members], kind="stable")]
        g = group[order]
        start = np.r_[0, np.flatnonzero(np.diff(g)) + 1]
        counts = np.diff(np.r_[start, g.size])
        rank[order] = np.arange(g.size) - np.repeat(start, counts) + 1
    return rank
