"""Wall faces of the 2-D lidar: the merged boundary and the face casting against the grid walk."""

from __future__ import annotations

import math

import numpy as np

from arena.maps.grid import OccupancyGrid
from arena.sensors import Lidar2D
from tests.sensors.lidar_kit import random_map, random_spec


def test_wall_faces_cover_every_boundary_edge_once() -> None:
    from arena.sensors.lidar2d import wall_faces

    rng = np.random.default_rng(5)
    for _ in range(10):
        grid = random_map(rng)
        occ = grid.occupied
        h, w = occ.shape
        pad = np.zeros((h + 2, w + 2), dtype=bool)
        pad[1:-1, 1:-1] = occ
        # every unit edge between a blocking and a free cell, with the side it is seen from
        want = set()
        for r, c in zip(*np.nonzero(occ), strict=True):
            if not pad[r + 1, c]:      # free cell to the left: seen from x < c
                want.add((0, c, r))
            if not pad[r + 1, c + 2]:  # free to the right: seen from x > c + 1
                want.add((1, c + 1, r))
            if not pad[r, c + 1]:      # free below: seen from y < r
                want.add((2, r, c))
            if not pad[r + 2, c + 1]:  # free above
                want.add((3, r + 1, c))
        faces = wall_faces(grid)
        assert wall_faces(grid) is faces  # computed once per grid
        assert not faces.flags.writeable
        got = []
        for kind, line, lo, hi in faces:
            assert lo < hi and float(lo).is_integer() and float(hi).is_integer()
            got += [(int(kind), int(line), k) for k in range(int(lo), int(hi))]
        assert len(got) == len(set(got)) and set(got) == want
        # merged: no two faces of one kind and line touch end to end
        ends = {(int(k), int(ln), int(hi)) for k, ln, _, hi in faces}
        assert not any((int(k), int(ln), int(lo)) in ends for k, ln, lo, _ in faces)


def test_faces_and_grid_walk_give_identical_ranges(monkeypatch) -> None:
    import arena.sensors.lidar2d.model as mod

    monkeypatch.setattr(mod, "FACES_PER_BEAM", math.inf)
    rng = np.random.default_rng(11)
    for _ in range(12):
        grid = random_map(rng)
        spec = random_spec(rng, range_max=float(rng.uniform(2.0, 20.0)))
        faces, walk = Lidar2D(spec), Lidar2D(spec)
        faces.bind(grid)
        monkeypatch.setattr(mod, "FACES_PER_BEAM", -1.0)
        walk.bind(grid)
        monkeypatch.setattr(mod, "FACES_PER_BEAM", math.inf)
        assert faces._use_faces and not walk._use_faces
        xmin, ymin, xmax, ymax = grid.bounds
        res = grid.resolution
        poses = rng.uniform([xmin - 1, ymin - 1, -math.pi], [xmax + 1, ymax + 1, math.pi],
                            size=(40, 3))
        poses[::4, 2] = rng.integers(-4, 5, size=len(poses[::4])) * (math.pi / 2)  # axis beams
        # origins on grid lines and grid points
        poses[::3, 0] = grid.origin[0] + np.round((poses[::3, 0] - grid.origin[0]) / res) * res
        poses[::5, 1] = grid.origin[1] + np.round((poses[::5, 1] - grid.origin[1]) / res) * res
        np.testing.assert_array_equal(faces.scan_many(poses), walk.scan_many(poses))


def test_noisy_maps_keep_the_grid_walk() -> None:
    from arena.sensors.lidar2d import use_wall_faces, wall_faces

    occ = np.random.default_rng(0).random((200, 200)) < 0.05  # speckle: thousands of faces
    grid = OccupancyGrid.from_occupied(occ, 0.05)
    assert len(wall_faces(grid)) > 1440 and not use_wall_faces(wall_faces(grid), 720)
    room = np.zeros((200, 200), dtype=bool)
    room[0] = room[-1] = room[:, 0] = room[:, -1] = True
    assert len(wall_faces(OccupancyGrid.from_occupied(room, 0.05))) == 8
