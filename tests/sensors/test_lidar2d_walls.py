"""Tests of the 2-D lidar's walls against independent references.

Grid casting against a brute-force march; exact faces, grid lines and corners.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.maps.grid import OccupancyGrid
from arena.sensors import Lidar2D, LidarSpec
from tests.sensors.lidar_kit import (
    ONE_BEAM,
    circle_ref,
    clip,
    clip_chords,
    gap_to_walls,
    march_grid,
    one_beam,
    random_map,
    random_spec,
    segment_ref,
    sensor_frame,
    wall_casting,  # noqa: F401  (autouse: every test runs with faces and with the grid walk)
)

# ------------------------------------------------------------------------------------------------
# Grid casting against the brute-force march
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(24))
def test_grid_matches_brute_force_march(seed: int) -> None:
    rng = np.random.default_rng(seed)
    grid = random_map(rng)
    xmin, ymin, xmax, ymax = grid.bounds
    spec = random_spec(rng, range_max=float(rng.uniform(3.0, 1.5 * max(xmax - xmin, ymax - ymin))))
    lidar = Lidar2D(spec)
    lidar.bind(grid)
    step = grid.resolution / 50
    n_hits = n_thin = 0
    for _ in range(6):
        pose = np.array([rng.uniform(xmin - 1, xmax + 1), rng.uniform(ymin - 1, ymax + 1),
                         rng.uniform(-math.pi, math.pi)])
        o, dirs = sensor_frame(spec, pose)
        if grid.contains(o[None])[0] and grid.is_occupied(o[None])[0]:
            continue
        got = lidar.scan(pose)
        ref = march_grid(grid, o, dirs, spec.range_max, step)
        hit = got < spec.range_max
        # Never later than a sample known to lie in a wall: no beam leaks through a wall.
        assert np.all(got <= np.minimum(ref, spec.range_max) + 1e-9)
        # Every reported grid hit really touches a blocking cell (exact, up to rounding).
        gaps = gap_to_walls(grid, o + got[hit, None] * dirs[hit])
        assert np.all(gaps <= 1e-7), gaps.max()
        # Within one march step of the march (far below one cell), except where the march
        # stepped over a corner clip thinner than its step: then the beam's chord through the
        # clipped cell must indeed be that thin.
        err = got[hit] - ref[hit]
        thin = err < -(step + 1e-9)
        assert np.all(np.abs(err[~thin]) <= step + 1e-9), np.abs(err[~thin]).max()
        idx = np.flatnonzero(hit)[thin]
        chords = clip_chords(grid, o, dirs[idx], got[idx])
        assert np.all(chords < step + 1e-9), chords
        assert np.all(ref[~hit] >= spec.range_max - 1e-9)  # misses are real misses
        n_hits += int(hit.sum())
        n_thin += int(thin.sum())
    assert n_hits > 0
    assert n_thin <= 0.01 * n_hits


@pytest.mark.parametrize("seed", range(6))
def test_grid_circles_and_segments_combine_as_nearest_hit(seed: int) -> None:
    rng = np.random.default_rng(500 + seed)
    grid = random_map(rng)
    xmin, ymin, xmax, ymax = grid.bounds
    spec = random_spec(rng, range_max=float(rng.uniform(3.0, 12.0)))
    sa = rng.uniform([xmin, ymin], [xmax, ymax], size=(10, 2))
    sb = sa + rng.normal(0, 0.8, size=(10, 2))
    cxy = rng.uniform([xmin, ymin], [xmax, ymax], size=(15, 2))
    cr = rng.uniform(0.05, 0.5, size=15)
    walls_only, full = Lidar2D(spec), Lidar2D(spec)
    walls_only.bind(grid)
    full.bind(grid, sa, sb)
    free = OccupancyGrid.from_occupied(np.zeros((1, 1), dtype=bool), 1.0, (1e6, 1e6))
    for _ in range(8):
        pose = np.array([*rng.uniform([xmin, ymin], [xmax, ymax]), rng.uniform(-3, 3)])
        o, dirs = sensor_frame(spec, pose)
        if np.any(np.linalg.norm(cxy - o, axis=1) <= cr) or gap_to_walls(grid, o[None])[0] == 0:
            continue
        ref = np.minimum.reduce([
            walls_only.scan(pose), circle_ref(o, dirs, cxy, cr), segment_ref(o, dirs, sa, sb)
        ])
        np.testing.assert_allclose(full.scan(pose, cxy, cr), clip(ref, spec), atol=1e-9)
    # The same scene without a grid nearby behaves like the analytic references alone.
    full.bind(free, sa, sb)
    pose = np.array([(xmin + xmax) / 2, (ymin + ymax) / 2, 0.3])
    o, dirs = sensor_frame(spec, pose)
    if not np.any(np.linalg.norm(cxy - o, axis=1) <= cr):
        ref = np.minimum(circle_ref(o, dirs, cxy, cr), segment_ref(o, dirs, sa, sb))
        np.testing.assert_allclose(full.scan(pose, cxy, cr), clip(ref, spec), atol=1e-9)


def test_batched_grid_cast_equals_scalar_cast() -> None:
    from arena.sensors.lidar2d.grid_kernels import _cast_grid

    rng = np.random.default_rng(77)
    for _ in range(5):
        grid = random_map(rng)
        spec = random_spec(rng, range_max=15.0)
        lidar = Lidar2D(spec)
        lidar.bind(grid)
        xmin, ymin, xmax, ymax = grid.bounds
        pose = np.array([*rng.uniform([xmin - 1, ymin - 1], [xmax + 1, ymax + 1]), 0.7])
        o, dirs = sensor_frame(spec, pose)
        if gap_to_walls(grid, o[None])[0] == 0:
            continue
        got = lidar.scan(pose)
        g = (o - np.asarray(grid.origin)) / grid.resolution
        distg = lidar._distg
        tlim = spec.range_max / grid.resolution
        scalar = np.array([_cast_grid(g[0], g[1], d[0], d[1], tlim, distg) for d in dirs])
        np.testing.assert_allclose(got, clip(scalar * grid.resolution, spec), atol=1e-12)


def test_thin_diagonal_wall_never_leaks() -> None:
    # A one-cell staircase from the map's bottom-right to its top-left corner: consecutive cells
    # touch only at corners, so the wall is held together by zero-width joints. Cell k spans
    # x ∈ [(39 − k)/4, (40 − k)/4], y ∈ [k/4, (k + 1)/4], i.e. 9.75 ≤ x + y ≤ 10.25.
    n = 40
    occ = np.zeros((n, n), dtype=bool)
    for k in range(n):
        occ[k, n - 1 - k] = True
    grid = OccupancyGrid.from_occupied(occ, 0.25)
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=3600, range_max=50.0)
    lidar = Lidar2D(spec)
    lidar.bind(grid)
    rng = np.random.default_rng(7)
    for _ in range(8):
        x, y = rng.uniform(0.1, 4.5, size=2)  # below the staircase
        pose = np.array([x, y, rng.uniform(-3, 3)])
        r = lidar.scan(pose)
        o, dirs = sensor_frame(spec, pose)
        s = dirs.sum(axis=1)
        ahead = s > 1e-6
        t_star = (10.25 - o.sum()) / s[ahead]  # where the beam reaches x + y = 10.25
        p_star = o + t_star[:, None] * dirs[ahead]
        on_map = np.all((p_star >= 0.0) & (p_star <= 10.0), axis=1)
        # Reaching the far side of the staircase inside the map would be a leak.
        assert np.all((r[ahead] <= t_star + 1e-9) | ~on_map)
    # Beams aimed exactly at the joints stop at the joint. A joint is a notch opening towards
    # −x, −y, and the quadrant below-left of it holds no blocking cell.
    lone = Lidar2D(ONE_BEAM)
    lone.bind(grid)
    for k in range(n - 1):
        corner = np.array([(39 - k) / 4, (k + 1) / 4])
        o = corner - rng.uniform(0.2, 3.0, size=2)
        yaw = math.atan2(corner[1] - o[1], corner[0] - o[0])
        got = lone.scan(np.array([*o, yaw]))[0]
        assert got == pytest.approx(float(np.hypot(*(corner - o))), abs=1e-9)


def test_sphere_tracing_reaches_exact_hits_at_every_distance() -> None:
    # A single blocking cell seen from many distances and angles, the beams aimed at points in
    # and around it (hits and near misses of its corners): after long jumps through open space
    # the hit or miss must be exactly that of the beam against the closed square.
    occ = np.zeros((200, 200), dtype=bool)
    occ[100, 150] = True
    grid = OccupancyGrid.from_occupied(occ, 0.05)
    spec = LidarSpec(angle_min=0.0, angle_max=0.0, num_beams=1, range_max=30.0)
    lidar = Lidar2D(spec)
    lidar.bind(grid)
    rng = np.random.default_rng(3)
    cell_lo = np.array([150 * 0.05, 100 * 0.05])
    n_hit = n_miss = 0
    for _ in range(600):
        target = cell_lo + rng.uniform(-0.01, 0.06, size=2)
        o = rng.uniform(0.0, 10.0, size=2)
        if np.all(np.floor(o / 0.05) == [150, 100]):
            continue
        yaw = math.atan2(*(target - o)[::-1])
        got = lidar.scan(np.array([*o, yaw]))[0]
        # Exact entry into the closed square by the slab method.
        d = np.array([math.cos(yaw), math.sin(yaw)])
        with np.errstate(divide="ignore"):
            t_a = (cell_lo - o) / d
            t_b = (cell_lo + 0.05 - o) / d
        t_in = np.max(np.minimum(t_a, t_b))
        t_out = np.min(np.maximum(t_a, t_b))
        if t_in <= t_out:
            assert got == pytest.approx(t_in, abs=1e-9)
            n_hit += 1
        else:
            assert got == spec.range_max
            n_miss += 1
    assert n_hit > 100 and n_miss > 50


# ------------------------------------------------------------------------------------------------
# Exact faces, grid lines and corners (res 0.25: grid coordinates are exact in binary)
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize(
    ("yaw", "expected"),
    [
        (0.0, 9.75 - 3.1),
        (math.pi / 2, 9.75 - 4.3),
        (math.pi, 3.1 - 0.25),
        (-math.pi / 2, 4.3 - 0.25),
    ],
)
def test_axis_aligned_beams_hit_faces_exactly(box_room, yaw: float, expected: float) -> None:
    assert one_beam(box_room, 3.1, 4.3, yaw) == pytest.approx(expected, abs=1e-12)


def test_axis_aligned_face_hit_with_offset_origin_and_fine_grid() -> None:
    occ = np.zeros((100, 200), dtype=bool)
    occ[:, 150:] = True
    grid = OccupancyGrid.from_occupied(occ, 0.05, origin=(-2.0, -1.0))
    # Wall face at x = −2 + 150·0.05 = 5.5.
    assert one_beam(grid, 0.37, 1.21, 0.0) == pytest.approx(5.5 - 0.37, abs=1e-9)


def test_beam_along_grid_line_touches_cells_on_both_sides() -> None:
    occ = np.zeros((20, 40), dtype=bool)
    occ[10, 30] = True  # above the line y = 2.5 (row 10 spans y ∈ [2.5, 2.75])
    occ[9, 20] = True  # below it (row 9 spans y ∈ [2.25, 2.5])
    grid = OccupancyGrid.from_occupied(occ, 0.25)
    assert one_beam(grid, 1.0, 2.5, 0.0) == pytest.approx(5.0 - 1.0, abs=1e-12)  # touches row 9
    assert one_beam(grid, 6.0, 2.5, 0.0) == pytest.approx(7.5 - 6.0, abs=1e-12)  # touches row 10
    assert one_beam(grid, 9.0, 2.5, math.pi) == pytest.approx(9.0 - 7.75, abs=1e-12)
    # Vertical beam along x = 5.0 (between columns 19 and 20), yaw π/2 gives cos = 6e-17.
    occ2 = np.zeros((40, 20), dtype=bool)
    occ2[30, 19] = True
    grid2 = OccupancyGrid.from_occupied(occ2, 0.25)
    assert one_beam(grid2, 5.0, 1.0, math.pi / 2) == pytest.approx(7.5 - 1.0, abs=1e-12)
    # A beam next to the line (not on it) misses that cell.
    assert one_beam(grid2, 5.01, 1.0, math.pi / 2) == ONE_BEAM.range_max


@pytest.mark.parametrize("quadrant", range(4))
def test_diagonal_gap_is_closed_and_corners_stop_beams(quadrant: int) -> None:
    # Two blocking cells touching at the corner (5, 5) (cells (4,5) and (5,4) in (row, col) for
    # the NE quadrant, mirrored for the others). A 45° beam through the corner stops there.
    sx = 1 if quadrant in (0, 3) else -1
    sy = 1 if quadrant in (0, 1) else -1
    n = 10
    occ = np.zeros((n, n), dtype=bool)
    cx0 = 5 if sx > 0 else 4  # column of the cell beyond the corner along x
    cy0 = 5 if sy > 0 else 4
    occ[cy0 - sy, cx0] = True  # beside the corner along x
    occ[cy0, cx0 - sx] = True  # beside it along y
    grid = OccupancyGrid.from_occupied(occ, 1.0)
    yaw = math.atan2(sy, sx)
    start = (5.0 - 3.0 * sx, 5.0 - 3.0 * sy)
    assert one_beam(grid, *start, yaw) == pytest.approx(3.0 * math.sqrt(2.0), abs=1e-9)
    # With one of the two cells removed the beam still touches the other one's corner: stops.
    occ1 = occ.copy()
    occ1[cy0 - sy, cx0] = False
    grid1 = OccupancyGrid.from_occupied(occ1, 1.0)
    assert one_beam(grid1, *start, yaw) == pytest.approx(3.0 * math.sqrt(2.0), abs=1e-9)
    # With both removed it passes the corner and leaves the map.
    grid0 = OccupancyGrid.from_occupied(np.zeros((n, n), dtype=bool), 1.0)
    assert one_beam(grid0, *start, yaw) == ONE_BEAM.range_max
    # Slightly off the corner, on the free side, the beam squeezes past the single cell.
    off = (start[0] + 0.01 * sx, start[1] - 0.01 * sy)  # shifted towards the removed cell
    assert one_beam(grid1, *off, yaw) == ONE_BEAM.range_max


