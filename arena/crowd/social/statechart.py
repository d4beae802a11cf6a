"""Arena's pedestrian social states as one vectorised statechart (crowdsim ``Human``).

Each agent carries three levels in ``[0, 1]`` (stress, energy, social) that drift every tick and
change with the current state; thresholds on them, perception and chance move the agent between
states (arena_specs §5.2, paper Table II)::

    rest:             WALKING (initial) ⇄ IDLE
    energy activity:  RUNNING, INTERACTING (approach a robot or an obstacle)
    social activity:  TALKING (pairs or groups gather and face each other), PHONE
    PANIC:            transient, one tick, then RUNNING

Transitions, evaluated every tick from the state at the start of the tick (masks, no loops):

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

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.base import RobotView
from arena.crowd.neighbors import CellList
from arena.crowd.social.params import (
    LEVEL_NAMES,
    SocialStatesParams,
    sample_agent_params,
)
from arena.crowd.social.perception import (
    NEAR_FACTOR,
    Vision,
    nearest_seen_agents,
    nearest_seen_robots,
    nearest_seen_wall_points,
    sees,
)
from arena.crowd.social.robots import robot_avoidance as _avoidance
from arena.crowd.social.robots import robot_fear
from arena.crowd.state import AgentType, CrowdState, SocialState
from arena.crowd.walls import WallIndex
from arena.maps.grid import OccupancyGrid
from arena.sim.state import StaticWorld

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

TARGET_NONE = 0
TARGET_AGENT = 1
TARGET_ROBOT = 2
TARGET_POINT = 3


class _S:
    """:class:`SocialState` codes as plain ints (an enum member lookup costs ~1 µs on 3.11)."""

    IDLE = int(SocialState.IDLE)
    WALKING = int(SocialState.WALKING)
    RUNNING = int(SocialState.RUNNING)
    INTERACTING = int(SocialState.INTERACTING)
    TALKING = int(SocialState.TALKING)
    PHONE = int(SocialState.PHONE)
    PANIC = int(SocialState.PANIC)


_N_STATES = 7
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


def _unit(v: FloatArray, fallback: FloatArray) -> FloatArray:
    """Row-wise unit vectors of ``(m, 2)`` ``v``; ``fallback`` rows where ``v`` is ~0."""
    norm = np.hypot(v[:, 0], v[:, 1])
    ok = norm > 1e-12
    out = fallback.copy()
    out[ok] = v[ok] / norm[ok, None]
    return out


_WALL_CACHE: list[tuple[FloatArray, WallIndex | None]] = []
"""The last map's wall index (at most one entry): see :func:`_grid_wall_index`."""


def _grid_wall_index(grid: OccupancyGrid) -> WallIndex | None:
    """The wall index of ``grid`` (``None`` without walls), reused while the map stays the same.

    An RL env builds a fresh crowd (so a fresh :class:`SocialStates`) every reset, mostly on
    the same map; :func:`~arena.crowd.simulator.grid_walls` returns the same segment arrays
    while the map is unchanged, and a :class:`WallIndex` is read-only once built.
    """
    from arena.crowd.simulator import grid_walls  # the simulator imports this module lazily

    wa, wb = grid_walls(grid)
    if _WALL_CACHE and _WALL_CACHE[0][0] is wa:
        return _WALL_CACHE[0][1]
    index = WallIndex(wa, wb) if wa.shape[0] else None
    _WALL_CACHE[:] = [(wa, index)]
    return index


# The kernels below use the SocialState codes as literals (numba cannot read _S's attributes).
assert (_S.IDLE, _S.WALKING, _S.RUNNING, _S.INTERACTING, _S.TALKING, _S.PHONE, _S.PANIC) == (
    0, 1, 2, 3, 4, 5, 6
)


# -- the per-agent state machine ------------------------------------------------------------------
# Element-wise transcriptions of the numpy formulation (same operations in the same order, no
# fastmath), so that the levels, states and targets are bit-identical to it. ``_clip01`` and
# ``_max0`` mirror numpy's clip/maximum exactly, signed zeros and NaN included.
@njit(cache=True, inline="always")
def _clip01(x: float) -> float:
    if math.isnan(x):
        return x
    x = x if x > 0.0 else 0.0
    return x if x < 1.0 else 1.0


@njit(cache=True, inline="always")
def _max0(x: float) -> float:
    """``np.maximum(0.0, x)``."""
    return 0.0 if x <= 0.0 else x  # NaN: x


@njit(cache=True)
def _levels_and_exits(
    s0, rates, d_stress, d_energy, d_social, fear, with_fear, fear_scale, dt, t_in, min_time,
    energy_lo, energy_hi, social_lo, social_hi, stress_hi, lost, stress, energy, social,
    new, rest, talk_cand,
):  # type: ignore[no-untyped-def]
    """Levels, exits and panic of one tick; ``rest`` agents may start something new.

    Advances ``stress/energy/social`` (rates of the state at the start of the tick, robot
    fear, clipped to [0, 1]) and ``t_in`` by ``dt``; writes ``new`` (panic → running, leaving
    → walking, panic), ``rest`` (walking or idle, past ``min_time``, not panicking) and
    ``talk_cand`` (resting agents social enough to look for a partner).
    """
    for i in range(s0.shape[0]):
        st = s0[i]
        stress[i] += dt * (d_stress[i] + rates[i, st, 0])
        energy[i] += dt * (d_energy[i] + rates[i, st, 1])
        social[i] += dt * (d_social[i] + rates[i, st, 2])
        if with_fear:
            stress[i] += fear_scale * fear[i]
        stress[i] = _clip01(stress[i])
        energy[i] = _clip01(energy[i])
        social[i] = _clip01(social[i])
        t_in[i] += dt
        ok = t_in[i] >= min_time[i]
        nw = st
        if st == 6:  # PANIC lasts one tick
            nw = 2  # RUNNING
        if st == 2 or st == 3:  # RUNNING, INTERACTING: energy-consuming
            if (ok and energy[i] <= energy_lo[i]) or lost[i]:
                nw = 1  # WALKING
        elif (st == 4 or st == 5) and (  # TALKING, PHONE: social
            (ok and social[i] <= social_lo[i]) or lost[i]
        ):
            nw = 1
        panic = ok and stress[i] > stress_hi[i] and st != 6
        if panic:
            nw = 6
            e, hi = energy[i], energy_hi[i]
            energy[i] = e if (e >= hi or math.isnan(e)) else hi
            stress[i] = stress_hi[i]
        new[i] = nw
        rest[i] = (st == 1 or st == 0) and ok and not panic
        talk_cand[i] = rest[i] and social[i] >= social_hi[i]


@njit(cache=True)
def _chance_transitions(
    s0, rest, talk, inter, u, social, energy, social_hi, energy_hi, energy_lo, idle_recovery,
    dt, new, approach_q,
):  # type: ignore[no-untyped-def]
    """Talk, interact, phone, run, idle or walk again for the resting agents (into ``new``).

    ``approach_q``: idle agents not yet recovered, who walk again if someone comes close.
    """
    for i in range(s0.shape[0]):
        approach_q[i] = False
        if talk[i]:
            new[i] = 4  # TALKING
            continue
        if inter[i]:
            new[i] = 3  # INTERACTING
            continue
        if not rest[i]:
            continue
        p_phone = 1.0 - (1.0 - _max0(social[i] - social_hi[i])) ** dt
        if u[i, 0] < p_phone:
            new[i] = 5  # PHONE
            continue
        p_run = 1.0 - (1.0 - _max0(energy[i] - energy_hi[i])) ** dt
        if u[i, 1] < p_run:
            new[i] = 2  # RUNNING
            continue
        if s0[i] == 1 and energy[i] <= energy_lo[i]:
            new[i] = 0  # IDLE
        elif s0[i] == 0:
            lo = energy_lo[i]
            if energy[i] >= lo + idle_recovery * (energy_hi[i] - lo):
                new[i] = 1  # WALKING
            else:
                approach_q[i] = True


@njit(cache=True)
def _update_targets(
    s0, new, talk, partner, inter, q_kind, q_tidx, q_tpoint, kind, tidx, tpoint, conv, t_in,
    social_state,
):  # type: ignore[no-untyped-def]
    """Targets cleared on leaving a targeted state, set on entering one; commit ``new``.

    Talkers join the partner's conversation if the partner keeps talking; else they start one
    named after the lower index, so two agents choosing each other share it. The partner's
    conversation is read after the clearing and before any talker's is written (two passes),
    as the vectorised formulation did.
    """
    n = s0.shape[0]
    for i in range(n):
        targeted = new[i] == 4 or new[i] == 3
        if not targeted or talk[i] or inter[i]:
            kind[i] = 0
            tidx[i] = -1
            tpoint[i, 0] = np.nan
            tpoint[i, 1] = np.nan
            conv[i] = -1
    joined = np.empty(n, dtype=np.int64)
    for i in range(n):
        if talk[i]:
            j = partner[i]
            if s0[j] == 4 and new[j] == 4 and conv[j] >= 0:
                joined[i] = conv[j]
            else:
                joined[i] = min(i, j)
    for i in range(n):
        if talk[i]:
            kind[i] = 1  # TARGET_AGENT
            tidx[i] = partner[i]
            conv[i] = joined[i]
        if inter[i]:
            kind[i] = q_kind[i]
            tidx[i] = q_tidx[i]
            tpoint[i, 0] = q_tpoint[i, 0]
            tpoint[i, 1] = q_tpoint[i, 1]
        if new[i] != s0[i]:
            t_in[i] = 0.0
        social_state[i] = new[i]


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
        self._rates = np.zeros((n, _N_STATES, 3))
        self._t_in = np.zeros(n)
        self._kind = np.zeros(n, dtype=np.int64)
        self._tidx = np.full(n, -1, dtype=np.int64)
        self._tpoint = np.full((n, 2), np.nan)
        self._conv = np.full(n, -1, dtype=np.int64)
        self._gathered = np.zeros(n, dtype=bool)
        self._avoid = np.zeros((n, 2))
        self._robot_pos = np.zeros((0, 2))
        self._vision = Vision(np.zeros(n), np.zeros(n), np.zeros(n))

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
        self._vision = Vision(
            range=p["vision_range"],
            half_angle=np.deg2rad(p["vision_angle"]),
            near=NEAR_FACTOR * p["personal_space_radius"],
        )
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
        p = self._p
        pos = state.positions
        s0 = state.social_state.copy()
        # The per-agent state machine runs in two numba kernels around the perception queries
        # (partners, interests, approaching agents), which stay vectorised; the kernels do
        # exactly the arithmetic of the former numpy formulation, element by element, so the
        # results are bit-identical (a tick used to cost ~60 small numpy calls).
        lost = self._target_lost(state, robots, s0)
        fear = self._fear(state, robots)
        new = np.empty_like(s0)
        rest = np.empty(n, dtype=bool)
        talk_cand = np.empty(n, dtype=bool)
        _levels_and_exits(
            s0, self._rates, p["d_stress"], p["d_energy"], p["d_social"], fear,
            len(robots) > 0, dt * self.params.fear_rate_hz, dt, self._t_in, p["min_time_in_state"],
            p["energy_lo"], p["energy_hi"], p["social_lo"], p["social_hi"], p["stress_hi"],
            lost, state.stress, state.energy, state.social, new, rest, talk_cand,
        )
        energy = state.energy

        # Rest: events first (talk, interact), then chance (phone, run), then idle/walk.
        cells = None
        talk_q = np.flatnonzero(talk_cand)
        partner = np.full(n, -1, dtype=np.int64)
        if talk_q.shape[0]:
            cells = CellList(pos, max(self._vision.reach, 1e-3))
            partner[talk_q] = nearest_seen_agents(self._vision, pos, state.headings, talk_q, cells)
        talk = partner >= 0
        inter, kind, tidx, tpoint = self._find_interest(
            state, robots, np.flatnonzero(rest & ~talk & (energy >= p["energy_hi"]))
        )
        # Drawn for every agent every tick, so the stream does not depend on who is eligible.
        u = self._rng.random((n, 2))
        approach_q = np.empty(n, dtype=bool)
        _chance_transitions(
            s0, rest, talk, inter, u, state.social, energy, p["social_hi"], p["energy_hi"],
            p["energy_lo"], self.params.idle_recovery, dt, new, approach_q,
        )
        if self.params.wake_on_approach:
            query = np.flatnonzero(approach_q)
            if query.shape[0]:
                new[self._approached(state, robots, query, cells)] = _S.WALKING
        _update_targets(
            s0, new, talk, partner, inter, kind, tidx, tpoint,
            self._kind, self._tidx, self._tpoint, self._conv, self._t_in, state.social_state,
        )
        self._set_destinations(state, robots)
        self._set_vmax_factors(state)
        self._robot_pos = np.array(robots.positions, dtype=np.float64).reshape(-1, 2)
        if self.params.robot_avoidance.enabled:
            self._avoid = self.robot_avoidance(state, robots)

    def _fear(self, state: CrowdState, robots: RobotView) -> FloatArray:
        """``(n,)`` Arena's per-tick stress from robots (zeros without robots)."""
        if not len(robots):
            return np.zeros(len(state))
        p = self._p
        return robot_fear(
            state.positions,
            p["personal_space_radius"],
            p["fear_robot"],
            p["fear_robot_speed_tolerance"],
            robots,
        )

    def _target_lost(self, state: CrowdState, robots: RobotView, s0: IntArray) -> BoolArray:
        """Talking/interacting agents whose partner or target is no longer perceived."""
        n = len(state)
        lost = np.zeros(n, dtype=bool)
        has = (s0 == _S.TALKING) | (s0 == _S.INTERACTING)
        if not has.any():  # the common tick: nobody has a partner or target to lose
            return lost
        lost[has & (self._kind == TARGET_NONE)] = True
        pos, hd = state.positions, state.headings
        ia = np.flatnonzero(has & (self._kind == TARGET_AGENT))
        if ia.shape[0]:
            j = self._tidx[ia]
            valid = (j >= 0) & (j < n) & (j != ia)
            seen, _ = sees(self._vision, ia, pos, hd, pos[np.where(valid, j, 0)])
            lost[ia] = ~(valid & seen)
        ir = np.flatnonzero(has & (self._kind == TARGET_ROBOT))
        if ir.shape[0]:
            k = self._tidx[ir]
            valid = (k >= 0) & (k < len(robots))
            rp = np.asarray(robots.positions).reshape(-1, 2)
            if rp.shape[0]:
                seen, _ = sees(self._vision, ir, pos, hd, rp[np.where(valid, k, 0)])
                lost[ir] = ~(valid & seen)
            else:
                lost[ir] = True
        ip = np.flatnonzero(has & (self._kind == TARGET_POINT))
        if ip.shape[0]:
            seen, _ = sees(self._vision, ip, pos, hd, self._tpoint[ip])
            lost[ip] = ~seen
        return lost

    def _find_interest(
        self, state: CrowdState, robots: RobotView, query: IntArray
    ) -> tuple[BoolArray, IntArray, IntArray, FloatArray]:
        """Interaction targets for ``query`` agents: robots first, then obstacles, then walls."""
        n = len(state)
        found = np.zeros(n, dtype=bool)
        kind = np.zeros(n, dtype=np.int64)
        tidx = np.full(n, -1, dtype=np.int64)
        tpoint = np.full((n, 2), np.nan)
        if query.shape[0] == 0:
            return found, kind, tidx, tpoint
        pos, hd = state.positions, state.headings
        rest = query
        if self.params.interested_in_robots and len(robots):
            k = nearest_seen_robots(
                self._vision, pos, hd, rest, np.asarray(robots.positions).reshape(-1, 2)
            )
            hit = k >= 0
            found[rest[hit]] = True
            kind[rest[hit]] = TARGET_ROBOT
            tidx[rest[hit]] = k[hit]
            rest = rest[~hit]
        for index in (self._obstacles, self._walls):
            if index is None or rest.shape[0] == 0:
                continue
            hit, pts = nearest_seen_wall_points(self._vision, pos, hd, rest, index)
            found[rest[hit]] = True
            kind[rest[hit]] = TARGET_POINT
            tpoint[rest[hit]] = pts[hit]
            rest = rest[~hit]
        return found, kind, tidx, tpoint

    def _approached(
        self, state: CrowdState, robots: RobotView, query: IntArray, cells: CellList | None
    ) -> BoolArray:
        """``(n,)`` agents in ``query`` with another agent or a robot inside 1.1 radii."""
        n = len(state)
        out = np.zeros(n, dtype=bool)
        if query.shape[0] == 0:
            return out
        pos = state.positions
        near = self._vision.near
        if n > 1:
            if cells is None:
                cells = CellList(pos, max(self._vision.reach, 1e-3))
            nb = cells.query(pos[query], float(near.max()))
            qrow, j = nb.pairs()
            i = query[qrow]
            d = pos[j] - pos[i]
            close = (j != i) & (np.hypot(d[:, 0], d[:, 1]) < near[i])
            out[i[close]] = True
        if len(robots):
            d = pos[query, None, :] - np.asarray(robots.positions)[None, :, :]
            out[query] |= (np.hypot(d[..., 0], d[..., 1]) < near[query, None]).any(axis=1)
        return out

    def _set_destinations(self, state: CrowdState, robots: RobotView) -> None:
        """Talking/interacting agents head for a spot at personal-space distance from the target."""
        p = self._p
        pos = state.positions
        psr = p["personal_space_radius"]
        self._gathered[:] = False
        ss = state.social_state
        targeted = (ss == _S.TALKING) | (ss == _S.INTERACTING)
        idx = np.flatnonzero(targeted & (self._kind != TARGET_NONE))
        if idx.shape[0] == 0:
            return
        kind = self._kind[idx]
        centre = np.empty((idx.shape[0], 2))
        dist = psr[idx].copy()
        a = kind == TARGET_AGENT
        j = self._tidx[idx[a]]
        centre[a] = pos[j]
        # Both partners agree on one gathering distance (see the module docstring).
        dist[a] = 0.5 * (psr[idx[a]] + psr[j])
        r = kind == TARGET_ROBOT
        if r.any():
            centre[r] = np.asarray(robots.positions).reshape(-1, 2)[self._tidx[idx[r]]]
        q = kind == TARGET_POINT
        centre[q] = self._tpoint[idx[q]]
        # Coincident with the target: step back against the heading.
        back = -np.stack([np.cos(state.headings[idx]), np.sin(state.headings[idx])], axis=1)
        spot = centre + dist[:, None] * _unit(pos[idx] - centre, back)
        state.destinations[idx] = spot
        gap = spot - pos[idx]
        self._gathered[idx] = np.hypot(gap[:, 0], gap[:, 1]) < self.params.gather_tolerance

    def _set_vmax_factors(self, state: CrowdState) -> None:
        f = self.params.human.vmax_factors
        table = self._vmax_table
        ss = state.social_state
        # min/max: np.clip's Python wrapper costs more than the work for 20 agents
        vf = table[np.minimum(np.maximum(ss, 0), _N_STATES - 1)]
        if self._gathered.any():
            vf[(ss == _S.TALKING) & self._gathered] = f.talking
            vf[(ss == _S.INTERACTING) & self._gathered] = f.interacting
        state.vmax_factor[:] = vf

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
        gap = state.destinations - state.positions
        at = np.hypot(gap[:, 0], gap[:, 1]) < prm.at_destination_radius
        if at.any():
            zero = np.zeros((int(at.sum()), 2))
            a[at] = prm.at_destination_force * _unit(a[at], zero)
            state.vmax_factor[at] = np.minimum(
                state.vmax_factor[at], prm.at_destination_vmax_factor
            )
        # After the at-destination rule: it replaces the model's pull, not the robot's push.
        if prm.robot_avoidance.enabled and self._avoid.shape[0] == n:
            a += self._avoid
            state.forces["robot_avoidance"] = self._avoid.copy()
        stand = state.vmax_factor <= 0.0
        a[stand] = -state.velocities[stand] / dt
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
        ss = state.social_state
        if not self._gathered.any():  # only gathered talkers and interactors are turned
            return
        pos = state.positions
        talking = (ss == _S.TALKING) & (self._kind == TARGET_AGENT) & (self._conv >= 0)
        look = np.full((n, 2), np.nan)
        if talking.any():
            conv = self._conv[talking]
            count = np.bincount(conv, minlength=n)
            cx = np.bincount(conv, weights=pos[talking, 0], minlength=n)
            cy = np.bincount(conv, weights=pos[talking, 1], minlength=n)
            ti = np.flatnonzero(talking & self._gathered)
            c = self._conv[ti]
            group = count[c] >= 2
            partner = pos[self._tidx[ti]]
            centre = np.where(
                group[:, None],
                np.stack([cx[c], cy[c]], axis=1) / np.maximum(count[c], 1)[:, None],
                partner,
            )
            # Standing on the centre (e.g. a pair whose midpoint it occupies): face the partner.
            off = centre - pos[ti]
            on_centre = np.hypot(off[:, 0], off[:, 1]) < 1e-6
            centre[on_centre] = partner[on_centre]
            look[ti] = centre
        inter = (ss == _S.INTERACTING) & self._gathered
        ir = np.flatnonzero(inter & (self._kind == TARGET_ROBOT))
        if ir.shape[0] and self._robot_pos.shape[0]:
            k = self._tidx[ir]
            good = k < self._robot_pos.shape[0]
            look[ir[good]] = self._robot_pos[k[good]]
        ip = np.flatnonzero(inter & (self._kind == TARGET_POINT))
        look[ip] = self._tpoint[ip]
        turn = np.flatnonzero(~np.isnan(look[:, 0]))
        if turn.shape[0] == 0:
            return
        d = look[turn] - pos[turn]
        far = np.hypot(d[:, 0], d[:, 1]) > 1e-9
        state.headings[turn[far]] = np.arctan2(d[far, 1], d[far, 0])
