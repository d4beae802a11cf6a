"""Dense requests: 1,000 people, obstacle counts a map cannot hold, the exact search they use."""

import numpy as np
import pytest

from arena.core.errors import SamplingError
from arena.core.geometry import rectangle
from arena.maps.grid import OccupancyGrid
from arena.maps.io import load_map
from arena.maps.sources import resolve_world
from arena.robots.presets import load_robot
from arena.scene.episode import episode_digest
from arena.scene.state import Obstacle
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.obstacle_modes.random import RandomObstacles, obstacle_capacity
from arena.tasks.sampling import accept_spaced
from arena.tasks.world import WorldSampler, polygons_distance

HOSPITAL = {"type": "world", "name": "hospital_floor"}
OFFICE = {"type": "world", "name": "small_office"}


def generator(obstacles, map_spec, seed=0):
    cfg = TaskConfig(robots={"type": "random"}, obstacles=obstacles)
    return TaskGenerator(cfg, map_spec=map_spec, robots=[load_robot("jackal")], seed=seed)


def _reference_accept(candidates, chosen, min_gap, n):
    """The pair loop the kernel replaced, as it was written."""
    chosen = list(chosen)
    for p in candidates:
        if len(chosen) == n:
            break
        if all(np.hypot(*(p - q)) >= min_gap for q in chosen):
            chosen.append(p)
    return np.array(chosen).reshape(-1, 2)


@pytest.mark.parametrize("seed", range(8))
def test_accept_kernel_equals_the_pair_loop(seed):
    rng = np.random.default_rng(seed)
    gap = [0.7, 0.0, 1e-3, 5.0, 0.25, 0.7, np.nan, 0.05][seed]
    m = int(rng.integers(1, 3000))
    if seed % 2:
        # Points on a lattice of exactly the gap (and a bit less): ties decide.
        step = gap if gap > 0 else 0.1
        k = np.arange(40) * step
        pts = np.stack(np.meshgrid(k, k * (1 - 1e-12)), axis=-1).reshape(-1, 2)
        pts = pts[rng.permutation(len(pts))][:m] + 3.0
    else:
        pts = rng.uniform(-20, 40, size=(m, 2))
        pts[rng.integers(0, m, size=m // 10)] = pts[0]  # duplicates
    n = int(rng.integers(1, m + 5))
    n0 = int(rng.integers(0, min(n, 20)))
    seeds = rng.uniform(-20, 40, size=(n0, 2))
    want = _reference_accept(pts, seeds, gap, n)
    chosen = np.zeros((n, 2))
    chosen[:n0] = seeds
    count = accept_spaced(np.ascontiguousarray(pts), chosen, n0, gap)
    assert count == len(want)
    assert np.array_equal(chosen[:count], want)


def test_accept_kernel_on_a_wide_spread_with_a_small_gap():
    """Far more buckets than points would fit: the buckets grow, the answer does not change."""
    rng = np.random.default_rng(3)
    pts = np.concatenate([rng.uniform(0, 1, size=(300, 2)), [[1e6, 1e6], [1e6, 1e6 + 1e-4]]])
    want = _reference_accept(pts, np.zeros((0, 2)), 0.01, 400)
    chosen = np.zeros((400, 2))
    count = accept_spaced(pts, chosen, 0, 0.01)
    assert np.array_equal(chosen[:count], want)


def test_polygons_distance_with_a_cutoff_is_exact_below_it():
    rng = np.random.default_rng(0)
    polys = [rectangle(*rng.uniform(0.2, 2, size=2), center=tuple(rng.uniform(0, 30, size=2)))
             for _ in range(40)]
    pts = rng.uniform(-5, 35, size=(5000, 2))
    full = polygons_distance(pts, polys)
    for cutoff in (0.0, 0.3, 1.2, 4.0):
        cut = polygons_distance(pts, polys, cutoff=cutoff)
        below = full < cutoff
        assert np.array_equal(cut[below], full[below])
        assert np.all(cut[~below] >= cutoff)
        assert np.array_equal(cut >= cutoff, full >= cutoff)


def _reference_exhaustive(sampler, flat, n, clearance, rng):
    """Every candidate centre in random order, each tested against everything by brute force."""
    order = rng.permutation(flat)
    pts = sampler.grid.cell_to_world(np.stack(np.unravel_index(order, sampler.grid.data.shape), 1))
    ok = (polygons_distance(pts, sampler._polygons) >= clearance) & (
        sampler.forbidden_distance(pts) >= clearance
    )
    return _reference_accept(pts[ok], np.zeros((0, 2)), 2 * clearance, n)


@pytest.mark.parametrize("clearance", [0.3, 0.55, 0.9])
def test_exhaustive_search_takes_what_the_brute_force_search_takes(clearance):
    """On a crowded room the pre-filtered, chunked search picks the same cell centres."""
    grid = OccupancyGrid(np.zeros((120, 160), dtype=np.int8), 0.05, (0.0, 0.0))
    rng = np.random.default_rng(7)
    obstacles = []
    for k in range(30):
        pose = np.array([*rng.uniform(0.3, [7.7, 5.7]), rng.uniform(-np.pi, np.pi)])
        footprint = rectangle(*rng.uniform(0.2, 0.8, size=2))
        obstacles.append(Obstacle(f"S_box_{k}", "cuboid", pose, footprint))
    sampler = WorldSampler(grid, obstacles)
    sampler.forbid([4.0, 3.0], 0.5)
    flat = np.flatnonzero(sampler.candidate_mask(clearance))
    want = _reference_exhaustive(sampler, flat, 500, clearance, np.random.default_rng(1))
    assert 0 < len(want) < 500  # the room fills up: every candidate is searched
    chosen = np.zeros((500, 2))
    with pytest.raises(SamplingError, match=f"found room for {len(want)} of 500"):
        sampler._exhaustive(flat, grid.data.shape, chosen, 0, clearance, None,
                            np.random.default_rng(1), "500 things")
    assert np.array_equal(chosen[: len(want)], want)
    # A request that fits takes the same first positions.
    got = np.zeros((len(want), 2))
    sampler._exhaustive(flat, grid.data.shape, got, 0, clearance, None,
                        np.random.default_rng(1), "some things")
    assert np.array_equal(got, want)


def test_a_thousand_people_on_the_hospital_floor_are_valid_and_repeatable():
    """Once minutes (a pure-Python pair loop), now about a second: every start keeps its room."""
    obstacles = {"type": "random", "static": 0, "dynamic": 1000}
    ep = generator(obstacles, HOSPITAL).episode(0)
    p = RandomObstacles.Params(dynamic=1000)
    body = p.agent_radius + 0.05
    pos = ep.agents.positions
    assert pos.shape == (1000, 2)
    d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    np.fill_diagonal(d, np.inf)
    assert d.min() >= 2 * body
    exact = WorldSampler(ep.grid, ep.obstacles)
    assert np.all(exact.wall_distance(pos) >= body)
    assert np.all(exact.obstacle_distance(pos) >= body)
    robot = ep.robots[0]
    keep = robot.model.radius + p.agent_robot_clearance
    assert np.all(np.hypot(*(pos - robot.start.xy).T) >= keep)
    assert episode_digest(generator(obstacles, HOSPITAL).episode(0)) == episode_digest(ep)


def test_obstacle_counts_the_map_cannot_hold_fail_at_once(monkeypatch):
    gen = generator({"type": "random", "static": 500, "dynamic": 0}, OFFICE)
    asked = []
    original = WorldSampler.sample

    def sample(self, n, clearance, rng, *, what, **kw):
        asked.append(what)
        return original(self, n, clearance, rng, what=what, **kw)

    monkeypatch.setattr(WorldSampler, "sample", sample)
    with pytest.raises(SamplingError) as err:
        gen.episode(0)
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith("task.obstacles.static: 500 obstacles cannot fit on map 'small_office'")
    grid = load_map(resolve_world("small_office"))
    fit = obstacle_capacity(grid, ["box"], RandomObstacles.Params())
    assert f"at most ~{fit} fit" in msg and 0 < fit < 500
    assert asked and all(w.startswith("robot") for w in asked)  # no obstacle was tried


def test_capacity_bounds_what_actually_fits():
    """Fill a room until it fails: the count placed never exceeds the bound, which is close."""
    room = {"type": "empty", "width": 6.0, "height": 5.0}
    params = {"dynamic": 0, "box_size": [0.5, 0.5], "obstacle_clearance": 0.2}
    robots = {"type": "random", "min_goal_distance": 1.0}
    grid, error = None, ""
    for static in range(1, 200):
        cfg = TaskConfig(robots=robots, obstacles={"type": "random", **params, "static": static})
        gen = TaskGenerator(cfg, map_spec=room, robots=[load_robot("jackal")], seed=0)
        try:
            grid = gen.episode(0).grid
        except SamplingError as e:
            error = str(e)
            break
    assert error.startswith(f"task.obstacles.static: only {static - 1} of {static} "), error
    fit = obstacle_capacity(grid, ["box"], RandomObstacles.Params(**params))
    assert static - 1 <= fit <= 4 * static
