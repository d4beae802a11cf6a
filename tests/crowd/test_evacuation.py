"""Evacuation (Helbing, Farkas & Vicsek 2000) and bonding models: hand-derived forces."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.crowd.base import CROWD_MODELS, CrowdFrame, RobotView
from arena.crowd.models.bonding import Bonding, group_partners
from arena.crowd.models.evacuation.model import Evacuation
from arena.crowd.neighbors import find_neighbors
from arena.crowd.state import CrowdState
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import AgentSpawn
from arena.scene.state import StaticWorld
from arena.testing.conformance import check_crowd_model

A, B, K, KAPPA, M, TAU = 2000.0, 0.08, 1.2e5, 2.4e5, 80.0, 0.5
NO_WALLS = (np.zeros((0, 2)), np.zeros((0, 2)))


def make_state(positions, *, radius=0.3, vmax=100.0, velocities=None, groups=None) -> CrowdState:
    """Agents whose only waypoint is where they stand (so the desired term is just −v/τ)."""
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    n = len(p)
    spawn = AgentSpawn(
        positions=p,
        radii=np.full(n, radius),
        vmax=np.full(n, vmax),
        waypoints=p[:, None, :].copy(),
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        kinds=np.zeros(n, dtype=np.int64),
        groups=None if groups is None else np.asarray(groups, dtype=np.int64),
    )
    s = CrowdState.from_spawn(spawn)
    if velocities is not None:
        s.velocities = np.asarray(velocities, dtype=float).reshape(n, 2)
    return s


def make_frame(
    model, state, *, dt=0.001, dest=None, active=None, robots=None, walls=NO_WALLS
) -> CrowdFrame:
    n = len(state)
    return CrowdFrame(
        state=state,
        destinations=state.positions.copy() if dest is None else np.asarray(dest, dtype=float),
        active=np.ones(n, dtype=bool) if active is None else np.asarray(active, dtype=bool),
        robots=robots or RobotView.empty(),
        walls_a=walls[0],
        walls_b=walls[1],
        neighbors=find_neighbors(state.positions, model.neighbor_cutoff()),
        dt=dt,
        rng=np.random.default_rng(0),
    )


# dt = 0.001 s ≤ max_substep: one sub-step, so the output is the plain force at the state.


def test_contact_pair_body_force_by_hand():
    overlap = 0.05
    s = make_state([[0.0, 0.0], [0.6 - overlap, 0.0]])
    model = Evacuation()
    out = model.compute(make_frame(model, s))
    social = A * math.exp(overlap / B) / M
    body = K * overlap / M
    assert out.forces["social"][0] == pytest.approx([-social, 0.0], rel=1e-12)
    assert out.forces["body"][0] == pytest.approx([-body, 0.0], rel=1e-12)
    assert out.forces["friction"][0] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert out.accelerations[0] == pytest.approx([-(social + body), 0.0], rel=1e-12)
    assert out.accelerations[1] == pytest.approx([social + body, 0.0], rel=1e-12)
    # The pair term alone, by hand: 2000·e^(0.625) + 1.2e5·0.05 N ≈ 9736.5 N.
    assert (social + body) * M == pytest.approx(9736.49, abs=0.05)


def test_no_contact_no_body_force():
    gap = 0.2
    s = make_state([[0.0, 0.0], [0.6 + gap, 0.0]])
    model = Evacuation()
    out = model.compute(make_frame(model, s))
    assert out.forces["social"][0] == pytest.approx([-A * math.exp(-gap / B) / M, 0.0])
    assert np.all(out.forces["body"] == 0.0) and np.all(out.forces["friction"] == 0.0)


def test_sliding_friction_along_tangent_with_right_sign():
    overlap = 0.05
    # Agent 1 slides past agent 0 in +y: 0 is dragged along (+y), 1 is held back (−y).
    s = make_state([[0.0, 0.0], [0.6 - overlap, 0.0]], velocities=[[0.0, 0.0], [0.0, 1.0]])
    model = Evacuation()
    out = model.compute(make_frame(model, s))
    fr = KAPPA * overlap * 1.0 / M  # κ·g·|Δv_t| / m = 150 m/s²
    assert out.forces["friction"][0] == pytest.approx([0.0, fr], rel=1e-12)
    assert out.forces["friction"][1] == pytest.approx([0.0, -fr], rel=1e-12)
    # Friction is tangential: no component along the contact normal (x).
    assert out.forces["friction"][:, 0] == pytest.approx([0.0, 0.0], abs=1e-12)


def test_wall_repulsion_and_wall_friction_by_hand():
    overlap = 0.05
    s = make_state([[1.0, 0.3 - overlap]], velocities=[[1.0, 0.0]])
    walls = (np.array([[0.0, 0.0]]), np.array([[2.0, 0.0]]))
    model = Evacuation()
    out = model.compute(make_frame(model, s, walls=walls))
    push = (A * math.exp(overlap / B) + K * overlap) / M
    rub = KAPPA * overlap * 1.0 / M  # opposes the motion along the wall
    assert out.forces["obstacle"][0] == pytest.approx([-rub, push], rel=1e-12)
    # Far from every wall: nothing.
    far = make_state([[1.0, 5.0]])
    out = model.compute(make_frame(model, far, walls=walls))
    assert np.all(out.forces["obstacle"] == 0.0)


def test_wall_segments_from_reset_world():
    grid = OccupancyGrid.empty(6.0, 4.0, 0.05)  # one-cell walls; inner faces at 0.05 m
    model = Evacuation()
    s = make_state([[3.0, 0.05 + 0.3]])  # touching the bottom wall's inner face
    model.reset(s, StaticWorld.build(grid), np.random.default_rng(0))
    from arena.crowd.walls import world_segments

    frame = make_frame(model, s, walls=world_segments(StaticWorld.build(grid)))
    out = model.compute(frame)
    # Only the inner face is a segment (outside the map counts as blocking): A/m at contact.
    expected = A / M
    assert out.forces["obstacle"][0] == pytest.approx([0.0, expected], rel=1e-9)


def test_robot_as_body_and_switch():
    overlap = 0.05
    s = make_state([[0.0, 0.0]])
    robots = RobotView(
        np.array([[0.3 + 0.2 - overlap, 0.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.2])
    )
    model = Evacuation()
    out = model.compute(make_frame(model, s, robots=robots))
    assert out.forces["robot"][0] == pytest.approx(
        [-(A * math.exp(overlap / B) + K * overlap) / M, 0.0], rel=1e-12
    )
    off = Evacuation(Evacuation.Params(robots_as_bodies=False))
    assert np.all(off.compute(make_frame(off, s, robots=robots)).forces["robot"] == 0.0)


def test_desired_term_uses_vmax_factor_and_tau():
    s = make_state([[0.0, 0.0]], vmax=1.2)
    s.vmax_factor[:] = 2.0
    model = Evacuation()
    out = model.compute(make_frame(model, s, dest=[[10.0, 0.0]]))
    assert out.forces["desired"][0] == pytest.approx([2.4 / TAU, 0.0])


def test_inactive_agents_get_zero_but_still_repel():
    s = make_state([[0.0, 0.0], [0.7, 0.0]])
    model = Evacuation()
    out = model.compute(make_frame(model, s, active=[False, True]))
    assert np.all(out.accelerations[0] == 0.0)
    assert all(np.all(f[0] == 0.0) for f in out.forces.values())
    assert out.accelerations[1, 0] == pytest.approx(A * math.exp(-0.1 / B) / M)


def simulate(model, state, dest, dt, steps, cap):
    """The simulator's update (v += a·dt, speed cap, x += v·dt) around ``model``."""
    for _ in range(steps):
        out = model.compute(make_frame(model, state, dt=dt, dest=dest))
        v = state.velocities + out.accelerations * dt
        v *= np.minimum(1.0, cap / np.maximum(np.hypot(*v.T), 1e-300))[:, None]
        state.velocities = v
        state.positions = state.positions + v * dt
    return out


def test_substeps_land_where_fine_integration_goes():
    """Two steps of 0.1 s put agents exactly where 40 plain 5 ms steps do.

    Within a step the model integrates 20 sub-steps and returns the acceleration that makes
    the simulator's velocity the mean sub-stepped velocity (so positions match); the next step
    resumes from the true end velocity it remembered.
    """
    pos = [[0.0, 0.0], [0.58, 0.05], [0.3, 0.5]]  # in contact: body and friction act
    vel = [[-0.5, 0.0], [0.5, 0.2], [0.1, 0.4]]
    # Moving and heading apart, so contacts only soften and the fine reference never needs
    # shorter steps than the coarse step chose at its start.
    dest = np.array([[-5.0, 0.0], [5.0, 0.0], [0.0, 5.0]])
    coarse, fine = make_state(pos, vmax=1.5, velocities=vel), make_state(pos, vmax=1.5)
    fine.velocities = coarse.velocities.copy()
    model, reference = Evacuation(), Evacuation()
    for _ in range(2):
        out = simulate(model, coarse, dest, 0.1, 1, 1.5)
        n = model.last_substeps
        assert n >= 20  # at least 0.1 / max_substep
        np.testing.assert_allclose(sum(out.forces.values()), out.accelerations, atol=1e-9)
        simulate(reference, fine, dest, 0.1 / n, n, 1.5)
        assert reference.last_substeps == 1
        np.testing.assert_allclose(coarse.positions, fine.positions, atol=1e-9)
    # The simulator holds the mean velocity of the last step; the model continues from the
    # true one (the "carry" term of the next step bridges the two).
    out = model.compute(make_frame(model, coarse, dt=0.1, dest=dest))
    assert np.any(np.abs(out.forces["carry"]) > 1e-3)


def test_deep_overlap_resolves_without_jitter():
    """Agents spawned almost on top of each other separate within a few steps at dt = 0.1."""
    model = Evacuation()
    s = make_state([[0.0, 0.0], [0.1, 0.0]], vmax=1.5)
    dest = np.array([[-3.0, 0.0], [3.0, 0.0]])  # overlap 0.5 m: contact force ≈ 8.7e5 N
    simulate(model, s, dest, 0.1, 1, 1.5)
    assert model.last_substeps > 20  # stiff contact: shorter sub-steps than max_substep
    assert np.hypot(*(s.positions[1] - s.positions[0])) > 0.38  # apart at the cap, 2·1.5·0.1
    simulate(model, s, dest, 0.1, 2, 1.5)
    assert np.hypot(*(s.positions[1] - s.positions[0])) > 0.6  # out of contact
    assert model.last_substeps == 20
    # Symmetric, along the line of centres, at most the cap: no jitter.
    np.testing.assert_allclose(s.velocities[0], -s.velocities[1], atol=1e-12)
    assert np.all(s.velocities[:, 1] == 0.0) and np.all(np.hypot(*s.velocities.T) <= 1.5)


def test_deterministic_and_inputs_not_mutated():
    rng = np.random.default_rng(4)
    pos = rng.uniform(1.0, 9.0, (40, 2))
    s = make_state(pos, vmax=1.3, velocities=rng.normal(0, 0.5, (40, 2)), groups=np.arange(40) % 7)
    grid = OccupancyGrid.empty(10.0, 10.0, 0.05)
    from arena.crowd.walls import world_segments

    walls = world_segments(StaticWorld.build(grid))
    robots = RobotView(np.array([[5.0, 5.0]]), np.zeros(1), np.array([[0.5, 0.0]]), np.array([0.3]))
    dest = rng.uniform(1.0, 9.0, (40, 2))
    for cls in (Evacuation, Bonding):
        model = cls()
        frame = make_frame(model, s, dt=0.1, dest=dest, robots=robots, walls=walls)
        kept = [a.copy() for a in (s.positions, s.velocities, s.vmax, frame.destinations,
                                   frame.active, robots.positions, walls[0])]  # fmt: skip
        a = model.compute(frame)
        b = cls().compute(frame)
        assert np.array_equal(a.accelerations, b.accelerations)
        assert np.all(np.isfinite(a.accelerations))
        after = (s.positions, s.velocities, s.vmax, frame.destinations, frame.active,
                 robots.positions, walls[0])  # fmt: skip
        for x, y in zip(kept, after, strict=True):
            assert np.array_equal(x, y)


def test_bonded_agents_attract_beyond_comfort_distance():
    d = 2.0  # gap between surfaces 1.4 m, 0.9 m beyond the 0.5 m comfort gap
    model = Bonding()
    related = make_state([[0.0, 0.0], [d, 0.0]], groups=[3, 3])
    out = model.compute(make_frame(model, related))
    pull = 200.0 * (1.0 - math.exp(-(d - 0.6 - 0.5) / 1.0)) / M
    assert out.forces["bonding"][0] == pytest.approx([pull, 0.0], rel=1e-12)
    assert out.forces["bonding"][1] == pytest.approx([-pull, 0.0], rel=1e-12)
    # Unrelated (alone or different groups): no bonding.
    for groups in ([-1, -1], [1, 2]):
        s = make_state([[0.0, 0.0], [d, 0.0]], groups=groups)
        assert np.all(model.compute(make_frame(model, s)).forces["bonding"] == 0.0)
    # Within the comfort distance: no pull.
    close = make_state([[0.0, 0.0], [1.0, 0.0]], groups=[0, 0])
    assert np.all(model.compute(make_frame(model, close)).forces["bonding"] == 0.0)
    # Beyond the neighbour cutoff the bond still acts, saturating toward C/m.
    far = make_state([[0.0, 0.0], [30.0, 0.0]], groups=[0, 0])
    f = model.compute(make_frame(model, far)).forces["bonding"][0, 0]
    assert 0.99 * 200.0 / M < f <= 200.0 / M
    # The plain evacuation model has no bonding term.
    assert "bonding" not in Evacuation().compute(make_frame(Evacuation(), related)).forces


def test_bonding_pulls_members_together_over_time():
    model = Bonding()
    # Standing agents (destination = start) with a weak desired term (v0/τ = 1 m/s²) that the
    # ≈ 2.1 m/s² bond overcomes.
    pos = [[0.0, 0.0], [3.0, 0.0], [0.0, 3.0], [3.0, 3.0]]
    s = make_state(pos, vmax=0.5, groups=[0, 0, -1, 1])
    for _ in range(30):
        acc = model.compute(make_frame(model, s, dt=0.1, dest=s.waypoints[:, 0])).accelerations
        s.velocities = s.velocities + acc * 0.1
        s.positions = s.positions + s.velocities * 0.1
    assert np.hypot(*(s.positions[1] - s.positions[0])) < 2.5  # the pair closed in
    assert np.allclose(s.positions[2:], [[0.0, 3.0], [3.0, 3.0]], atol=1e-6)  # loners stay


def test_group_partners():
    ptr, idx = group_partners(np.array([0, -1, 0, 1, 1, 0]))
    got = [sorted(idx[ptr[i] : ptr[i + 1]].tolist()) for i in range(6)]
    assert got == [[2, 5], [], [0, 5], [4], [3], [0, 2]]


def test_registered_and_params():
    assert "evacuation" in CROWD_MODELS.names("panic")
    assert "bonding" in CROWD_MODELS.names("panic")
    m = CROWD_MODELS.build({"type": "evacuation", "mass": 180.0, "tau": 1.0})
    assert isinstance(m, Evacuation) and m.params.mass == 180.0
    b = CROWD_MODELS.build({"type": "bonding", "bond_strength": 100.0})
    assert isinstance(b, Bonding) and b.params.bond_strength == 100.0
    with pytest.raises(Exception):  # noqa: B017  (unknown keys are rejected)
        CROWD_MODELS.build({"type": "evacuation", "bogus": 1})


@pytest.mark.parametrize("cls", [Evacuation, Bonding])
def test_conformance(cls):
    check_crowd_model(cls)
