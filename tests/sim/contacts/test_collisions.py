import numpy as np

from arena.core.geometry import circles_overlap_polygon, rectangle, transform_points
from arena.maps.grid import OccupancyGrid
from arena.sim.contacts import Footprint, first_agent_hit, hits_grid


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
    from arena.sim.contacts.kernels import _near_circles

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


def reference_hits_grid(grid, fp, pose):
    """``hits_grid`` as it was before its compiled window test (NumPy throughout)."""
    from arena.core.geometry import convex_polygon_overlaps_squares

    x, y = float(pose[0]), float(pose[1])
    xmin, ymin, xmax, ymax = grid.bounds
    if not (xmin <= x < xmax and ymin <= y < ymax):
        return True
    r = fp.radius
    if x - r < xmin or y - r < ymin or x + r > xmax or y + r > ymax:
        pts = fp.world_polygon(pose)
        if pts is None or (
            pts[:, 0].min() < xmin
            or pts[:, 1].min() < ymin
            or pts[:, 0].max() > xmax
            or pts[:, 1].max() > ymax
        ):
            return True
    res = grid.resolution
    col = int((x - grid.origin[0]) // res)
    row = int((y - grid.origin[1]) // res)
    if grid.distance[row, col] - res * np.sqrt(2.0) >= r:
        return False
    k = int(np.ceil(r / res)) + 1
    r0, r1 = max(row - k, 0), min(row + k + 1, grid.height)
    c0, c1 = max(col - k, 0), min(col + k + 1, grid.width)
    rows, cols = np.nonzero(grid.occupied[r0:r1, c0:c1])
    if rows.size == 0:
        return False
    cx = grid.origin[0] + (cols + c0 + 0.5) * res
    cy = grid.origin[1] + (rows + r0 + 0.5) * res
    half = 0.5 * res
    if fp.polygon is None:
        dx = np.maximum(np.abs(cx - x) - half, 0.0)
        dy = np.maximum(np.abs(cy - y) - half, 0.0)
        return bool(np.any(dx * dx + dy * dy < r * r))
    poly = transform_points(fp.polygon, pose)
    return bool(np.any(convex_polygon_overlaps_squares(poly, np.stack([cx, cy], axis=1), half)))


def test_hits_grid_matches_the_numpy_reference_near_walls():
    """The compiled circle test and the polygon's bounding-circle shortcut change no answer.

    Poses are drawn near blocking cells (where the window test runs), including exactly
    tangent circles (centres a radius from a cell edge) and a footprint whose radius is
    smaller than its polygon (the shortcut must use the polygon's extent).
    """
    rng = np.random.default_rng(5)
    occ = rng.random((50, 50)) < 0.04
    grid = OccupancyGrid.from_occupied(occ, 0.05, origin=(-1.3, 0.7))
    feet = [
        Footprint.make(None, 0.25),
        Footprint.make(rectangle(0.5, 0.43), 0.3),
        Footprint.make(np.array([[0.3, 0.0], [-0.2, 0.2], [-0.2, -0.2]]), 0.3),
        Footprint(rectangle(0.6, 0.2), 0.1),  # radius below the polygon's extent
    ]
    rows, cols = np.nonzero(occ)
    answers = set()
    for trial in range(3000):
        fp = feet[trial % len(feet)]
        q = rng.integers(rows.size)
        cx = -1.3 + (cols[q] + 0.5) * 0.05
        cy = 0.7 + (rows[q] + 0.5) * 0.05
        if trial % 5 == 0:  # tangent to the cell's right edge
            pose = np.array([cx + 0.025 + fp.radius, cy, rng.uniform(-np.pi, np.pi)])
        else:
            pose = np.array([*(np.array([cx, cy]) + rng.uniform(-0.6, 0.6, 2)), 0.0])
            pose[2] = rng.uniform(-np.pi, np.pi)
        want = reference_hits_grid(grid, fp, pose)
        assert hits_grid(grid, fp, pose) == want, (trial, pose)
        answers.add(want)
    assert answers == {True, False}
