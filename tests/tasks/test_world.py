import numpy as np
import pytest

from arena.core.errors import SamplingError
from arena.core.geometry import point_segment_distance, points_in_polygon
from arena.maps.generators import MAP_GENERATORS
from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import make_obstacle
from arena.tasks.sampling import components
from arena.tasks.world import WorldSampler, polygon_distance, polygons_distance


def brute_wall_distance(grid: OccupancyGrid, pts: np.ndarray) -> np.ndarray:
    """Exact distance from points to every non-free cell square and to the map border."""
    rows, cols = np.nonzero(~grid.free)
    res = grid.resolution
    lo = np.stack([grid.origin[0] + cols * res, grid.origin[1] + rows * res], axis=1)
    out = []
    x0, y0, x1, y1 = grid.bounds
    for p in pts:
        dx = np.maximum(np.maximum(lo[:, 0] - p[0], p[0] - (lo[:, 0] + res)), 0)
        dy = np.maximum(np.maximum(lo[:, 1] - p[1], p[1] - (lo[:, 1] + res)), 0)
        border = min(p[0] - x0, x1 - p[0], p[1] - y0, y1 - p[1])
        out.append(min(float(np.hypot(dx, dy).min()) if len(lo) else np.inf, border))
    return np.array(out)


def test_polygon_distance_reference_values():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    pts = np.array([[1, 1], [3, 1], [3, 3], [-1, 1], [1, 2.5]])
    assert np.allclose(polygon_distance(pts, square), [0, 1, np.sqrt(2), 1, 0.5])


def test_sampled_positions_respect_clearances_over_1000_samples():
    """Walls, obstacles and forbidden zones, checked against brute-force exact distances."""
    grid = MAP_GENERATORS.build({"type": "barn", "width": 15.0, "height": 10.0}).build(
        np.random.default_rng(3)
    ).grid
    obstacles = [make_obstacle(f"t{i}", "table", [3 + 3 * i, 5.0, 0.0]) for i in range(3)]
    world = WorldSampler(grid, obstacles)
    world.forbid([7.5, 2.0], 1.0)
    zone = np.array([[11.0, 6.0], [13.0, 6.0], [13.0, 8.0], [11.0, 8.0]])
    world.forbid_polygon(zone)
    rng = np.random.default_rng(0)
    pts, clearances = [], []
    for _ in range(200):
        c = float(rng.uniform(0.1, 0.5))
        pts.append(world.sample(5, c, rng, what="points", forbid=False))
        clearances += [c] * 5
    pts, clear = np.concatenate(pts), np.array(clearances)
    assert len(pts) == 1000
    assert np.all(brute_wall_distance(grid, pts) >= clear)
    for o in obstacles:
        poly = o.polygon
        d = point_segment_distance(pts, poly, np.roll(poly, -1, axis=0)).min(axis=1)
        assert not points_in_polygon(pts, poly).any()
        assert np.all(d >= clear)
    assert np.all(np.hypot(*(pts - [7.5, 2.0]).T) >= 1.0 + clear)
    assert not points_in_polygon(pts, zone).any()
    assert np.all(polygon_distance(pts, zone) >= clear)
    # Positions sampled in one call keep 2·clearance from each other.
    batch = world.sample(30, 0.4, rng, what="people")
    d = np.hypot(*(batch[:, None] - batch[None]).transpose(2, 0, 1))
    assert np.all(d[np.triu_indices(30, 1)] >= 0.8)
    # ... and with forbid=True later positions keep away from them.
    later = world.sample(50, 0.2, rng, what="more")
    assert np.all(np.hypot(*(later[:, None] - batch[None]).transpose(2, 0, 1)) >= 0.6)


def test_wall_distance_is_exact():
    grid = MAP_GENERATORS.build({"type": "barn", "width": 10.0, "height": 8.0}).build(
        np.random.default_rng(1)
    ).grid
    rng = np.random.default_rng(2)
    pts = rng.uniform([0.5, 0.5], [9.5, 7.5], size=(300, 2))
    world = WorldSampler(grid)
    assert np.allclose(world.wall_distance(pts), brute_wall_distance(grid, pts), atol=1e-12)


def test_impossible_request_raises_never_places_outside():
    grid = OccupancyGrid.empty(2.0, 2.0, 0.05)
    world = WorldSampler(grid)
    with pytest.raises(SamplingError, match=r"cannot place 5 robots: found room for \d of 5"):
        world.sample(5, 0.6, np.random.default_rng(0), what="5 robots")
    # Inside a polygon zone only.
    zone = np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]])
    pts = world.sample(3, 0.1, np.random.default_rng(1), what="x", polygon=zone)
    assert points_in_polygon(pts, zone).all()


def test_clear_forbidden():
    world = WorldSampler(OccupancyGrid.empty(4.0, 4.0, 0.05))
    world.forbid([2.0, 2.0], 2.5)
    with pytest.raises(SamplingError):
        world.sample(1, 0.3, np.random.default_rng(0), what="x")
    world.clear_forbidden()
    assert world.sample(1, 0.3, np.random.default_rng(0), what="x").shape == (1, 2)


def _reference_polygon_distance(points, polygon):
    """The vectorised form the kernel replaced."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    poly = np.asarray(polygon, dtype=np.float64)
    d = point_segment_distance(p, poly, np.roll(poly, -1, axis=0)).min(axis=1)
    return np.where(points_in_polygon(p, poly), 0.0, d)


@pytest.mark.parametrize("seed", range(20))
def test_polygons_distance_is_the_minimum_of_the_reference(seed):
    rng = np.random.default_rng(seed)
    polys = [
        rng.normal(size=(int(rng.integers(1, 9)), 2)) * rng.uniform(0.2, 3) + rng.normal(size=2)
        for _ in range(int(rng.integers(1, 5)))
    ]
    pts = rng.normal(size=(200, 2)) * 4
    if seed % 2:  # grid-aligned values: ties, horizontal edges, points on vertices
        polys = [np.round(q * 4) / 4 for q in polys]
        pts = np.round(pts * 8) / 8
        pts[:3] = polys[0][:3] if len(polys[0]) >= 3 else pts[:3]
    pts[5] = np.nan
    want = np.full(len(pts), np.inf)
    for q in polys:
        want = np.minimum(want, _reference_polygon_distance(pts, q))
    assert np.array_equal(polygons_distance(pts, polys), want, equal_nan=True)
    assert np.array_equal(
        polygon_distance(pts, polys[0]), _reference_polygon_distance(pts, polys[0]), equal_nan=True
    )
    assert np.all(np.isinf(polygons_distance(pts, [])))


def test_sample_cells_equals_within():
    grid = MAP_GENERATORS.build({"type": "rosnav_indoor"}).build(np.random.default_rng(2)).grid
    within = np.zeros(grid.data.shape, dtype=bool)
    within[: grid.height // 2, : grid.width // 3] = True
    for seed in range(5):
        world_a, world_b = WorldSampler(grid), WorldSampler(grid)
        a = world_a.sample(3, 0.3, np.random.default_rng(seed), what="a", within=within)
        b = world_b.sample(
            3, 0.3, np.random.default_rng(seed), what="b", cells=np.flatnonzero(within)
        )
        assert a.tobytes() == b.tobytes()
        assert world_a.forbidden_discs == world_b.forbidden_discs


def test_candidate_regions_are_reused_and_follow_the_mask():
    grid = MAP_GENERATORS.build({"type": "rosnav_indoor"}).build(np.random.default_rng(2)).grid
    first = WorldSampler(grid).candidate_regions(0.4)
    again = WorldSampler(grid).candidate_regions(0.4)
    assert again is first  # the same map and mask: one labelling for every reset
    world = WorldSampler(grid)
    labels = components(world.candidate_mask(0.4))
    r, c = np.argwhere(labels > 0)[0]
    world.forbid(grid.cell_to_world([r, c]), 1.0)  # changes the mask: no stale regions
    changed = world.candidate_regions(0.4)
    assert changed is not first
    assert not changed.cells(r, c).size
    assert np.array_equal(first.cells(r, c), np.argwhere(labels == labels[r, c]))


def test_wall_distance_map_is_computed_once_per_map_and_read_only():
    from arena.tasks.world import wall_distance_map

    occ = np.zeros((20, 30), dtype=bool)
    occ[5:8, 10:12] = True
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    d = wall_distance_map(grid)
    assert wall_distance_map(grid) is d and not d.flags.writeable
    assert d[6, 10] == 0.0 and d[0, 0] == pytest.approx(0.1)  # the map's edge counts as wall
    other = OccupancyGrid.from_occupied(occ, 0.1)  # an equal map is another object
    assert wall_distance_map(other) is not d
    np.testing.assert_array_equal(wall_distance_map(other), d)
