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

import numpy as np
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
from arena.crowd.walls import WallIndex, grid_wall_segments
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
                wa, wb = grid_wall_segments(world.grid)
                if wa.shape[0]:
                    self._walls = WallIndex(wa, wb)

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
        self._t_in += dt

        self._update_levels(state, robots, s0, dt)
        stress, energy, social = state.stress, state.energy, state.social
        ok = self._t_in >= p["min_time_in_state"]
        new = s0.copy()

        # Transient and exits (from the state at the start of the tick).
        new[s0 == _S.PANIC] = _S.RUNNING
        lost = self._target_lost(state, robots, s0)
        energy_act = (s0 == _S.RUNNING) | (s0 == _S.INTERACTING)
        social_act = (s0 == _S.TALKING) | (s0 == _S.PHONE)
        leave = energy_act & ((ok & (energy <= p["energy_lo"])) | lost)
        leave |= social_act & ((ok & (social <= p["social_lo"])) | lost)
        new[leave] = _S.WALKING

        # Panic pre-empts everything else.
        panic = ok & (stress > p["stress_hi"]) & (s0 != _S.PANIC)
        new[panic] = _S.PANIC
        energy[panic] = np.maximum(energy[panic], p["energy_hi"][panic])
        stress[panic] = p["stress_hi"][panic]

        # Rest: events first (talk, interact), then chance (phone, run), then idle/walk.
        rest = ((s0 == _S.WALKING) | (s0 == _S.IDLE)) & ok & ~panic
        cells = None
        talk_q = np.flatnonzero(rest & (social >= p["social_hi"]))
        partner = np.full(n, -1, dtype=np.int64)
        if talk_q.shape[0]:
            cells = CellList(pos, max(self._vision.reach, 1e-3))
            partner[talk_q] = nearest_seen_agents(self._vision, pos, state.headings, talk_q, cells)
        talk = partner >= 0
        inter, kind, tidx, tpoint = self._find_interest(
            state, robots, np.flatnonzero(rest & ~talk & (energy >= p["energy_hi"]))
        )
        free = rest & ~talk & ~inter
        # Drawn for every agent every tick, so the stream does not depend on who is eligible.
        u = self._rng.random((n, 2))
        p_phone = 1.0 - (1.0 - np.maximum(0.0, social - p["social_hi"])) ** dt
        p_run = 1.0 - (1.0 - np.maximum(0.0, energy - p["energy_hi"])) ** dt
        phone = free & (u[:, 0] < p_phone)
        run = free & ~phone & (u[:, 1] < p_run)
        calm = free & ~phone & ~run
        to_idle = calm & (s0 == _S.WALKING) & (energy <= p["energy_lo"])
        idle_q = calm & (s0 == _S.IDLE)
        recovered = energy >= p["energy_lo"] + self.params.idle_recovery * (
            p["energy_hi"] - p["energy_lo"]
        )
        to_walk = idle_q & recovered
        if self.params.wake_on_approach:
            to_walk |= self._approached(state, robots, np.flatnonzero(idle_q & ~recovered), cells)
        new[talk] = _S.TALKING
        new[inter] = _S.INTERACTING
        new[phone] = _S.PHONE
        new[run] = _S.RUNNING
        new[to_idle] = _S.IDLE
        new[to_walk] = _S.WALKING

        # Targets: cleared on leaving a targeted state, set on entering one.
        targeted = (new == _S.TALKING) | (new == _S.INTERACTING)
        clear = ~targeted | talk | inter
        self._kind[clear] = TARGET_NONE
        self._tidx[clear] = -1
        self._tpoint[clear] = np.nan
        self._conv[clear] = -1
        ti = np.flatnonzero(talk)
        if ti.shape[0]:
            j = partner[ti]
            self._kind[ti] = TARGET_AGENT
            self._tidx[ti] = j
            # Join the partner's conversation if it keeps talking; else start one named after
            # the lower index, so two agents choosing each other share it.
            joins = (s0[j] == _S.TALKING) & (new[j] == _S.TALKING) & (self._conv[j] >= 0)
            self._conv[ti] = np.where(joins, self._conv[j], np.minimum(ti, j))
        self._kind[inter] = kind[inter]
        self._tidx[inter] = tidx[inter]
        self._tpoint[inter] = tpoint[inter]

        changed = new != s0
        self._t_in[changed] = 0.0
        state.social_state[:] = new
        self._set_destinations(state, robots)
        self._set_vmax_factors(state)
        self._robot_pos = np.array(robots.positions, dtype=np.float64).reshape(-1, 2)
        if self.params.robot_avoidance.enabled:
            self._avoid = self.robot_avoidance(state, robots)

    def _update_levels(self, state: CrowdState, robots: RobotView, s0: IntArray, dt: float) -> None:
        p = self._p
        n = len(state)
        rates = self._rates[np.arange(n), s0]
        state.stress += dt * (p["d_stress"] + rates[:, 0])
        state.energy += dt * (p["d_energy"] + rates[:, 1])
        state.social += dt * (p["d_social"] + rates[:, 2])
        if len(robots):
            fear = robot_fear(
                state.positions,
                p["personal_space_radius"],
                p["fear_robot"],
                p["fear_robot_speed_tolerance"],
                robots,
            )
            state.stress += dt * self.params.fear_rate_hz * fear
        for name in LEVEL_NAMES:
            np.clip(getattr(state, name), 0.0, 1.0, out=getattr(state, name))

    def _target_lost(self, state: CrowdState, robots: RobotView, s0: IntArray) -> BoolArray:
        """Talking/interacting agents whose partner or target is no longer perceived."""
        n = len(state)
        lost = np.zeros(n, dtype=bool)
        has = (s0 == _S.TALKING) | (s0 == _S.INTERACTING)
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
        table = np.array([f.idle, f.walking, f.running, f.approach, f.approach, f.phone, f.panic])
        ss = state.social_state
        vf = table[np.clip(ss, 0, _N_STATES - 1)]
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
        pos = state.positions
        ss = state.social_state
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
