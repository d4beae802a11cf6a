import numpy as np

from arena.core.geometry import circles_overlap_polygon, rectangle, transform_points
from arena.maps.grid import OccupancyGrid
from arena.sim.native2d.collisions import Footprint, first_agent_hit, hits_grid


def reference_agent_hit(fp, pose, pos, radii):
    d = np.hypot(*(pos - pose[:2]).T)
    if fp.polygon is None:
        hit = d < radii + fp.radius
    else:
        hit = (d < radii + fp.radius) & circles_overlap_polygon(
            pos, radii, transform_points(fp.polygon, pose)
        )
    return int(np.flatnonzero(hit)[np.argmin(d[hit])]) if hit.any() else -1


def test_agent_hit_matches_reference_geometry():
    rng = np.random.default_rng(0)
    for trial in range(300):
        poly = rectangle(*rng.uniform(0.2, 1.0, 2)) if trial % 3 else None
        fp = Footprint.make(poly, 0.3)
        pose = rng.uniform([-1, -1, -np.pi], [1, 1, np.pi])
        pos = rng.uniform(-1.5, 1.5, (rng.integers(0, 8), 2))
        radii = rng.uniform(0.1, 0.4, len(pos))
        assert first_agent_hit(fp, pose, pos, radii) == reference_agent_hit(fp, pose, pos, radii)


def test_hits_grid_circle_matches_dense_sampling():
    rng = np.random.default_rng(1)
    occ = rng.random((60, 60)) < 0.05
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    fp = Footprint.make(None, 0.25)
    t = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    for _ in range(200):
        pose = np.array([*rng.uniform(0.5, 5.5, 2), 0.0])
        # Dense sample of the disc (interior points strictly inside).
        rr = np.linspace(0, 0.2499, 12)[:, None]
        pts = pose[:2] + np.stack([rr * np.cos(t), rr * np.sin(t)], -1).reshape(-1, 2)
        sampled = bool(grid.is_occupied(pts).any())
        got = hits_grid(grid, fp, pose)
        if sampled:
            assert got


def test_near_circles_matches_the_numpy_rejection_test():
    """The compiled bounding-circle test selects exactly what ``hypot(...) <= r`` selects."""
    from arena.sim.native2d.collisions import _near_circles

    rng = np.random.default_rng(1)
    for _ in range(300):
        k = int(rng.integers(0, 12))
        centers = rng.uniform(-3, 3, (k, 2))
        radii = rng.uniform(0.1, 1.5, k)
        x, y, r = *rng.uniform(-3, 3, 2), float(rng.uniform(0.1, 0.6))
        ref = np.flatnonzero(np.hypot(centers[:, 0] - x, centers[:, 1] - y) <= radii + r)
        assert _near_circles(centers, radii, x, y, r).tolist() == ref.tolist()


def test_hits_grid_with_given_bounds_matches():
    grid = OccupancyGrid.empty(4.0, 3.0, 0.1)
    fp = Footprint.make(rectangle(0.5, 0.3), 0.3)
    rng = np.random.default_rng(2)
    for _ in range(200):
        pose = rng.uniform([-0.5, -0.5, -np.pi], [4.5, 3.5, np.pi])
        assert hits_grid(grid, fp, pose, bounds=grid.bounds) == hits_grid(grid, fp, pose)
