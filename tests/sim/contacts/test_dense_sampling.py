"""The exact contact tests agree with densely sampled bodies (an independent brute force).

Each body is sampled on its boundary (spacing ``STEP``) and on a few shrunk copies of it. A
sample strictly inside the other body proves a contact; all samples farther apart than
``2 STEP`` prove none. Between the two the answer is not checked (the samples cannot tell).
"""

import itertools

import numpy as np
from scipy.spatial import cKDTree

from arena.core.geometry import rectangle, regular_polygon
from arena.maps.grid import OccupancyGrid
from arena.scene.state import Obstacle, StaticWorld
from arena.sim.contacts import (
    Footprint,
    ObstacleIndex,
    first_obstacle_hit,
    footprints_overlap,
    hits_grid,
)

STEP = 0.004
BODIES = (
    Footprint.make(None, 0.27),
    Footprint.make(rectangle(0.7, 0.35), 0.0),
    Footprint.make(np.array([[0.35, 0.0], [-0.2, 0.25], [-0.2, -0.25]]), 0.0),
    Footprint.make(regular_polygon(0.25, 5), 0.0),
)


def world_outline(fp: Footprint, pose: np.ndarray) -> np.ndarray:
    """``(k, 2)`` convex outline at ``pose``: the polygon, or a 720-gon inscribed in the circle."""
    if fp.polygon is None:
        t = np.linspace(0, 2 * np.pi, 720, endpoint=False)
        return pose[:2] + fp.radius * np.stack([np.cos(t), np.sin(t)], 1)
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return pose[:2] + fp.polygon @ np.array([[c, s], [-s, c]])


def samples(outline: np.ndarray) -> np.ndarray:
    """Points on the outline every ``STEP`` and on 11 shrunk copies of it toward its centroid."""
    closed = np.vstack([outline, outline[:1]])
    edge_pts = []
    for a, b in itertools.pairwise(closed):
        n = max(int(np.ceil(np.linalg.norm(b - a) / STEP)), 1)
        edge_pts.append(a + np.linspace(0, 1, n, endpoint=False)[:, None] * (b - a))
    ring = np.concatenate(edge_pts)
    centre = outline.mean(axis=0)
    scales = np.linspace(0, 1, 12)  # rings ≤ 0.035 m apart: no 0.1 m cell fits between
    return np.concatenate([centre + s * (ring - centre) for s in scales])


def strictly_inside_convex(points: np.ndarray, outline: np.ndarray, margin: float) -> np.ndarray:
    """Points at least ``margin`` inside a convex outline (either orientation)."""
    e = np.roll(outline, -1, axis=0) - outline
    cross = e[:, 0] * (points[:, None, 1] - outline[:, 1]) - e[:, 1] * (
        points[:, None, 0] - outline[:, 0]
    )
    cross /= np.linalg.norm(e, axis=1)
    return (cross > margin).all(axis=1) | (cross < -margin).all(axis=1)


def min_distance(p: np.ndarray, q: np.ndarray) -> float:
    return float(cKDTree(q).query(p)[0].min())


def test_grid_contacts_agree_with_samples():
    rng = np.random.default_rng(5)
    occ = rng.random((40, 40)) < 0.04
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    half = 0.05
    cells = grid.cell_to_world(np.argwhere(occ))
    decided = 0
    for trial in range(120):
        fp = BODIES[trial % len(BODIES)]
        pose = np.array([*rng.uniform(0.6, 3.4, 2), rng.uniform(-np.pi, np.pi)])
        pts = samples(world_outline(fp, pose))
        gap = np.abs(pts[:, None, :] - cells[None, :, :]) - half  # (n, cells, 2)
        inside = (gap < -1e-9).all(-1).any()
        far = np.sqrt((np.maximum(gap, 0) ** 2).sum(-1)).min() > 2 * STEP
        got = hits_grid(grid, fp, pose)
        if inside:
            assert got, (trial, pose)
        if far:
            assert not got, (trial, pose)
        decided += inside or far
    assert decided > 100


def test_obstacle_and_robot_contacts_agree_with_samples():
    rng = np.random.default_rng(6)
    grid = OccupancyGrid.from_occupied(np.zeros((50, 50), dtype=bool), 0.1)
    decided = [0, 0]
    for trial in range(100):
        fp, other = BODIES[trial % 4], BODIES[(trial // 4) % 4]
        centre = rng.uniform(1.5, 3.5, 2)
        ob = Obstacle("o", "box", np.array([*centre, rng.uniform(-3, 3)]), rectangle(0.6, 0.3))
        index = ObstacleIndex.build(StaticWorld.build(grid, (ob,)))
        pose = np.array([*(centre + rng.normal(0, 0.4, 2)), rng.uniform(-np.pi, np.pi)])
        mine = world_outline(fp, pose)
        pts = samples(mine)
        # against the obstacle
        if strictly_inside_convex(pts, ob.polygon, 1e-9).any():
            assert first_obstacle_hit(index, fp, pose) == 0
            decided[0] += 1
        elif min_distance(pts, samples(ob.polygon)) > 2 * STEP:
            assert first_obstacle_hit(index, fp, pose) == -1
            decided[0] += 1
        # against another robot
        pose_b = np.array([*(pose[:2] + rng.normal(0, 0.35, 2)), rng.uniform(-np.pi, np.pi)])
        theirs = world_outline(other, pose_b)
        if strictly_inside_convex(pts, theirs, 1e-9).any():
            assert footprints_overlap(fp, pose, other, pose_b)
            assert footprints_overlap(other, pose_b, fp, pose)
            decided[1] += 1
        elif min_distance(pts, samples(theirs)) > 2 * STEP:
            assert not footprints_overlap(fp, pose, other, pose_b)
            decided[1] += 1
    assert min(decided) > 70
