"""Numba kernels of the social-state statechart: one tick of perception and transitions.

:class:`~arena.crowd.social.statechart.SocialStates` used to run a tick as ~60 small numpy
calls on ``(n,)`` arrays (about 200 µs for 20 agents, nearly all of it call overhead). Here a
tick is one compiled call, :func:`pre_tick`, plus :func:`post_tick` and :func:`orient_look`.

Every kernel is an element-wise transcription of the numpy formulation it replaced (the
functions in :mod:`arena.crowd.social.perception` and :mod:`arena.crowd.social.robots` stay as
the reference and are tested against these kernels): same operations in the same order, no
fastmath, so the levels, states, targets and destinations are bit-identical to it. Three details
keep them so:

* Perception queries are the compiled one-agent versions in
  :mod:`~arena.crowd.social.perception` (same candidates in the same order, vision cones
  decided as numpy decides them, see there).
* numpy's ``arctan2`` is a SIMD implementation that may differ from libm's ``atan2`` (which
  numba calls) in the last bit, so :func:`orient_look` returns the look-at offsets and the
  caller computes the headings with numpy itself.
* Sums over robots run in numpy's order for up to :data:`MAX_SEQUENTIAL_ROBOTS` robots (beyond
  that numpy sums pairwise and the caller passes numpy's fear in).

Per-agent parameters are the rows of one ``(N_ROWS, n)`` table (row indices below), so that a
tick passes one array instead of fifteen.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from arena.crowd.social.perception import (
    candidates,
    cell_grid,
    clip01,
    nearest_seen_agent,
    nearest_seen_robot,
    nearest_seen_wall_point,
    sees_one,
)

# Rows of the per-agent parameter table (SocialStates builds it at reset).
D_STRESS, D_ENERGY, D_SOCIAL = 0, 1, 2
MIN_TIME = 3
ENERGY_LO, ENERGY_HI, SOCIAL_LO, SOCIAL_HI, STRESS_HI = 4, 5, 6, 7, 8
PSR, FEAR_ROBOT, FEAR_TOLERANCE = 9, 10, 11
VISION_RANGE, VISION_HALF_ANGLE, VISION_NEAR = 12, 13, 14
N_ROWS = 15

# Entries of the per-tick float settings vector of pre_tick.
C_DT, C_FEAR_SCALE, C_IDLE_RECOVERY, C_GATHER_TOL, C_VF_TALKING, C_VF_INTERACTING = range(6)
N_SETTINGS = 6

# Social-state and target codes as literals (numba cannot read the enums); statechart asserts
# that they match SocialState and its TARGET_* constants.
IDLE, WALKING, RUNNING, INTERACTING, TALKING, PHONE, PANIC = 0, 1, 2, 3, 4, 5, 6
N_STATES = 7
TARGET_NONE, TARGET_AGENT, TARGET_ROBOT, TARGET_POINT = 0, 1, 2, 3

MAX_SEQUENTIAL_ROBOTS = 7
"""numpy sums up to this many terms in order (then pairwise): robot fear is summed here up to it."""


# -- scalar helpers ---------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _max0(x: float) -> float:
    """``np.maximum(0.0, x)``."""
    return 0.0 if x <= 0.0 else x  # NaN: x


# -- the state machine ------------------------------------------------------------------------
@njit(cache=True)
def _fear(table, positions, robot_pos, robot_vel, i):  # type: ignore[no-untyped-def]
    """:func:`~arena.crowd.social.robots.robot_fear` for agent ``i`` (robots summed in order)."""
    total = 0.0
    for k in range(robot_pos.shape[0]):
        inside = math.hypot(positions[i, 0] - robot_pos[k, 0], positions[i, 1] - robot_pos[k, 1])
        excess = _max0(math.hypot(robot_vel[k, 0], robot_vel[k, 1]) - table[FEAR_TOLERANCE, i])
        term = table[FEAR_ROBOT, i] + excess if inside < table[PSR, i] else 0.0
        total = term if k == 0 else total + term
    return total


@njit(cache=True)
def _target_lost(  # type: ignore[no-untyped-def]
    vision, positions, headings, s0, kind, tidx, tpoint, robot_pos, i
):
    """Talking/interacting agent ``i`` no longer perceives its partner or target."""
    if s0[i] != TALKING and s0[i] != INTERACTING:
        return False
    k = kind[i]
    if k == TARGET_NONE:
        return True
    if k == TARGET_AGENT:
        j = tidx[i]
        if j < 0 or j >= positions.shape[0] or j == i:
            return True
        return not sees_one(vision, positions, headings, i, positions[j, 0], positions[j, 1])[0]
    if k == TARGET_ROBOT:
        r = tidx[i]
        if r < 0 or r >= robot_pos.shape[0]:
            return True
        return not sees_one(vision, positions, headings, i, robot_pos[r, 0], robot_pos[r, 1])[0]
    if k == TARGET_POINT:
        return not sees_one(vision, positions, headings, i, tpoint[i, 0], tpoint[i, 1])[0]
    return False


@njit(cache=True)
def _levels_and_exits(  # type: ignore[no-untyped-def]
    s0, table, rates, fear, with_fear, fear_scale, dt, t_in, lost, stress, energy, social,
    new, rest, talk_cand,
):
    """Levels, exits and panic of one tick; ``rest`` agents may start something new.

    Advances ``stress/energy/social`` (rates of the state at the start of the tick, robot
    fear, clipped to [0, 1]) and ``t_in`` by ``dt``; writes ``new`` (panic → running, leaving
    → walking, panic), ``rest`` (walking or idle, past ``min_time``, not panicking) and
    ``talk_cand`` (resting agents social enough to look for a partner).
    """
    for i in range(s0.shape[0]):
        st = s0[i]
        stress[i] += dt * (table[D_STRESS, i] + rates[i, st, 0])
        energy[i] += dt * (table[D_ENERGY, i] + rates[i, st, 1])
        social[i] += dt * (table[D_SOCIAL, i] + rates[i, st, 2])
        if with_fear:
            stress[i] += fear_scale * fear[i]
        stress[i] = clip01(stress[i])
        energy[i] = clip01(energy[i])
        social[i] = clip01(social[i])
        t_in[i] += dt
        ok = t_in[i] >= table[MIN_TIME, i]
        nw = st
        if st == PANIC:  # lasts one tick
            nw = RUNNING
        if st in (RUNNING, INTERACTING):  # energy-consuming
            if (ok and energy[i] <= table[ENERGY_LO, i]) or lost[i]:
                nw = WALKING
        elif st in (TALKING, PHONE) and (
            (ok and social[i] <= table[SOCIAL_LO, i]) or lost[i]
        ):
            nw = WALKING
        panic = ok and stress[i] > table[STRESS_HI, i] and st != PANIC
        if panic:
            nw = PANIC
            e, hi = energy[i], table[ENERGY_HI, i]
            energy[i] = e if (e >= hi or math.isnan(e)) else hi
            stress[i] = table[STRESS_HI, i]
        new[i] = nw
        rest[i] = st in (WALKING, IDLE) and ok and not panic
        talk_cand[i] = rest[i] and social[i] >= table[SOCIAL_HI, i]


@njit(cache=True)
def _chance_transitions(  # type: ignore[no-untyped-def]
    s0, rest, talk, inter, u, social, energy, table, idle_recovery, dt, new, approach_q
):
    """Talk, interact, phone, run, idle or walk again for the resting agents (into ``new``).

    ``approach_q``: idle agents not yet recovered, who walk again if someone comes close.
    """
    for i in range(s0.shape[0]):
        approach_q[i] = False
        if talk[i]:
            new[i] = TALKING
            continue
        if inter[i]:
            new[i] = INTERACTING
            continue
        if not rest[i]:
            continue
        p_phone = 1.0 - (1.0 - _max0(social[i] - table[SOCIAL_HI, i])) ** dt
        if u[i, 0] < p_phone:
            new[i] = PHONE
            continue
        p_run = 1.0 - (1.0 - _max0(energy[i] - table[ENERGY_HI, i])) ** dt
        if u[i, 1] < p_run:
            new[i] = RUNNING
            continue
        lo = table[ENERGY_LO, i]
        if s0[i] == WALKING and energy[i] <= lo:
            new[i] = IDLE
        elif s0[i] == IDLE:
            if energy[i] >= lo + idle_recovery * (table[ENERGY_HI, i] - lo):
                new[i] = WALKING
            else:
                approach_q[i] = True


@njit(cache=True)
def _interest(  # type: ignore[no-untyped-def]
    vision, positions, headings, robot_pos, obstacles, walls, reach, with_robots, i, buf
):
    """Agent ``i``'s interaction target: the nearest seen robot, else obstacle, else wall point.

    Returns ``(kind, index, x, y)``: ``TARGET_ROBOT`` and the robot's index,
    ``TARGET_POINT`` and the point (m), or ``TARGET_NONE``; -1 and NaN where unused.
    """
    if with_robots and robot_pos.shape[0] > 0:
        k = nearest_seen_robot(vision, positions, headings, robot_pos, i)
        if k >= 0:
            return TARGET_ROBOT, k, np.nan, np.nan
    for index in (obstacles, walls):
        if index[0].shape[0] == 0 or not reach > 0.0:
            continue
        found, x, y = nearest_seen_wall_point(vision, positions, headings, index, reach, i, buf)
        if found:
            return TARGET_POINT, -1, x, y
    return TARGET_NONE, -1, np.nan, np.nan


@njit(cache=True)
def _approached(table, positions, grid, robot_pos, i, buf):  # type: ignore[no-untyped-def]
    """Another agent or a robot is within agent ``i``'s all-around perception radius."""
    near = table[VISION_NEAR, i]
    n = positions.shape[0]
    px, py = positions[i, 0], positions[i, 1]
    if n > 1:
        m = candidates(positions, grid, px, py, np.max(table[VISION_NEAR]), buf)
        for k in range(m):
            j = buf[k]
            if j != i and math.hypot(positions[j, 0] - px, positions[j, 1] - py) < near:
                return True
    for k in range(robot_pos.shape[0]):
        if math.hypot(px - robot_pos[k, 0], py - robot_pos[k, 1]) < near:
            return True
    return False


@njit(cache=True)
def _update_targets(  # type: ignore[no-untyped-def]
    s0, new, talk, partner, inter, q_kind, q_tidx, q_tpoint, kind, tidx, tpoint, conv, t_in,
    social_state,
):
    """Targets cleared on leaving a targeted state, set on entering one; commit ``new``.

    Talkers join the partner's conversation if the partner keeps talking; else they start one
    named after the lower index, so two agents choosing each other share it. The partner's
    conversation is read after the clearing and before any talker's is written (two passes).
    """
    n = s0.shape[0]
    for i in range(n):
        targeted = new[i] == TALKING or new[i] == INTERACTING
        if not targeted or talk[i] or inter[i]:
            kind[i] = TARGET_NONE
            tidx[i] = -1
            tpoint[i, 0] = np.nan
            tpoint[i, 1] = np.nan
            conv[i] = -1
    joined = np.empty(n, dtype=np.int64)
    for i in range(n):
        if talk[i]:
            j = partner[i]
            if s0[j] == TALKING and new[j] == TALKING and conv[j] >= 0:
                joined[i] = conv[j]
            else:
                joined[i] = min(i, j)
    for i in range(n):
        if talk[i]:
            kind[i] = TARGET_AGENT
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


@njit(cache=True)
def _set_destinations(  # type: ignore[no-untyped-def]
    table, positions, headings, social_state, kind, tidx, tpoint, robot_pos, gather_tol,
    destinations, gathered,
):
    """Talking/interacting agents head for a spot at personal-space distance from the target.

    Partners agree on the mean of their two radii; an agent standing on its target steps
    back against its heading. Writes ``destinations`` and ``gathered`` (within ``gather_tol``).
    """
    for i in range(positions.shape[0]):
        gathered[i] = False
        st, k = social_state[i], kind[i]
        if (st != TALKING and st != INTERACTING) or k == TARGET_NONE:
            continue
        dist = table[PSR, i]
        if k == TARGET_AGENT:
            j = tidx[i]
            cx, cy = positions[j, 0], positions[j, 1]
            dist = 0.5 * (table[PSR, i] + table[PSR, j])
        elif k == TARGET_ROBOT:
            cx, cy = robot_pos[tidx[i], 0], robot_pos[tidx[i], 1]
        else:
            cx, cy = tpoint[i, 0], tpoint[i, 1]
        vx, vy = positions[i, 0] - cx, positions[i, 1] - cy
        norm = math.hypot(vx, vy)
        if norm > 1e-12:
            ux, uy = vx / norm, vy / norm
        else:
            ux, uy = -math.cos(headings[i]), -math.sin(headings[i])
        sx, sy = cx + dist * ux, cy + dist * uy
        destinations[i, 0] = sx
        destinations[i, 1] = sy
        gathered[i] = math.hypot(sx - positions[i, 0], sy - positions[i, 1]) < gather_tol


@njit(cache=True)
def _set_vmax_factors(  # type: ignore[no-untyped-def]
    social_state, gathered, vmax_table, vf_talking, vf_interacting, vmax_factor
):
    """The vmax factor of each agent's state; gathered talkers/interactors their own."""
    for i in range(social_state.shape[0]):
        st = social_state[i]
        f = vmax_table[min(max(st, 0), N_STATES - 1)]
        if gathered[i] and st == TALKING:
            f = vf_talking
        elif gathered[i] and st == INTERACTING:
            f = vf_interacting
        vmax_factor[i] = f


@njit(cache=True)
def pre_tick(  # type: ignore[no-untyped-def]
    positions, headings, social_state, stress, energy, social, destinations, vmax_factor,
    table, rates, t_in, kind, tidx, tpoint, conv, gathered, robot_pos, robot_vel, fear_in, u,
    obstacles, walls, settings, vmax_table, interested_in_robots, wake_on_approach,
):
    """One tick of :meth:`SocialStates.pre` (see its docstring and the module's).

    Args:
        positions: ``(n, 2)`` m.
        headings: ``(n,)`` rad.
        social_state: ``(n,)`` state codes (updated).
        stress: ``(n,)`` level in [0, 1] (updated).
        energy: ``(n,)`` level in [0, 1] (updated).
        social: ``(n,)`` level in [0, 1] (updated).
        destinations: ``(n, 2)`` m (updated for talking and interacting agents).
        vmax_factor: ``(n,)`` (updated).
        table: ``(N_ROWS, n)`` per-agent parameters.
        rates: ``(n, N_STATES, 3)`` level rates (1/s) by state.
        t_in: ``(n,)`` s in the current state (updated).
        kind: ``(n,)`` ``TARGET_*`` (updated).
        tidx: ``(n,)`` partner agent or robot index, -1 for none (updated).
        tpoint: ``(n, 2)`` m, obstacle point targets, NaN for none (updated).
        conv: ``(n,)`` conversation ids, -1 for none (updated).
        gathered: ``(n,)`` bool, at the spot (updated).
        robot_pos: ``(r, 2)`` m.
        robot_vel: ``(r, 2)`` m/s.
        fear_in: ``(n,)`` numpy's robot fear when there are more than
            ``MAX_SEQUENTIAL_ROBOTS`` robots (else unused, any shape).
        u: ``(n, 2)`` this tick's uniforms (phone, run).
        obstacles: :func:`wall_index_arrays` of the placed obstacles.
        walls: :func:`wall_index_arrays` of the map walls (empty unless they are targets).
        settings: ``(N_SETTINGS,)`` the ``C_*`` values.
        vmax_table: ``(N_STATES,)`` vmax factor by state.
        interested_in_robots: robots count as interaction targets.
        wake_on_approach: idle agents walk again when something comes close.
    """
    n = positions.shape[0]
    r = robot_pos.shape[0]
    dt = settings[C_DT]
    s0 = social_state.copy()
    vision = (table[VISION_RANGE], table[VISION_HALF_ANGLE], table[VISION_NEAR])
    reach = max(np.max(vision[0]), np.max(vision[2]))  # Vision.reach
    lost = np.zeros(n, dtype=np.bool_)
    fear = fear_in if r > MAX_SEQUENTIAL_ROBOTS else np.zeros(n)
    for i in range(n):
        lost[i] = _target_lost(vision, positions, headings, s0, kind, tidx, tpoint, robot_pos, i)
        if 0 < r <= MAX_SEQUENTIAL_ROBOTS:
            fear[i] = _fear(table, positions, robot_pos, robot_vel, i)
    new = np.empty_like(s0)
    rest = np.empty(n, dtype=np.bool_)
    talk_cand = np.empty(n, dtype=np.bool_)
    _levels_and_exits(
        s0, table, rates, fear, r > 0, settings[C_FEAR_SCALE], dt, t_in, lost, stress, energy,
        social, new, rest, talk_cand,
    )

    # Rest: events first (talk, interact), then chance (phone, run), then idle/walk.
    buf = np.empty(max(n, obstacles[0].shape[0], walls[0].shape[0]), dtype=np.int64)
    # The agents' cell list, built on first use (as before: never for a tick without queries);
    # until then a placeholder of the same type.
    grid = walls[4]
    have_grid = False
    talk = np.zeros(n, dtype=np.bool_)
    partner = np.full(n, -1, dtype=np.int64)
    inter = np.zeros(n, dtype=np.bool_)
    q_kind = np.zeros(n, dtype=np.int64)
    q_tidx = np.full(n, -1, dtype=np.int64)
    q_tpoint = np.full((n, 2), np.nan)
    for i in range(n):
        if talk_cand[i] and n >= 2 and reach > 0.0:
            if not have_grid:
                grid, have_grid = cell_grid(positions, max(reach, 1e-3)), True
            partner[i] = nearest_seen_agent(vision, positions, headings, grid, reach, i, buf)
            talk[i] = partner[i] >= 0
        if not rest[i] or talk[i] or not energy[i] >= table[ENERGY_HI, i]:
            continue
        q_kind[i], q_tidx[i], q_tpoint[i, 0], q_tpoint[i, 1] = _interest(
            vision, positions, headings, robot_pos, obstacles, walls, reach,
            interested_in_robots, i, buf,
        )
        inter[i] = q_kind[i] != TARGET_NONE
    approach_q = np.empty(n, dtype=np.bool_)
    _chance_transitions(
        s0, rest, talk, inter, u, social, energy, table, settings[C_IDLE_RECOVERY], dt, new,
        approach_q,
    )
    if wake_on_approach:
        for i in range(n):
            if approach_q[i] and n > 1 and not have_grid:
                grid, have_grid = cell_grid(positions, max(reach, 1e-3)), True
            if approach_q[i] and _approached(table, positions, grid, robot_pos, i, buf):
                new[i] = WALKING
    _update_targets(
        s0, new, talk, partner, inter, q_kind, q_tidx, q_tpoint, kind, tidx, tpoint, conv, t_in,
        social_state,
    )
    _set_destinations(
        table, positions, headings, social_state, kind, tidx, tpoint, robot_pos,
        settings[C_GATHER_TOL], destinations, gathered,
    )
    _set_vmax_factors(
        social_state, gathered, vmax_table, settings[C_VF_TALKING], settings[C_VF_INTERACTING],
        vmax_factor,
    )


@njit(cache=True)
def post_tick(  # type: ignore[no-untyped-def]
    acc, destinations, positions, velocities, vmax_factor, avoid, radius, force, vf_cap, dt
):
    """:meth:`SocialStates.post` on ``(n, 2)`` ``acc`` (a copy, updated in place).

    At the destination: ``force · unit(a)`` and ``vmax_factor ≤ vf_cap``; then ``avoid``
    (``(n, 2)``, or ``(0, 2)`` for none) is added; standing agents get ``−v/dt``.
    """
    add = avoid.shape[0] == acc.shape[0]
    for i in range(acc.shape[0]):
        gx = destinations[i, 0] - positions[i, 0]
        gy = destinations[i, 1] - positions[i, 1]
        if math.hypot(gx, gy) < radius:
            norm = math.hypot(acc[i, 0], acc[i, 1])
            if norm > 1e-12:
                acc[i, 0] = force * (acc[i, 0] / norm)
                acc[i, 1] = force * (acc[i, 1] / norm)
            else:
                acc[i, 0] = force * 0.0
                acc[i, 1] = force * 0.0
            f = vmax_factor[i]
            vmax_factor[i] = f if (f < vf_cap or math.isnan(f)) else vf_cap  # np.minimum
        if add:
            acc[i, 0] += avoid[i, 0]
            acc[i, 1] += avoid[i, 1]
        if vmax_factor[i] <= 0.0:
            acc[i, 0] = -velocities[i, 0] / dt
            acc[i, 1] = -velocities[i, 1] / dt


@njit(cache=True)
def orient_look(  # type: ignore[no-untyped-def]
    positions, social_state, kind, tidx, tpoint, conv, gathered, robot_pos
):
    """Whom gathered talkers and interactors face: ``(turn, dy, dx)`` for :meth:`orient`.

    ``turn`` ``(m,)`` agent indices and the offsets ``(m,)`` m to their look-at points (longer
    than 1 nm); the caller sets ``headings[turn] = np.arctan2(dy, dx)`` with numpy's arctan2.
    A talker faces its conversation's mean position (when two or more members talk; sums in
    index order, as ``np.bincount``), else its partner, and its partner when on the centre.
    """
    n = positions.shape[0]
    count = np.zeros(n, dtype=np.int64)
    cx = np.zeros(n)
    cy = np.zeros(n)
    for i in range(n):
        if social_state[i] == TALKING and kind[i] == TARGET_AGENT and conv[i] >= 0:
            c = conv[i]
            count[c] += 1
            cx[c] += positions[i, 0]
            cy[c] += positions[i, 1]
    turn = np.empty(n, dtype=np.int64)
    dy = np.empty(n)
    dx = np.empty(n)
    m = 0
    nr = robot_pos.shape[0]
    for i in range(n):
        if not gathered[i]:
            continue
        st, k = social_state[i], kind[i]
        if st == TALKING and k == TARGET_AGENT and conv[i] >= 0:
            c = conv[i]
            j = tidx[i]
            lx, ly = positions[j, 0], positions[j, 1]
            if count[c] >= 2:
                w = float(max(count[c], 1))
                gx, gy = cx[c] / w, cy[c] / w
                if not math.hypot(gx - positions[i, 0], gy - positions[i, 1]) < 1e-6:
                    lx, ly = gx, gy
        elif st == INTERACTING and k == TARGET_ROBOT and nr > 0 and tidx[i] < nr:
            lx, ly = robot_pos[tidx[i], 0], robot_pos[tidx[i], 1]
        elif st == INTERACTING and k == TARGET_POINT:
            lx, ly = tpoint[i, 0], tpoint[i, 1]
        else:
            continue
        if math.isnan(lx):
            continue
        ox, oy = lx - positions[i, 0], ly - positions[i, 1]
        if math.hypot(ox, oy) > 1e-9:
            turn[m], dy[m], dx[m] = i, oy, ox
            m += 1
    return turn[:m], dy[:m], dx[:m]
