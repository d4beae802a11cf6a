"""Behaviour of the social-state statechart (arena_specs §5.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.geometry import wrap_angle
from arena.crowd.base import RobotView
from arena.crowd.social import (
    TARGET_AGENT,
    TARGET_POINT,
    TARGET_ROBOT,
    Dist,
    HumanParams,
    RobotAvoidanceParams,
    SocialStates,
    SocialStatesParams,
    Vision,
    sample_agent_params,
)
from arena.crowd.social import kernels as K
from arena.crowd.social import perception as P
from arena.crowd.social.perception import (
    nearest_seen_agents,
    nearest_seen_robots,
    nearest_seen_wall_points,
)
from arena.crowd.social.robots import robot_fear
from arena.crowd.state import AgentType, CrowdState, SocialState
from arena.crowd.walls import WallIndex, world_segments
from arena.maps.grid import OccupancyGrid
from arena.scene.state import Obstacle, StaticWorld

S = SocialState


# -- helpers ------------------------------------------------------------------------------------
def make_state(positions, headings=None, kinds=None, vmax=1.0) -> CrowdState:
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    n = len(p)
    h = np.zeros(n) if headings is None else np.asarray(headings, dtype=float)
    k = np.zeros(n, dtype=np.int64) if kinds is None else np.asarray(kinds, dtype=np.int64)
    return CrowdState(
        ids=np.arange(n, dtype=np.int64),
        positions=p.copy(),
        velocities=np.zeros((n, 2)),
        headings=h.copy(),
        radii=np.full(n, 0.3),
        vmax=np.full(n, float(vmax)),
        vmax_factor=np.ones(n),
        waypoints=p[:, None, :].copy(),
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_index=np.zeros(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        destinations=p.copy(),
        startup_mode=np.zeros(n, dtype=np.int64),
        wait_time=np.zeros(n),
        trigger_radius=np.zeros(n),
        started=np.ones(n, dtype=bool),
        group=np.full(n, -1, dtype=np.int64),
        leader=np.arange(n, dtype=np.int64),
        kinds=k,
        social_state=np.full(n, int(S.WALKING), dtype=np.int64),
        stress=np.zeros(n),
        energy=np.full(n, 0.5),
        social=np.full(n, 0.5),
    )


def exact_human(**means: float) -> HumanParams:
    """Arena's means with σ = 0 and no bounds; ``means`` overrides some."""
    base = HumanParams()
    fields = {}
    for name in HumanParams.dist_names():
        fields[name] = Dist(mean=means.get(name, getattr(base, name).mean), sigma=0.0)
    return HumanParams(**fields)


def machine(**kw) -> SocialStates:
    human = kw.pop("human", None) or exact_human()
    return SocialStates(SocialStatesParams(human=human, **kw))


def spread(n: int, spacing: float = 20.0) -> np.ndarray:
    side = math.ceil(math.sqrt(n))
    ij = np.stack(np.divmod(np.arange(n), side), axis=1)
    return ij * spacing


def robots_at(positions, velocities=None, radius=0.3) -> RobotView:
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    v = np.zeros_like(p) if velocities is None else np.asarray(velocities, dtype=float)
    return RobotView(p, np.zeros(len(p)), v.reshape(-1, 2), np.full(len(p), radius))


NO_ROBOTS = RobotView.empty()


def step(social: SocialStates, state: CrowdState, robots: RobotView, dt: float) -> None:
    """A minimal crowd step: relax toward the destination at the capped speed."""
    social.pre(state, robots, None, dt)
    gap = state.destinations - state.positions
    dist = np.hypot(gap[:, 0], gap[:, 1])
    unit = np.divide(gap, dist[:, None], out=np.zeros_like(gap), where=dist[:, None] > 1e-9)
    desired = unit * (state.vmax * state.vmax_factor)[:, None] * np.minimum(1.0, dist)[:, None]
    acc = (desired - state.velocities) / 0.5
    acc = social.post(state, acc, dt)
    v = state.velocities + acc * dt
    speed = np.hypot(v[:, 0], v[:, 1])
    cap = state.vmax * state.vmax_factor
    over = speed > cap
    v[over] *= (cap[over] / speed[over])[:, None]
    state.velocities = v
    state.positions = state.positions + v * dt
    moving = speed > 1e-3
    state.headings[moving] = np.arctan2(v[moving, 1], v[moving, 0])
    social.orient(state)
    state.time += dt


# -- parameters ---------------------------------------------------------------------------------
def test_truncated_normal_keeps_bounds_and_moments():
    rng = np.random.default_rng(0)
    x = Dist(mean=0.8, sigma=0.05, lo=0.0, hi=1.0).sample(200_000, rng)
    assert x.min() >= 0.0 and x.max() <= 1.0
    assert x.mean() == pytest.approx(0.8, abs=1e-3)
    assert x.std() == pytest.approx(0.05, rel=0.02)
    tail = Dist(mean=-0.01, sigma=0.001, hi=-0.001).sample(10_000, rng)
    assert tail.max() <= -0.001
    # Interval far in the upper tail: still inside, finite, and not all on one bound.
    far = Dist(mean=0.0, sigma=1.0, lo=8.0, hi=9.0).sample(10_000, rng)
    assert np.isfinite(far).all() and far.min() >= 8.0 and far.max() <= 9.0
    assert far.mean() == pytest.approx(8.12, abs=0.03)
    assert (Dist(mean=3.0, lo=0.0, hi=1.0).sample(5, rng) == 1.0).all()


def _agent_params_one_by_one(params, is_elder, rng):
    """The reference: one ``truncated_normal`` per parameter, in declaration order."""
    from arena.crowd.social.params import truncated_normal

    out = {}
    for name in HumanParams.dist_names():
        d = getattr(params.human, name)
        u = rng.random(len(is_elder))
        mean = np.full(len(is_elder), d.mean)
        k = params.elder.offsets.get(name, 0.0)
        if k:
            mean[is_elder] += k * d.sigma
        vals = truncated_normal(mean, d.sigma, d.lo, d.hi, u)
        if name in params.elder.constants:
            vals[is_elder] = params.elder.constants[name]
        out[name] = vals
    return out


@pytest.mark.parametrize("n", [0, 1, 7, 40])
def test_agent_params_drawn_together_are_the_one_by_one_draws(n):
    """All parameters at once: the same bits and the same generator state afterwards."""
    from arena.crowd.social import ElderOffsets

    custom = SocialStatesParams(
        human=HumanParams(
            stress_lo=Dist(mean=0.3, sigma=0.0, lo=0.4),  # sigma 0: the clipped mean
            fear_robot=Dist(mean=0.0, sigma=1.0, lo=8.0, hi=9.0),  # the upper tail (mirrored)
            vision_angle=Dist(mean=-0.0, sigma=0.0),
        ),
        elder=ElderOffsets(
            offsets={"vision_range": -3.0, "stress_lo": 1.5},
            constants={"energy_hi": 1.0, "social_lo": 0.2},
        ),
    )
    for params in (SocialStatesParams(), custom):
        for frac in (0.0, 0.4, 1.0):
            elder = np.random.default_rng(n).random(n) < frac
            r1, r2 = np.random.default_rng(5), np.random.default_rng(5)
            got = sample_agent_params(params, elder, r1)
            want = _agent_params_one_by_one(params, elder, r2)
            assert list(got) == list(want)
            for name in want:
                assert got[name].shape == (n,)
                assert got[name].tobytes() == want[name].tobytes(), name
            assert r1.random() == r2.random()


def test_elders_shift_means_by_sigma_and_never_want_to_run():
    rng = np.random.default_rng(1)
    n = 40_000
    elder = np.arange(n) % 2 == 1
    p = sample_agent_params(SocialStatesParams(), elder, rng)
    diff = lambda k: p[k][elder].mean() - p[k][~elder].mean()  # noqa: E731
    assert diff("vision_range") == pytest.approx(-3 * 0.5, abs=0.02)
    assert diff("personal_space_radius") == pytest.approx(+2 * 0.1, abs=0.01)
    assert diff("fear_robot_speed_tolerance") == pytest.approx(-2 * 0.1, abs=0.01)
    assert diff("d_social") == pytest.approx(+3 * 0.001, abs=1e-4)
    assert (p["energy_hi"][elder] == 1.0).all()
    assert (p["energy_hi"][~elder] < 1.0).all()
    assert p["min_time_in_state"][~elder].min() >= 1.0


def test_reset_keeps_vmax_and_starts_walking():
    # Elders' x0.7 is the crowd simulator's job (tests/crowd/test_simulator.py), not reset's.
    state = make_state(spread(3), kinds=[AgentType.ADULT, AgentType.ELDER, AgentType.CHILD])
    state.social_state[:] = S.PHONE
    SocialStates().reset(state, None, np.random.default_rng(0))
    np.testing.assert_allclose(state.vmax, [1.0, 1.0, 1.0])
    assert (state.social_state == S.WALKING).all()
    assert (state.vmax_factor == 1.0).all()


# -- levels -------------------------------------------------------------------------------------
def test_levels_drift_with_state_rates():
    social = machine(human=exact_human(min_time_in_state=1e9))
    state = make_state(spread(5))
    social.reset(state, None, np.random.default_rng(0))
    state.social_state[:] = [S.WALKING, S.IDLE, S.RUNNING, S.PHONE, S.WALKING]
    state.stress[:] = [0.5, 0.5, 0.5, 0.5, 0.0]
    state.energy[:] = [0.5, 0.3, 0.7, 0.5, 0.5]
    state.social[:] = [0.5, 0.3, 0.5, 0.7, 0.5]
    dt, ticks = 0.1, 20
    for _ in range(ticks):
        social.pre(state, NO_ROBOTS, None, dt)
    t = dt * ticks
    np.testing.assert_array_equal(
        state.social_state, [S.WALKING, S.IDLE, S.RUNNING, S.PHONE, S.WALKING]
    )
    # drift (−0.01, +0.01, +0.01) + state rates; stress of the last agent is clipped at 0.
    np.testing.assert_allclose(
        state.stress, [0.5 - 0.01 * t, 0.5 - 0.06 * t, 0.5 - 0.01 * t, 0.5 - 0.01 * t, 0.0]
    )
    np.testing.assert_allclose(
        state.energy,
        [0.5 + 0.01 * t, 0.3 + 0.16 * t, 0.7 - 0.04 * t, 0.5 + 0.01 * t, 0.5 + 0.01 * t],
    )
    np.testing.assert_allclose(
        state.social,
        [0.5 + 0.01 * t, 0.3 + 0.06 * t, 0.5 + 0.01 * t, 0.7 - 0.04 * t, 0.5 + 0.01 * t],
    )


@pytest.mark.parametrize("dt", [0.1, 0.5])
def test_phone_probability_per_tick_matches_formula(dt):
    n = 20_000
    social = machine(human=exact_human(min_time_in_state=0.0, d_social=0.0, walking_d_social=0.0))
    state = make_state(spread(n))
    social.reset(state, None, np.random.default_rng(7))
    state.social[:] = 0.95
    social.pre(state, NO_ROBOTS, None, dt)
    expected = 1.0 - (1.0 - (0.95 - 0.80)) ** dt
    got = np.mean(state.social_state == S.PHONE)
    sd = math.sqrt(expected * (1 - expected) / n)
    assert abs(got - expected) < 4 * sd
    assert not np.any(state.social_state == S.RUNNING)  # energy 0.5 is below energy_hi
    assert not np.any(state.social_state == S.TALKING)  # nobody sees anybody
    np.testing.assert_allclose(state.vmax_factor[state.social_state == S.PHONE], 0.5)


# -- panic, running, elders ------------------------------------------------------------------
def test_panic_is_a_one_tick_transient_into_running():
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0]])
    social.reset(state, None, np.random.default_rng(0))
    state.stress[:] = 0.9
    social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] == S.PANIC
    assert state.stress[0] == pytest.approx(0.8)
    assert state.energy[0] == pytest.approx(0.8)  # raised to energy_hi
    assert state.vmax_factor[0] == 2.0
    social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] == S.RUNNING
    assert state.vmax_factor[0] == 2.0
    assert state.max_speeds[0] == pytest.approx(2.0)


def test_running_ends_when_energy_runs_low():
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0]])
    social.reset(state, None, np.random.default_rng(0))
    state.social_state[:] = S.RUNNING
    state.energy[:] = 0.25
    for _ in range(20):  # −0.04 /s: below energy_lo 0.2 after 1.25 s
        social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] in (S.WALKING, S.IDLE)


def test_elders_never_run():
    n = 2000
    kinds = np.where(np.arange(n) % 2 == 0, AgentType.ADULT, AgentType.ELDER)
    social = SocialStates()
    state = make_state(spread(n), kinds=kinds)
    social.reset(state, None, np.random.default_rng(3))
    state.energy[:] = 0.99
    elder = kinds == AgentType.ELDER
    adults_ran = np.zeros(n, dtype=bool)
    for _ in range(150):
        social.pre(state, NO_ROBOTS, None, 0.1)
        assert not np.any(state.social_state[elder] == S.RUNNING)
        adults_ran |= state.social_state == S.RUNNING
    assert adults_ran[~elder].mean() > 0.5  # the same drive makes adults run


# -- robots ---------------------------------------------------------------------------------------
def test_robot_fear_only_in_personal_space_and_more_for_fast_robots():
    human = exact_human(d_stress=0.0, walking_d_stress=0.0)
    social = machine(human=human, interested_in_robots=False)
    agents = np.array([[0.0, 0.0], [20.0, 0.0], [40.0, 0.0]])
    state = make_state(agents)
    social.reset(state, None, np.random.default_rng(0))
    robots = robots_at(
        [[0.5, 0.0], [20.5, 0.0], [41.5, 0.0]],  # inside, inside, outside (1.5 m > 1.0 m)
        [[0.2, 0.0], [1.5, 0.0], [3.0, 0.0]],  # slow, fast, very fast
    )
    dt = 0.01
    social.pre(state, robots, None, dt)
    rate = SocialStatesParams().fear_rate_hz
    np.testing.assert_allclose(
        state.stress, [dt * rate * 0.02, dt * rate * (0.02 + 1.5 - 0.7), 0.0]
    )


def test_fear_from_many_robots_adds_up():
    # More robots than the kernel sums itself: numpy's pairwise sum is passed in.
    human = exact_human(d_stress=0.0, walking_d_stress=0.0)
    social = machine(human=human, interested_in_robots=False)
    state = make_state([[0.0, 0.0], [20.0, 0.0]])
    social.reset(state, None, np.random.default_rng(0))
    r = K.MAX_SEQUENTIAL_ROBOTS + 2
    ring = 0.5 * np.stack([np.cos(np.arange(r)), np.sin(np.arange(r))], axis=1)
    robots = robots_at(ring, np.full((r, 2), [0.0, 1.0]))
    dt = 0.001
    social.pre(state, robots, None, dt)
    rate = SocialStatesParams().fear_rate_hz
    np.testing.assert_allclose(state.stress, [dt * rate * r * (0.02 + 1.0 - 0.7), 0.0])


def test_robot_avoidance_pushes_away_and_decays():
    prm = RobotAvoidanceParams(enabled=True, strength=2.0, range_factor=0.5, cutoff_factor=2.0)
    social = machine(robot_avoidance=prm, interested_in_robots=False)
    state = make_state([[1.0, 0.0], [0.0, 1.5], [0.0, -10.0]])
    social.reset(state, None, np.random.default_rng(0))
    robots = robots_at([[0.0, 0.0]], radius=0.2)
    a = social.robot_avoidance(state, robots)
    assert a[0, 0] > 0 and a[0, 1] == pytest.approx(0.0)  # away along +x
    assert a[1, 1] > 0 and a[1, 0] == pytest.approx(0.0)  # away along +y
    assert np.hypot(*a[0]) > np.hypot(*a[1])  # decays with distance
    np.testing.assert_array_equal(a[2], 0.0)  # beyond the cutoff
    gap0 = 1.0 - 0.3 - 0.2
    assert np.hypot(*a[0]) == pytest.approx(2.0 * math.exp(-gap0 / 0.5))
    social.pre(state, robots, None, 0.1)
    state.destinations[:] = [[9.0, 9.0]]  # away from the at-destination rule
    out = social.post(state, np.zeros((3, 2)), 0.1)
    np.testing.assert_allclose(out[0], a[0])
    assert "robot_avoidance" in state.forces


def test_interested_agent_approaches_robot_to_personal_space():
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0]], headings=[0.0])
    social.reset(state, None, np.random.default_rng(0))
    state.energy[:] = 0.9
    social.pre(state, robots_at([[3.0, 0.0]]), None, 0.1)
    assert state.social_state[0] == S.INTERACTING
    assert social.target_kind[0] == TARGET_ROBOT
    np.testing.assert_allclose(state.destinations[0], [2.0, 0.0])


def test_idle_agent_wakes_when_a_robot_comes_close():
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0]])
    social.reset(state, None, np.random.default_rng(0))
    state.social_state[:] = S.IDLE
    state.energy[:] = 0.3  # below the recovery level (0.5)
    social.pre(state, robots_at([[5.0, 5.0]]), None, 0.1)
    assert state.social_state[0] == S.IDLE
    social.pre(state, robots_at([[0.8, 0.0]]), None, 0.1)
    assert state.social_state[0] == S.WALKING


# -- perception, talking, interacting -------------------------------------------------------------
def test_vision_is_relative_to_heading():
    social = machine(human=exact_human(min_time_in_state=0.0))
    # Agent 0 looks up (+y): it sees agent 1 ahead at 3 m, not agent 2 to its right at 3 m.
    state = make_state([[0.0, 0.0], [0.0, 3.0], [3.0, 0.0]], headings=[np.pi / 2, 0.0, 0.0])
    social.reset(state, None, np.random.default_rng(0))
    state.social[:] = [0.9, 0.0, 0.0]
    social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] == S.TALKING
    assert social.target_index[0] == 1


def test_two_sociable_agents_gather_and_face_each_other():
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0], [4.0, 0.0]], headings=[0.0, np.pi])
    social.reset(state, None, np.random.default_rng(0))
    state.social[:] = 0.9
    social.pre(state, NO_ROBOTS, None, 0.1)
    assert (state.social_state == S.TALKING).all()
    np.testing.assert_array_equal(social.target_kind, [TARGET_AGENT, TARGET_AGENT])
    np.testing.assert_array_equal(social.target_index, [1, 0])
    # Each heads for the point at personal-space distance (1 m) from the other.
    np.testing.assert_allclose(state.destinations, [[3.0, 0.0], [1.0, 0.0]])
    for _ in range(100):
        step(social, state, NO_ROBOTS, 0.1)
    assert (state.social_state == S.TALKING).all()
    gap = np.hypot(*(state.positions[1] - state.positions[0]))
    assert gap == pytest.approx(1.0, abs=2 * social.params.gather_tolerance)
    assert social.gathered.all()
    np.testing.assert_array_equal(state.vmax_factor, 0.0)
    d = state.positions[1] - state.positions[0]
    facing = np.arctan2(d[1], d[0])
    assert math.cos(state.headings[0] - facing) == pytest.approx(1.0, abs=1e-9)
    assert math.cos(state.headings[1] - facing) == pytest.approx(-1.0, abs=1e-9)


def test_talking_ends_when_the_partner_is_lost():
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0], [3.0, 0.0]], headings=[0.0, np.pi])
    social.reset(state, None, np.random.default_rng(0))
    state.social[:] = [0.9, 0.0]
    social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] == S.TALKING
    state.positions[1] = [30.0, 0.0]
    social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] == S.WALKING
    assert social.target_index[0] == -1


def test_energetic_agent_interacts_with_a_seen_obstacle():
    box = np.array([[-0.5, -1.0], [0.5, -1.0], [0.5, 1.0], [-0.5, 1.0]])
    obstacle = Obstacle("box", "cuboid", np.array([3.5, 0.0, 0.0]), box)
    world = StaticWorld.build(OccupancyGrid.empty(20, 20, 0.1, origin=(-10, -10)), (obstacle,))
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0]], headings=[0.0])
    social.reset(state, world, np.random.default_rng(0))
    state.energy[:] = 0.9
    social.pre(state, NO_ROBOTS, world, 0.1)
    assert state.social_state[0] == S.INTERACTING
    assert social.target_kind[0] == TARGET_POINT
    np.testing.assert_allclose(social.target_point[0], [3.0, 0.0])
    np.testing.assert_allclose(state.destinations[0], [2.0, 0.0])
    state.positions[0] = [2.05, 0.0]
    state.headings[0] = 1.0
    social.pre(state, NO_ROBOTS, world, 0.1)
    assert social.gathered[0] and state.vmax_factor[0] == 0.0
    social.orient(state)
    assert state.headings[0] == pytest.approx(0.0)


# -- post and idle --------------------------------------------------------------------------------
def test_idle_agents_stand_and_resume_walking_after_recovering():
    social = machine(human=exact_human(min_time_in_state=0.0))
    state = make_state([[0.0, 0.0]])
    social.reset(state, None, np.random.default_rng(0))
    state.energy[:] = 0.1
    state.destinations[:] = [[10.0, 0.0]]
    social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] == S.IDLE
    assert state.vmax_factor[0] == 0.0
    state.velocities[:] = [[0.8, 0.1]]
    acc = social.post(state, np.array([[1.0, 0.0]]), 0.1)
    np.testing.assert_allclose(acc[0], [-8.0, -1.0])  # exactly cancels the velocity
    for _ in range(30):  # energy +0.16 /s from 0.1: recovered (0.5) after 2.5 s
        social.pre(state, NO_ROBOTS, None, 0.1)
    assert state.social_state[0] == S.WALKING
    assert state.vmax_factor[0] == 1.0


def test_at_destination_force_and_vmax_factor():
    social = machine()
    state = make_state([[0.0, 0.0], [5.0, 0.0]])
    social.reset(state, None, np.random.default_rng(0))
    state.destinations[:] = [[0.05, 0.0], [9.0, 0.0]]
    acc = social.post(state, np.array([[3.0, 4.0], [3.0, 4.0]]), 0.1)
    np.testing.assert_allclose(acc[0], [0.006, 0.008])
    np.testing.assert_allclose(acc[1], [3.0, 4.0])
    np.testing.assert_allclose(state.vmax_factor, [0.01, 1.0])


def test_min_time_in_state_blocks_early_transitions():
    social = machine(human=exact_human(min_time_in_state=1.0))
    state = make_state([[0.0, 0.0]])
    social.reset(state, None, np.random.default_rng(0))
    state.stress[:] = 0.95
    seen = []
    for _ in range(5):
        social.pre(state, NO_ROBOTS, None, 0.25)
        seen.append(int(state.social_state[0]))
    assert seen == [S.WALKING, S.WALKING, S.WALKING, S.PANIC, S.RUNNING]
    assert social.time_in_state[0] == 0.0


# -- determinism ----------------------------------------------------------------------------------
def _episode(seed: int) -> list[tuple[np.ndarray, ...]]:
    rng = np.random.default_rng(seed)
    n = 120
    box = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    obstacles = tuple(
        Obstacle(f"o{i}", "cuboid", np.array([x, y, 0.0]), box)
        for i, (x, y) in enumerate([(5, 5), (15, 15), (5, 15)])
    )
    world = StaticWorld.build(OccupancyGrid.empty(20, 20, 0.1), obstacles)
    pos = np.random.default_rng(99).uniform(1, 19, (n, 2))
    kinds = np.where(np.arange(n) % 5 == 0, AgentType.ELDER, AgentType.ADULT)
    state = make_state(pos, headings=np.linspace(-3, 3, n), kinds=kinds)
    social = SocialStates()
    social.reset(state, world, rng)
    state.energy[:] = np.linspace(0.3, 0.95, n)
    state.social[:] = np.linspace(0.95, 0.3, n)
    trace = []
    for k in range(150):
        robots = robots_at([[2 + 0.1 * k, 10.0]], [[1.0, 0.0]])
        step(social, state, robots, 0.1)
        trace.append((state.social_state.copy(), state.positions.copy(), state.stress.copy()))
    return trace


def test_same_seed_same_sequence():
    a, b, c = _episode(5), _episode(5), _episode(6)
    for x, y in zip(a, b, strict=True):
        for u, v in zip(x, y, strict=True):
            np.testing.assert_array_equal(u, v)
    assert any(not np.array_equal(x[0], y[0]) for x, y in zip(a, c, strict=True))
    states = np.concatenate([x[0] for x in a])
    assert {S.TALKING, S.INTERACTING, S.RUNNING} <= set(states.tolist())  # chart exercised


# -- kernels against the numpy reference ----------------------------------------------------------
def _perception_table(rng: np.random.Generator, n: int) -> np.ndarray:
    """A kernel parameter table with random vision and fear rows."""
    table = np.zeros((K.N_ROWS, n))
    table[K.VISION_RANGE] = rng.uniform(1.0, 6.0, n)
    table[K.VISION_HALF_ANGLE] = rng.uniform(0.2, np.pi, n)
    table[K.PSR] = rng.uniform(0.3, 1.5, n)
    table[K.VISION_NEAR] = 1.1 * table[K.PSR]
    table[K.FEAR_ROBOT] = rng.uniform(0.0, 0.1, n)
    table[K.FEAR_TOLERANCE] = rng.uniform(0.0, 1.0, n)
    return table


@pytest.mark.parametrize("lattice", [False, True])
@pytest.mark.parametrize("seed", range(4))
def test_kernel_perception_equals_the_numpy_reference(seed, lattice):
    rng = np.random.default_rng(seed)
    n = 40
    if lattice:  # whole metres: many exact distance ties, which must go the same way
        pos = rng.integers(0, 8, (n, 2)).astype(float)
        heads = rng.integers(-2, 3, n) * (np.pi / 2)
    else:
        pos = rng.uniform(0.0, 8.0, (n, 2))
        heads = rng.uniform(-np.pi, np.pi, n)
    table = _perception_table(rng, n)
    if lattice:
        table[K.VISION_HALF_ANGLE] = np.pi
    vis = (table[K.VISION_RANGE], table[K.VISION_HALF_ANGLE], table[K.VISION_NEAR])
    vision = Vision(*vis)
    box = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    obstacles = tuple(
        Obstacle(f"o{i}", "cuboid", np.array([x, y, 0.0]), box)
        for i, (x, y) in enumerate(rng.uniform(1.0, 7.0, (3, 2)))
    )
    world = StaticWorld.build(OccupancyGrid.empty(80, 80, 0.1), obstacles)
    index = WallIndex(*world_segments(world))
    arrays = P.wall_index_arrays(index)
    robot_pos = rng.uniform(0.0, 8.0, (K.MAX_SEQUENTIAL_ROBOTS, 2))
    robot_vel = rng.normal(0.0, 1.0, robot_pos.shape)
    everyone = np.arange(n)
    want_agent = nearest_seen_agents(vision, pos, heads, everyone)
    want_robot = nearest_seen_robots(vision, pos, heads, everyone, robot_pos)
    want_found, want_point = nearest_seen_wall_points(vision, pos, heads, everyone, index)
    want_fear = robot_fear(
        pos,
        table[K.PSR],
        table[K.FEAR_ROBOT],
        table[K.FEAR_TOLERANCE],
        RobotView(robot_pos, np.zeros(len(robot_pos)), robot_vel, np.full(len(robot_pos), 0.3)),
    )
    grid = P.cell_grid(pos, max(vision.reach, 1e-3))
    buf = np.empty(max(n, len(index)), dtype=np.int64)
    for i in range(n):
        assert P.nearest_seen_agent(vis, pos, heads, grid, vision.reach, i, buf) == want_agent[i]
        assert P.nearest_seen_robot(vis, pos, heads, robot_pos, i) == want_robot[i]
        found, x, y = P.nearest_seen_wall_point(vis, pos, heads, arrays, vision.reach, i, buf)
        assert found == want_found[i]
        assert (x, y) == tuple(want_point[i])
        assert K._fear(table, pos, robot_pos, robot_vel, i) == want_fear[i]
    assert (want_agent >= 0).sum() > n // 2 and want_found.sum() > 0  # the queries found things


def _cone_edge_cases(n: int = 3_000):
    """Points and headings with half-angles on the cone's edge: the bearing and one ulp beside.

    Returns ``(d, headings, half, bearing)``: ``(3n, 2)`` offsets (m), ``(3n,)`` headings,
    half-angles and numpy's bearings (rad). The bearing is the reference's own
    (``np.arctan2`` over an array, as :func:`~arena.crowd.social.perception.sees` computes it),
    so each point is specified: unseen at ``half == bearing`` (strict ``<``), seen one ulp wider,
    unseen one ulp narrower, whatever ``atan2`` this machine's libm or SIMD kernel has.
    """
    rng = np.random.default_rng(0)
    d = rng.normal(size=(n, 2)) * rng.uniform(0.01, 5.0, size=(n, 1))
    headings = rng.uniform(-np.pi, np.pi, n)
    bearing = np.abs(wrap_angle(np.arctan2(d[:, 1], d[:, 0]) - headings))
    half = np.concatenate([bearing, np.nextafter(bearing, np.inf), np.nextafter(bearing, 0.0)])
    return np.tile(d, (3, 1)), np.tile(headings, 3), half, np.tile(bearing, 3)


def test_vision_cone_edge_follows_the_numpy_reference_on_every_input():
    # The compiled query answers as the vectorised reference on the very edge of the cone, and
    # the edge itself is specified (strict <): no search for inputs where two atan2 differ.
    d, headings, half, bearing = _cone_edge_cases()
    m = len(half)
    want = bearing < half
    assert want.sum() == m // 3  # exactly the one-ulp-wider third is inside
    positions = np.zeros((m, 2))
    vision = Vision(np.full(m, 100.0), half, np.zeros(m))
    seen, _ = P.sees(vision, np.arange(m), positions, headings, d)
    np.testing.assert_array_equal(seen, want)
    vis = (vision.range, vision.half_angle, vision.near)
    got = [P.sees_one(vis, positions, headings, i, d[i, 0], d[i, 1])[0] for i in range(m)]
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("ulps", [-4, -1, 1, 4])
def test_vision_cone_edge_ignores_an_atan2_off_in_the_last_bits(monkeypatch, ulps):
    # Whether this CPU's numpy and libm atan2 differ is not up to the test: the kernel's own
    # code runs (uncompiled) with a libm atan2 made off by a few ulps, and must still decide the
    # edge as numpy does. Without the re-check near the edge this fails on every machine.
    import types

    def off_atan2(y: float, x: float) -> float:
        r = math.atan2(y, x)
        for _ in range(abs(ulps)):
            r = math.nextafter(r, math.copysign(math.inf, ulps))
        return r

    P._wrap(0.5), P._numpy_atan2(1.0, 2.0)  # compiled before math is swapped in their module
    monkeypatch.setattr(P, "math", types.SimpleNamespace(atan2=off_atan2, pi=math.pi))
    d, headings, half, bearing = _cone_edge_cases(1_000)
    got = [
        P._in_cone.py_func(d[i, 0], d[i, 1], headings[i], half[i]) for i in range(len(half))
    ]
    np.testing.assert_array_equal(got, bearing < half)
