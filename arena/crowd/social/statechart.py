"""Arena's pedestrian social states as one vectorised statechart (crowdsim ``Human``).

Each agent carries three levels in ``[0, 1]`` (stress, energy, social) that drift every tick and
change with the current state; thresholds on them, perception and chance move the agent between
states (arena_specs §5.2, paper Table II)::

    rest:             WALKING (initial) ⇄ IDLE
    energy activity:  RUNNING, INTERACTING (approach a robot or an obstacle)
    social activity:  TALKING (pairs or groups gather and face each other), PHONE
    PANIC:            transient, one tick, then RUNNING

Transitions, evaluated every tick from the state at the start of the tick (one compiled
pass over the agents, :mod:`arena.crowd.social.kernels`):

* any → PANIC when ``stress > stress_hi`` (sets ``energy = max(energy, energy_hi)``,
  ``stress = stress_hi``); PANIC → RUNNING on the next tick.
* rest → TALKING when ``social ≥ social_hi`` and another agent is seen (the nearest one);
  rest → INTERACTING when ``energy ≥ energy_hi`` and a robot (preferred) or an obstacle point is
  seen; rest → PHONE with probability ``1 − (1 − max(0, social − social_hi))^dt``; rest →
  RUNNING with probability ``1 − (1 − max(0, energy − energy_hi))^dt`` (checked in this order).
* WALKING → IDLE when ``energy ≤ energy_lo``; IDLE → WALKING once energy has recovered to the
  middle of the band or something comes within 1.1 personal-space radii.
* RUNNING/INTERACTING → WALKING when ``energy ≤ energy_lo`` or the target is lost;
  TALKING/PHONE → WALKING when ``social ≤ social_lo`` or the partner is lost.

Every transition waits ``min_time_in_state`` except the PANIC → RUNNING transient and exits
because the target is lost (there is nothing left to do in the state).

Differences from Arena, on purpose:

* Vision is measured relative to the agent's heading (Arena: world-frame bearing).
* "Agent seen" / "obstacle seen" are evaluated every tick against current perception (Arena
  fires them once, when something enters view, and drops the event if a guard fails then, so
  two agents walking side by side never start talking however sociable they become).
* Obstacle targets are the nearest seen point of an obstacle's outline (Arena: its centre,
  which puts the approach spot inside large obstacles).
* Talking pairs gather at the mean of their two personal-space radii, so both agree on the
  distance (Arena: each its own radius, so a pair with different radii chases forever).
* Robot fear is a rate (see ``SocialStatesParams.fear_rate_hz``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import RobotView
from arena.crowd.social import kernels as K
from arena.crowd.social.params import (
    LEVEL_NAMES,
    SocialStatesParams,
    sample_agent_params,
)
from arena.crowd.social.perception import NEAR_FACTOR, Vision, wall_index_arrays
from arena.crowd.social.robots import robot_avoidance as _avoidance
from arena.crowd.social.robots import robot_fear
from arena.crowd.state import AgentType, CrowdState, SocialState
from arena.crowd.walls import WallIndex, grid_walls
from arena.maps.grid import OccupancyGrid
from arena.scene.state import StaticWorld

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

TARGET_NONE = K.TARGET_NONE
TARGET_AGENT = K.TARGET_AGENT
TARGET_ROBOT = K.TARGET_ROBOT
TARGET_POINT = K.TARGET_POINT


class _S:
    """:class:`SocialState` codes as plain ints (an enum member lookup costs ~1 µs on 3.11)."""

    IDLE = int(SocialState.IDLE)
    WALKING = int(SocialState.WALKING)
    RUNNING = int(SocialState.RUNNING)
    INTERACTING = int(SocialState.INTERACTING)
    TALKING = int(SocialState.TALKING)
    PHONE = int(SocialState.PHONE)
    PANIC = int(SocialState.PANIC)


_N_STATES = K.N_STATES
# The kernels use the SocialState codes as literals (numba cannot read _S's attributes).
assert (_S.IDLE, _S.WALKING, _S.RUNNING, _S.INTERACTING, _S.TALKING, _S.PHONE, _S.PANIC) == (
    K.IDLE, K.WALKING, K.RUNNING, K.INTERACTING, K.TALKING, K.PHONE, K.PANIC
)
# Where each per-agent parameter goes in the kernels' table (vision rows are filled at reset).
_TABLE_ROWS = {
    "d_stress": K.D_STRESS,
    "d_energy": K.D_ENERGY,
    "d_social": K.D_SOCIAL,
    "min_time_in_state": K.MIN_TIME,
    "energy_lo": K.ENERGY_LO,
    "energy_hi": K.ENERGY_HI,
    "social_lo": K.SOCIAL_LO,
    "social_hi": K.SOCIAL_HI,
    "stress_hi": K.STRESS_HI,
    "personal_space_radius": K.PSR,
    "fear_robot": K.FEAR_ROBOT,
    "fear_robot_speed_tolerance": K.FEAR_TOLERANCE,
}
# Per-state level rates come from these parameter prefixes; PANIC lasts one tick and uses the
# running rates (Arena has no panic rates: the panic state is left at once).
_RATE_PREFIX = {
    _S.IDLE: "idle",
    _S.WALKING: "walking",
    _S.RUNNING: "running",
    _S.INTERACTING: "interacting",
    _S.TALKING: "talking",
    _S.PHONE: "phone",
    _S.PANIC: "running",
}


_WALL_CACHE: list[tuple[FloatArray, WallIndex | None]] = []
"""The last map's wall index (at most one entry): see :func:`_grid_wall_index`."""


def _grid_wall_index(grid: OccupancyGrid) -> WallIndex | None:
    """The wall index of ``grid`` (``None`` without walls), reused while the map stays the same.

    An RL env builds a fresh crowd (so a fresh :class:`SocialStates`) every reset, mostly on
    the same map; :func:`~arena.crowd.walls.grid_walls` returns the same segment arrays
    while the map is unchanged, and a :class:`WallIndex` is read-only once built.
    """
    wa, wb = grid_walls(grid)
    if _WALL_CACHE and _WALL_CACHE[0][0] is wa:
        return _WALL_CACHE[0][1]
    index = WallIndex(wa, wb) if wa.shape[0] else None
    _WALL_CACHE[:] = [(wa, index)]
    return index


class SocialStates:
    """The social-state statechart for a whole crowd (struct of arrays, index ``i``).

    Called by :class:`~arena.crowd.simulator.CrowdSimulator` each step: :meth:`pre` after the
    default destinations are set and before the crowd model, :meth:`post` on the model's
    accelerations, :meth:`orient` after integration. :meth:`reset` once per episode, on the
    fresh :class:`CrowdState`: it samples every agent's parameters from the episode's crowd
    generator (all later random draws come from the same generator). Elders' slower walking
    (pedsim's ×0.7) is applied by the crowd simulator, so it holds with social states off too.

    Args:
        params: statechart parameters (defaults: Arena's).
    """

    Params = SocialStatesParams

    def __init__(self, params: SocialStatesParams | None = None) -> None:
        self.params = params or SocialStatesParams()
        f = self.params.human.vmax_factors
        # vmax factor by state code (talking/interacting: approach until gathered)
        self._vmax_table = np.array(
            [f.idle, f.walking, f.running, f.approach, f.approach, f.phone, f.panic]
        )
        # Float settings of the pre kernel: set at reset, the dt entries every tick.
        self._settings = np.zeros(K.N_SETTINGS)
        self._no_fear = np.zeros(0)
        self._no_avoid = np.zeros((0, 2))
        self._init_arrays(0)
        self._rng = np.random.default_rng(0)
        self._obstacles: WallIndex | None = None
        self._walls: WallIndex | None = None

    # -- introspection --------------------------------------------------------------------------
    @property
    def agent_params(self) -> dict[str, FloatArray]:
        """``name -> (n,)`` the per-agent parameters drawn at reset (vision_angle in degrees)."""
        return self._p

    @property
    def time_in_state(self) -> FloatArray:
        """``(n,)`` s spent in the current state (as of the last :meth:`pre`)."""
        return self._t_in

    @property
    def target_kind(self) -> IntArray:
        """``(n,)`` ``TARGET_NONE`` / ``TARGET_AGENT`` / ``TARGET_ROBOT`` / ``TARGET_POINT``."""
        return self._kind

    @property
    def target_index(self) -> IntArray:
        """``(n,)`` index of the partner agent or robot (-1 when none)."""
        return self._tidx

    @property
    def target_point(self) -> FloatArray:
        """``(n, 2)`` m, the obstacle point of ``TARGET_POINT`` targets (NaN otherwise)."""
        return self._tpoint

    @property
    def gathered(self) -> BoolArray:
        """``(n,)`` talking/interacting agents standing at their spot (as of the last pre)."""
        return self._gathered

    @property
    def vision(self) -> Vision:
        """Per-agent perception parameters."""
        return self._vision

    # -- lifecycle ------------------------------------------------------------------------------
    def _init_arrays(self, n: int) -> None:
        self._p: dict[str, FloatArray] = {}
        self._table = np.zeros((K.N_ROWS, n))
        self._rates = np.zeros((n, _N_STATES, 3))
        self._t_in = np.zeros(n)
        self._kind = np.zeros(n, dtype=np.int64)
        self._tidx = np.full(n, -1, dtype=np.int64)
        self._tpoint = np.full((n, 2), np.nan)
        self._conv = np.full(n, -1, dtype=np.int64)
        self._gathered = np.zeros(n, dtype=bool)
        self._avoid = np.zeros((n, 2))
        self._robot_pos = np.zeros((0, 2))
        self._obstacle_arrays = self._wall_arrays = wall_index_arrays(None)
        t = self._table
        self._vision = Vision(t[K.VISION_RANGE], t[K.VISION_HALF_ANGLE], t[K.VISION_NEAR])

    def reset(self, state: CrowdState, world: StaticWorld | None, rng: np.random.Generator) -> None:
        """Start an episode: sample parameters, everyone WALKING.

        Args:
            state: the episode's fresh crowd (mutated: ``social_state``,
                ``vmax_factor``, levels clipped to [0, 1]).
            world: the static world (placed obstacles and walls as interaction targets).
            rng: the crowd's generator; kept for the per-tick draws.
        """
        n = len(state)
        self._init_arrays(n)
        self._rng = rng
        is_elder = np.asarray(state.kinds) == AgentType.ELDER
        self._p = sample_agent_params(self.params, is_elder, rng)
        p = self._p
        for code, prefix in _RATE_PREFIX.items():
            for k, level in enumerate(LEVEL_NAMES):
                self._rates[:, int(code), k] = p[f"{prefix}_d_{level}"]
        self._fill_table()
        prm, settings = self.params, self._settings
        settings[K.C_IDLE_RECOVERY] = prm.idle_recovery
        settings[K.C_GATHER_TOL] = prm.gather_tolerance
        settings[K.C_VF_TALKING] = prm.human.vmax_factors.talking
        settings[K.C_VF_INTERACTING] = prm.human.vmax_factors.interacting
        state.social_state[:] = int(_S.WALKING)
        state.vmax_factor[:] = self.params.human.vmax_factors.walking
        for name in LEVEL_NAMES:
            np.clip(getattr(state, name), 0.0, 1.0, out=getattr(state, name))
        self._obstacles = None
        self._walls = None
        if world is not None:
            if world.segments_a.shape[0]:
                self._obstacles = WallIndex(world.segments_a, world.segments_b)
            if self.params.interact_with_walls:
                self._walls = _grid_wall_index(world.grid)
        self._obstacle_arrays = wall_index_arrays(self._obstacles)
        self._wall_arrays = wall_index_arrays(self._walls)

    def _fill_table(self) -> None:
        """Copy the drawn parameters and the vision into the kernels' ``(N_ROWS, n)`` table.

        The parameter dict and :attr:`vision` then hold views of its rows, so that whatever
        changes one (a test tuning an agent) changes what the kernels read.
        """
        p, t = self._p, self._table
        for name, row in _TABLE_ROWS.items():
            t[row] = p[name]
            p[name] = t[row]
        t[K.VISION_RANGE] = p["vision_range"]
        p["vision_range"] = t[K.VISION_RANGE]
        t[K.VISION_HALF_ANGLE] = np.deg2rad(p["vision_angle"])
        t[K.VISION_NEAR] = NEAR_FACTOR * p["personal_space_radius"]
        self._vision = Vision(t[K.VISION_RANGE], t[K.VISION_HALF_ANGLE], t[K.VISION_NEAR])

    # -- step: before the model -----------------------------------------------------------------
    def pre(
        self, state: CrowdState, robots: RobotView, world: StaticWorld | None, dt: float
    ) -> None:
        """Advance levels and states by ``dt`` s; set destinations and vmax factors.

        Mutates ``state.stress/energy/social``, ``state.social_state``, ``state.vmax_factor``
        and, for talking and interacting agents, ``state.destinations``.

        Args:
            state: the crowd.
            robots: the robots as pedestrians see them.
            world: unused (obstacle indices are built at reset); kept for the hook signature.
            dt: step length (s).
        """
        n = len(state)
        if n == 0:
            return
        if self._t_in.shape[0] != n:
            raise RuntimeError("SocialStates.pre called with a crowd it was not reset for")
        prm = self.params
        robot_pos = np.array(robots.positions, dtype=np.float64).reshape(-1, 2)
        robot_vel = np.ascontiguousarray(robots.velocities, dtype=np.float64).reshape(-1, 2)
        fear = self._no_fear
        if robot_pos.shape[0] > K.MAX_SEQUENTIAL_ROBOTS:  # numpy sums these pairwise
            p = self._p
            fear = robot_fear(
                state.positions,
                p["personal_space_radius"],
                p["fear_robot"],
                p["fear_robot_speed_tolerance"],
                robots,
            )
        # Drawn for every agent every tick, so the stream does not depend on who is eligible;
        # nothing else draws from this generator during a tick.
        u = self._rng.random((n, 2))
        settings = self._settings
        settings[K.C_DT] = dt
        settings[K.C_FEAR_SCALE] = dt * prm.fear_rate_hz
        K.pre_tick(
            state.positions, state.headings, state.social_state, state.stress, state.energy,
            state.social, state.destinations, state.vmax_factor, self._table, self._rates,
            self._t_in, self._kind, self._tidx, self._tpoint, self._conv, self._gathered,
            robot_pos, robot_vel, fear, u, self._obstacle_arrays, self._wall_arrays, settings,
            self._vmax_table, prm.interested_in_robots, prm.wake_on_approach,
        )
        self._robot_pos = robot_pos
        if prm.robot_avoidance.enabled:
            self._avoid = self.robot_avoidance(state, robots)

    # -- step: after the model ------------------------------------------------------------------
    def post(self, state: CrowdState, accelerations: FloatArray, dt: float) -> FloatArray:
        """Override the model's accelerations where a state demands it.

        In order: at the destination (within ``at_destination_radius``) Arena's residual
        ``at_destination_force · unit(a)`` with ``vmax_factor ≤ at_destination_vmax_factor``;
        then the robot-avoidance term is added (when enabled; also stored in
        ``state.forces["robot_avoidance"]``); agents whose vmax factor is 0 (idle, gathered
        talkers and interactors) get ``−v/dt`` so they stand still this step.

        Args:
            state: the crowd (``vmax_factor`` may be lowered).
            accelerations: ``(n, 2)`` m/s² from the crowd model (not mutated).
            dt: step length (s).

        Returns:
            ``(n, 2)`` m/s², the accelerations to integrate.
        """
        a = np.array(accelerations, dtype=np.float64, copy=True).reshape(-1, 2)
        n = a.shape[0]
        if n == 0:
            return a
        prm = self.params
        # The robot's push is added after the at-destination rule: it replaces the model's
        # pull, not the robot's push.
        add = prm.robot_avoidance.enabled and self._avoid.shape[0] == n
        K.post_tick(
            a, state.destinations, state.positions, state.velocities, state.vmax_factor,
            self._avoid if add else self._no_avoid, prm.at_destination_radius,
            prm.at_destination_force, prm.at_destination_vmax_factor, dt,
        )
        if add:
            state.forces["robot_avoidance"] = self._avoid.copy()
        return a

    def robot_avoidance(self, state: CrowdState, robots: RobotView) -> FloatArray:
        """``(n, 2)`` m/s², the Table II robot-avoidance repulsion (see RobotAvoidanceParams).

        Computed for every agent whatever ``enabled`` says, so a simulator may add it itself.
        """
        if len(state) == 0:
            return np.zeros((0, 2))
        return _avoidance(
            state.positions,
            state.radii,
            self._p["personal_space_radius"],
            robots,
            self.params.robot_avoidance,
        )

    # -- step: after integration ----------------------------------------------------------------
    def orient(self, state: CrowdState) -> None:
        """Turn standing talkers toward their group's centre, interacting agents to the target.

        A talker whose conversation has at least two talking members faces the members' mean
        position (for a pair: the partner); otherwise it faces its partner. Only agents that
        have gathered at their spot are turned; others keep the heading the simulator gave them.
        """
        n = len(state)
        if n == 0:
            return
        # only gathered talkers and interactors are turned (count_nonzero: cheaper than any)
        if not np.count_nonzero(self._gathered):
            return
        turn, dy, dx = K.orient_look(
            state.positions, state.social_state, self._kind, self._tidx, self._tpoint,
            self._conv, self._gathered, self._robot_pos,
        )
        if turn.shape[0]:
            # numpy's arctan2, not the kernel's libm one: they may differ in the last bit
            state.headings[turn] = np.arctan2(dy, dx)
