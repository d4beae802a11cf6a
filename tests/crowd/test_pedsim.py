"""libpedsim's social force (``pedsim``, ``passthrough``): each term against hand-derived values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from arena.crowd.base import CROWD_MODELS, CrowdFrame, RobotView
from arena.crowd.models.pedsim.model import TERMS, PassthroughModel, PedsimModel, _deviation
from arena.crowd.neighbors import find_neighbors
from arena.crowd.state import CrowdState
from arena.crowd.walls import grid_wall_segments
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import AgentSpawn
from arena.scene.state import StaticWorld

NO_WALLS = (np.zeros((0, 2)), np.zeros((0, 2)))


def quiet(**kw: object) -> PedsimModel:
    """A pedsim model without the random term (exact comparisons), other params as given."""
    return PedsimModel(PedsimModel.Params(**{"force_factor_random": 0.0, **kw}))


def make_frame(
    positions: object,
    velocities: object | None = None,
    destinations: object | None = None,
    *,
    radii: float = 0.3,
    vmax: float = 1.0,
    active: object | None = None,
    robots: RobotView | None = None,
    walls: tuple[np.ndarray, np.ndarray] = NO_WALLS,
    cutoff: float = 10.0,
    seed: int = 0,
    time: float = 0.0,
) -> CrowdFrame:
    """A hand-built frame: agents at ``positions`` with the given state, neighbours found."""
    pos = np.array(positions, dtype=np.float64).reshape(-1, 2)
    n = len(pos)
    dest = pos.copy() if destinations is None else np.array(destinations, dtype=np.float64)
    spawn = AgentSpawn(
        positions=pos,
        radii=np.full(n, radii),
        vmax=np.full(n, vmax),
        waypoints=dest[:, None, :].copy(),
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        kinds=np.zeros(n, dtype=np.int64),
    )
    state = CrowdState.from_spawn(spawn)
    if velocities is not None:
        state.velocities = np.array(velocities, dtype=np.float64).reshape(n, 2)
    state.time = time
    act = np.ones(n, dtype=bool) if active is None else np.array(active, dtype=bool)
    return CrowdFrame(
        state=state,
        destinations=dest,
        active=act,
        robots=robots if robots is not None else RobotView.empty(),
        walls_a=walls[0],
        walls_b=walls[1],
        neighbors=find_neighbors(pos, cutoff),
        dt=0.1,
        rng=np.random.default_rng(seed),
    )


def room_walls(size: float = 10.0) -> tuple[np.ndarray, np.ndarray]:
    """Walls on the edges of a free ``size × size`` m map: x = 0, x = size, y = 0, y = size."""
    return grid_wall_segments(OccupancyGrid.empty(size, size, 0.1, walls=False))


def libpedsim_pair(
    pi: np.ndarray, pj: np.ndarray, vi: np.ndarray, vj: np.ndarray, gap: float
) -> np.ndarray:
    """libpedsim's socialForce contribution of j on i, written out literally (unscaled).

    ``gap`` is the distance used in the exponent (edge-to-edge for Arena's libpedsim).
    Uses two polar angles and Tangle's wrap to (−π, π], as ``Tvector::angleTo`` does.
    """
    lam, gamma, n, n_prime = 2.0, 0.35, 2.0, 3.0
    diff = pj - pi
    e = diff / np.linalg.norm(diff)
    t = lam * (vi - vj) + e
    t_len = float(np.linalg.norm(t))
    t_dir = t / t_len
    theta = math.atan2(e[1], e[0]) - math.atan2(t_dir[1], t_dir[0])
    while theta <= -math.pi:
        theta += 2 * math.pi
    while theta > math.pi:
        theta -= 2 * math.pi
    b = gamma * t_len
    f_vel = -math.exp(-gap / b - (n_prime * b * theta) ** 2)
    f_ang = -np.sign(theta) * math.exp(-gap / b - (n * b * theta) ** 2)
    return f_vel * t_dir + f_ang * np.array([-t_dir[1], t_dir[0]])


# -- registry and parameters -------------------------------------------------------------------


def test_registered_with_libpedsim_defaults() -> None:
    assert CROWD_MODELS.get("pedsim") is PedsimModel
    assert CROWD_MODELS.get("passthrough") is PassthroughModel
    assert "social_force" in CROWD_MODELS.entry("pedsim").tags
    p = PedsimModel().params
    assert (p.relaxation_time, p.force_factor_desired, p.force_factor_social) == (0.5, 1.0, 2.1)
    assert (p.force_factor_obstacle, p.sigma_obstacle, p.obstacle_force_range) == (10.0, 0.8, 2.0)
    assert (p.lambda_importance, p.gamma, p.n, p.n_prime) == (2.0, 0.35, 2.0, 3.0)
    assert (p.keep_distance, p.force_factor_random) == (0.8, 0.1)
    assert PedsimModel().neighbor_cutoff() == 10.0
    assert quiet(neighborhood_range=4.0).neighbor_cutoff() == 4.0


def test_params_are_frozen_and_strict() -> None:
    with pytest.raises(ValidationError):
        PedsimModel.Params(force_social=5.1)  # type: ignore[call-arg]
    with pytest.raises(ValidationError):
        PedsimModel.Params(relaxation_time=0.0)
    built = CROWD_MODELS.build({"type": "pedsim", "force_factor_social": 5.1}, path="crowd")
    assert built.params.force_factor_social == 5.1
    with pytest.raises(ValidationError):
        built.params.gamma = 1.0  # type: ignore[misc]


# -- desired ------------------------------------------------------------------------------------


def test_desired_term_is_the_speed_gap_over_tau() -> None:
    v = np.array([0.2, -0.1])
    fr = make_frame([[1.0, 1.0]], [v], [[4.0, 5.0]], vmax=1.2)
    out = quiet().compute(fr)
    e = np.array([3.0, 4.0]) / 5.0
    expected = (e * 1.2 - v) / 0.5
    assert np.allclose(out.forces["desired"][0], expected, rtol=1e-14, atol=0)
    assert np.allclose(out.accelerations, expected[None], rtol=1e-14, atol=0)


def test_desired_term_scales_with_factor_and_vmax_factor() -> None:
    v = np.array([0.3, 0.0])
    fr = make_frame([[0.0, 0.0]], [v], [[0.0, 2.0]], vmax=1.0)
    fr.state.vmax_factor[:] = 0.5  # social states slow the agent down to 0.5 m/s
    out = quiet(force_factor_desired=3.0, relaxation_time=0.25).compute(fr)
    expected = 3.0 * (np.array([0.0, 0.5]) - v) / 0.25
    assert np.allclose(out.forces["desired"][0], expected, rtol=1e-14, atol=0)


def test_desired_term_brakes_at_or_without_a_destination() -> None:
    v = np.array([0.4, 0.2])
    at_goal = make_frame([[1.0, 1.0]], [v], [[1.0, 1.0]])
    assert np.allclose(quiet().compute(at_goal).forces["desired"][0], -v / 0.5)
    no_goal = make_frame([[1.0, 1.0]], [v], [[np.nan, np.nan]])
    assert np.allclose(quiet().compute(no_goal).forces["desired"][0], -v / 0.5)


# -- social -------------------------------------------------------------------------------------


def test_social_force_of_two_agents_at_rest() -> None:
    fr = make_frame([[0.0, 0.0], [2.0, 0.0]])
    soc = quiet().compute(fr).forces["social"]
    # At rest t = ê, θ = 0, B = γ; edge gap d = 2 − 0.3 − 0.3 = 1.4 m.
    expected = -2.1 * math.exp(-1.4 / 0.35)
    assert soc[0] == pytest.approx([expected, 0.0], rel=1e-13, abs=1e-300)
    assert np.array_equal(soc[1], -soc[0])


def test_social_forces_push_facing_agents_apart_antisymmetrically() -> None:
    fr = make_frame([[0.0, 0.0], [3.0, 0.0]], [[1.0, 0.0], [-1.0, 0.0]])
    soc = quiet().compute(fr).forces["social"]
    # t = λ·(v0 − v1) + ê = 2·(2, 0) + (1, 0) = (5, 0): B = 0.35·5 = 1.75, θ = 0.
    expected = -2.1 * math.exp(-(3.0 - 0.6) / 1.75)
    assert soc[0] == pytest.approx([expected, 0.0], rel=1e-13, abs=1e-300)
    assert soc[0, 0] < 0.0 < soc[1, 0]
    assert np.array_equal(soc[1], -soc[0])


def test_social_force_mirror_symmetric_configuration() -> None:
    # Mirror images across x = 0 (positions and velocities): forces mirror, and the pair force is
    # antisymmetric, F_10 = −F_01.
    fr = make_frame([[-1.0, 0.3], [1.0, 0.3]], [[0.5, 0.2], [-0.5, 0.2]])
    soc = quiet().compute(fr).forces["social"]
    assert np.array_equal(soc[1], -soc[0])
    assert soc[0, 0] < 0.0
    assert soc[0, 0] == -soc[1, 0] and soc[0, 1] == -soc[1, 1]


@pytest.mark.parametrize("subtract_radii", [True, False])
def test_social_force_matches_libpedsim_literal_formula(subtract_radii: bool) -> None:
    rng = np.random.default_rng(42)
    pos = rng.uniform(0.0, 6.0, (12, 2))
    vel = rng.normal(0.0, 0.8, (12, 2))
    fr = make_frame(pos, vel, radii=0.25)
    soc = quiet(subtract_radii=subtract_radii).compute(fr).forces["social"]
    expected = np.zeros_like(pos)
    for i in range(len(pos)):
        for j in range(len(pos)):
            dist = float(np.linalg.norm(pos[j] - pos[i]))
            if i == j or dist >= 10.0:
                continue
            gap = dist - 0.5 if subtract_radii else dist
            gap = gap if gap > 0 else 0.01
            expected[i] += libpedsim_pair(pos[i], pos[j], vel[i], vel[j], gap)
    assert np.allclose(soc, 2.1 * expected, rtol=1e-11, atol=1e-14)
    assert np.allclose(soc.sum(axis=0), 0.0, atol=1e-12)  # pairwise antisymmetric


def test_overlapping_agents_use_arenas_small_gap() -> None:
    fr = make_frame([[0.0, 0.0], [0.4, 0.0]])  # 0.4 m apart, radii 0.3: overlapping
    soc = quiet().compute(fr).forces["social"]
    assert soc[0] == pytest.approx([-2.1 * math.exp(-0.01 / 0.35), 0.0], rel=1e-13)


def test_social_force_vanishes_beyond_the_cutoff() -> None:
    near = quiet().compute(make_frame([[0.0, 0.0], [9.9, 0.0]])).forces["social"]
    assert near[0, 0] < 0.0  # tiny but present inside the 10 m neighbourhood
    far = quiet().compute(make_frame([[0.0, 0.0], [10.5, 0.0]])).forces["social"]
    assert np.array_equal(far, np.zeros((2, 2)))
    # Even if the caller lists neighbours from a wider search, the model's range applies.
    wide = make_frame([[0.0, 0.0], [6.0, 0.0]], cutoff=10.0)
    assert np.array_equal(quiet(neighborhood_range=5.0).compute(wide).forces["social"], 0 * near)


@pytest.mark.parametrize(
    ("v0", "v1"),
    [
        ((-0.25, 0.0), (0.25, 0.0)),  # λ·Δv = −ê exactly: no interaction direction
        ((-0.2499, 0.0), (0.25, 0.0)),  # |t| = 2e-4: B tiny, e^(−d/B) underflows to 0
        ((-0.5, 0.0), (0.5, 0.0)),  # t = −ê: θ = π (libpedsim's Tangle wraps −π to +π)
        ((0.0, 0.4), (0.1, -0.3)),
    ],
)
def test_degenerate_interaction_vectors(v0: tuple[float, float], v1: tuple[float, float]) -> None:
    pos = np.array([[0.0, 0.0], [2.0, 0.0]])
    vel = np.array([v0, v1])
    soc = quiet().compute(make_frame(pos, vel)).forces["social"]
    assert np.all(np.isfinite(soc))
    t = 2.0 * (vel[0] - vel[1]) + np.array([1.0, 0.0])
    expected = np.zeros(2) if not t.any() else libpedsim_pair(pos[0], pos[1], vel[0], vel[1], 1.4)
    assert np.allclose(soc[0], 2.1 * expected, rtol=1e-12, atol=1e-300)
    assert np.array_equal(soc[1], -soc[0])


def test_coincident_agents_are_skipped_not_nan() -> None:
    out = quiet().compute(make_frame([[1.0, 1.0], [1.0, 1.0]]))
    assert np.all(np.isfinite(out.accelerations))
    assert np.array_equal(out.forces["social"], np.zeros((2, 2)))


# -- obstacle -----------------------------------------------------------------------------------


def test_obstacle_force_points_away_from_the_nearest_wall_and_decays() -> None:
    walls = room_walls(10.0)
    fr = make_frame([[1.0, 5.0], [1.5, 5.0], [5.0, 8.8]], walls=walls)
    obs = quiet().compute(fr).forces["obstacle"]
    # Nearest wall x = 0 at 1.0 m and 1.5 m; radius 0.3: 10·exp(−(d − 0.3)/0.8) along +x.
    assert obs[0] == pytest.approx([10.0 * math.exp(-(1.0 - 0.3) / 0.8), 0.0], rel=1e-13)
    assert obs[1] == pytest.approx([10.0 * math.exp(-(1.5 - 0.3) / 0.8), 0.0], rel=1e-13)
    assert obs[0, 0] > obs[1, 0] > 0.0
    # Wall y = 10 at 1.2 m above: pushed down.
    assert obs[2] == pytest.approx([0.0, -10.0 * math.exp(-(1.2 - 0.3) / 0.8)], rel=1e-13)


def test_obstacle_force_uses_only_the_nearest_wall_within_range() -> None:
    walls = room_walls(10.0)
    # In a corner both walls are close, but only the nearer one (x = 0 at 0.6 m) counts.
    corner = quiet().compute(make_frame([[0.6, 0.9]], walls=walls)).forces["obstacle"]
    assert corner[0, 1] == 0.0 and corner[0, 0] > 0.0
    # Farther than obstacle_force_range (2 m) from every wall: no force.
    middle = quiet().compute(make_frame([[5.0, 5.0]], walls=walls)).forces["obstacle"]
    assert np.array_equal(middle, np.zeros((1, 2)))
    wide = quiet(obstacle_force_range=10.0).compute(make_frame([[5.0, 3.0]], walls=walls))
    assert wide.forces["obstacle"][0] == pytest.approx(
        [0.0, 10.0 * math.exp(-(3.0 - 0.3) / 0.8)], rel=1e-13
    )


def test_reset_indexes_the_world_walls() -> None:
    grid = OccupancyGrid.empty(10.0, 10.0, 0.1, walls=False)
    world = StaticWorld.build(grid)
    model = quiet()
    fr = make_frame([[1.0, 5.0]], walls=grid_wall_segments(grid))
    model.reset(fr.state, world, np.random.default_rng(0))
    assert model.compute(fr).forces["obstacle"][0] == pytest.approx(
        [10.0 * math.exp(-0.7 / 0.8), 0.0], rel=1e-13
    )


# -- robot --------------------------------------------------------------------------------------


def test_robot_force_repels_from_a_robot() -> None:
    robots = RobotView(np.array([[2.0, 0.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.4]))
    fr = make_frame([[0.0, 0.0], [0.0, 3.0]], robots=robots, vmax=1.0)
    out = quiet().compute(fr)
    # σ_robot = 0.3·vmax/0.4 = 0.75 s·m/s; edge distance 2 − 0.3 − 0.4 = 1.3 m; factor 2.
    assert out.forces["robot"][0] == pytest.approx([-2.0 * math.exp(-1.3 / 0.75), 0.0], rel=1e-13)
    d = np.array([2.0, -3.0])
    amount = -2.0 * math.exp(-(np.linalg.norm(d) - 0.7) / 0.75)
    assert out.forces["robot"][1] == pytest.approx(amount * d / np.linalg.norm(d), rel=1e-13)
    # Robots are not pedestrians: the social term is the same as without the robot.
    no_robot = quiet().compute(make_frame([[0.0, 0.0], [0.0, 3.0]], vmax=1.0))
    assert np.array_equal(out.forces["social"], no_robot.forces["social"])


def test_robot_force_off_by_factor_and_beyond_range() -> None:
    robots = RobotView(np.array([[2.0, 0.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.4]))
    fr = make_frame([[0.0, 0.0]], robots=robots)
    assert np.array_equal(quiet(force_factor_robot=0.0).compute(fr).forces["robot"], [[0, 0]])
    far = RobotView(np.array([[12.0, 0.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.4]))
    fr_far = make_frame([[0.0, 0.0]], robots=far)
    assert np.array_equal(quiet().compute(fr_far).forces["robot"], [[0.0, 0.0]])


# -- keep distance --------------------------------------------------------------------------------


def test_keep_distance_spring_only_where_a_centre_is_set() -> None:
    fr = make_frame([[2.0, 0.0], [0.0, 3.0]])
    model = quiet()
    assert np.array_equal(model.compute(fr).forces["keep_distance"], np.zeros((2, 2)))
    model.set_keep_distance_targets(np.array([[0.0, 0.0], [np.nan, np.nan]]))
    keep = model.compute(fr).forces["keep_distance"]
    # −10·(|p − c| − 0.8)·unit(p − c): 1.2 m too far, pulled back with 12 m/s².
    assert keep[0] == pytest.approx([-12.0, 0.0], rel=1e-14)
    assert np.array_equal(keep[1], np.zeros(2))
    model.set_keep_distance_targets(np.array([[1.5, 0.0], [np.nan, np.nan]]))
    assert model.compute(fr).forces["keep_distance"][0] == pytest.approx([3.0, 0.0])  # too close
    model.reset(fr.state, StaticWorld.build(OccupancyGrid.empty(4.0, 4.0)), fr.rng)
    assert np.array_equal(model.compute(fr).forces["keep_distance"], np.zeros((2, 2)))


# -- random -------------------------------------------------------------------------------------


def test_random_term_is_zero_without_factor_and_draws_nothing() -> None:
    fr = make_frame([[0.0, 0.0], [3.0, 3.0]])
    before = fr.rng.bit_generator.state
    out = quiet().compute(fr)
    assert np.array_equal(out.forces["random"], np.zeros((2, 2)))
    assert fr.rng.bit_generator.state == before


def test_random_term_is_reproducible_with_a_seed() -> None:
    a = PedsimModel().compute(make_frame([[0.0, 0.0], [3.0, 3.0]], seed=5)).forces["random"]
    b = PedsimModel().compute(make_frame([[0.0, 0.0], [3.0, 3.0]], seed=5)).forces["random"]
    c = PedsimModel().compute(make_frame([[0.0, 0.0], [3.0, 3.0]], seed=6)).forces["random"]
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    assert np.all(np.abs(a) < 1.0)  # 0.1 · N(0, 1): far below 1 m/s²


def test_random_term_fades_between_draws_like_pedsim() -> None:
    pos = [[0.0, 0.0], [3.0, 3.0]]
    model = PedsimModel()
    rng = np.random.default_rng(9)
    outs = []
    for t in (0.0, 0.5, 1.0):
        fr = make_frame(pos, time=t)
        fr = CrowdFrame(**{**fr.__dict__, "rng": rng})
        outs.append(model.compute(fr).forces["random"])
    ref = np.random.default_rng(9)
    d0, d1 = _deviation(ref, 2), _deviation(ref, 2)
    d2 = _deviation(ref, 2)
    assert np.allclose(outs[0], 0.1 * d0, rtol=1e-14)
    assert np.allclose(outs[1], 0.1 * (0.5 * d0 + 0.5 * d1), rtol=1e-12)
    assert np.allclose(outs[2], 0.1 * d1, rtol=1e-12)  # a new period: fading toward d2
    assert not np.allclose(d2, d1)


# -- the contract: inactive agents, sums, inputs, passthrough -------------------------------------


def test_inactive_agents_get_zero_but_still_repel() -> None:
    robots = RobotView(np.array([[1.0, 1.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.4]))
    fr = make_frame(
        [[1.0, 1.5], [2.0, 1.5]],
        [[0.3, 0.0], [0.3, 0.0]],
        [[5.0, 5.0], [5.0, 5.0]],
        active=[True, False],
        robots=robots,
        walls=room_walls(6.0),
    )
    model = PedsimModel()
    model.set_keep_distance_targets(np.array([[0.0, 0.0], [0.0, 0.0]]))
    out = model.compute(fr)
    assert np.array_equal(out.accelerations[1], np.zeros(2))
    for name in TERMS:
        assert np.array_equal(out.forces[name][1], np.zeros(2)), name
        assert np.any(out.forces[name][0] != 0.0), name
    alone = quiet().compute(make_frame([[1.0, 1.5]], [[0.3, 0.0]], [[5.0, 5.0]]))
    assert np.array_equal(alone.forces["social"], np.zeros((1, 2)))
    assert out.forces["social"][0, 0] < 0.0  # the inactive agent still pushes the active one


def test_terms_sum_to_the_acceleration() -> None:
    rng = np.random.default_rng(3)
    robots = RobotView(np.array([[4.0, 4.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.5]))
    fr = make_frame(
        rng.uniform(0.5, 7.5, (20, 2)),
        rng.normal(0, 0.5, (20, 2)),
        rng.uniform(0.5, 7.5, (20, 2)),
        robots=robots,
        walls=room_walls(8.0),
    )
    out = PedsimModel().compute(fr)
    assert set(out.forces) == set(TERMS)
    total = sum((out.forces[name] for name in TERMS), np.zeros((20, 2)))
    assert np.allclose(out.accelerations, total, rtol=0, atol=1e-12)
    assert out.accelerations.shape == (20, 2) and np.all(np.isfinite(out.accelerations))


def test_inputs_are_not_mutated() -> None:
    rng = np.random.default_rng(4)
    robots = RobotView(np.array([[4.0, 4.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.5]))
    fr = make_frame(
        rng.uniform(0.5, 7.5, (15, 2)),
        rng.normal(0, 0.5, (15, 2)),
        rng.uniform(0.5, 7.5, (15, 2)),
        active=rng.random(15) < 0.8,
        robots=robots,
        walls=room_walls(8.0),
    )
    arrays = {
        "positions": fr.state.positions,
        "velocities": fr.state.velocities,
        "radii": fr.state.radii,
        "vmax": fr.state.vmax,
        "vmax_factor": fr.state.vmax_factor,
        "destinations": fr.destinations,
        "active": fr.active,
        "robots": fr.robots.positions,
        "walls_a": fr.walls_a,
        "walls_b": fr.walls_b,
        "indptr": fr.neighbors.indptr,
        "indices": fr.neighbors.indices,
    }
    copies = {k: v.copy() for k, v in arrays.items()}
    targets = np.full((15, 2), 2.0)
    model = PedsimModel()
    model.set_keep_distance_targets(targets)
    model.compute(fr)
    model.compute(fr)
    for k, v in arrays.items():
        assert np.array_equal(v, copies[k]), k
    assert np.array_equal(targets, np.full((15, 2), 2.0))


def test_passthrough_is_pedsim_bit_for_bit() -> None:
    rng = np.random.default_rng(11)
    args = (rng.uniform(0.5, 9.5, (40, 2)), rng.normal(0, 0.6, (40, 2)), rng.uniform(1, 9, (40, 2)))
    robots = RobotView(np.array([[5.0, 5.0]]), np.zeros(1), np.zeros((1, 2)), np.array([0.5]))
    params = {"force_factor_social": 5.1, "force_factor_robot": 6.0}
    a_model = PedsimModel(PedsimModel.Params(**params))
    b_model = CROWD_MODELS.build({"type": "passthrough", **params}, path="crowd")
    for t in (0.0, 0.1, 0.2):
        fa = make_frame(*args, robots=robots, walls=room_walls(10.0), seed=2, time=t)
        fb = make_frame(*args, robots=robots, walls=room_walls(10.0), seed=2, time=t)
        a, b = a_model.compute(fa), b_model.compute(fb)
        assert a.accelerations is not None and b.accelerations is not None
        assert a.accelerations.tobytes() == b.accelerations.tobytes()
        for name in TERMS:
            assert a.forces[name].tobytes() == b.forces[name].tobytes(), name


def test_no_agents() -> None:
    out = PedsimModel().compute(make_frame(np.zeros((0, 2)), walls=room_walls(4.0)))
    assert out.accelerations is not None and out.accelerations.shape == (0, 2)


def test_many_agents_in_a_room_are_finite_and_deterministic() -> None:
    rng = np.random.default_rng(0)
    n = 300
    args = (rng.uniform(1, 19, (n, 2)), rng.normal(0, 0.5, (n, 2)), rng.uniform(1, 19, (n, 2)))
    a = PedsimModel().compute(make_frame(*args, walls=room_walls(20.0), seed=1))
    b = PedsimModel().compute(make_frame(*args, walls=room_walls(20.0), seed=1))
    assert a.accelerations is not None and b.accelerations is not None
    assert np.all(np.isfinite(a.accelerations))
    assert np.array_equal(a.accelerations, b.accelerations)
    assert np.allclose(a.forces["social"].sum(axis=0), 0.0, atol=1e-10)
