"""Tests of the 2-D lidar against independent brute-force and analytic references."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import SimulationError
from arena.maps.grid import OccupancyGrid
from arena.sensors import Lidar2D, LidarSpec

# ------------------------------------------------------------------------------------------------
# Independent references (pure numpy, no code shared with the module under test)
# ------------------------------------------------------------------------------------------------


def sensor_frame(spec: LidarSpec, pose) -> tuple[np.ndarray, np.ndarray]:
    """Sensor origin (2,) and unit beam directions (n, 2) in the world."""
    x, y, th = (float(v) for v in pose)
    mx, my, myaw = spec.mount
    c, s = math.cos(th), math.sin(th)
    o = np.array([x + c * mx - s * my, y + s * mx + c * my])
    ang = th + myaw + spec.angles()
    return o, np.stack([np.cos(ang), np.sin(ang)], axis=1)


def march_grid(grid: OccupancyGrid, o, dirs, t_max: float, step: float) -> np.ndarray:
    """First sample ``k·step`` of each ray inside a blocking cell (half-open cells), else inf."""
    ts = np.arange(0.0, t_max + step, step)
    out = np.full(len(dirs), np.inf)
    for lo in range(0, len(dirs), 64):
        d = dirs[lo : lo + 64]
        pts = o[None, None, :] + ts[:, None, None] * d[None, :, :]  # (S, b, 2)
        col = np.floor((pts[..., 0] - grid.origin[0]) / grid.resolution).astype(np.int64)
        row = np.floor((pts[..., 1] - grid.origin[1]) / grid.resolution).astype(np.int64)
        on = (row >= 0) & (row < grid.height) & (col >= 0) & (col < grid.width)
        hit = on & grid.occupied[np.clip(row, 0, grid.height - 1), np.clip(col, 0, grid.width - 1)]
        first = np.argmax(hit, axis=0)
        out[lo : lo + 64] = np.where(hit.any(axis=0), ts[first], np.inf)
    return out


def gap_to_walls(grid: OccupancyGrid, pts: np.ndarray) -> np.ndarray:
    """Distance (cells) from world points (k, 2) to the nearest closed blocking square nearby."""
    g = (pts - np.asarray(grid.origin)) / grid.resolution
    base = np.floor(g).astype(np.int64)
    best = np.full(len(pts), np.inf)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            r = base[:, 1] + dr
            c = base[:, 0] + dc
            on = (r >= 0) & (r < grid.height) & (c >= 0) & (c < grid.width)
            blk = on & grid.occupied[np.clip(r, 0, grid.height - 1), np.clip(c, 0, grid.width - 1)]
            ex = np.maximum.reduce([c - g[:, 0], g[:, 0] - (c + 1), np.zeros(len(g))])
            ey = np.maximum.reduce([r - g[:, 1], g[:, 1] - (r + 1), np.zeros(len(g))])
            best = np.where(blk, np.minimum(best, np.hypot(ex, ey)), best)
    return best


def clip_chords(grid: OccupancyGrid, o, dirs, ts) -> np.ndarray:
    """Length (m) of each ray's chord through the blocking squares it enters at ``ts``."""
    out = np.zeros(len(dirs))
    res = grid.resolution
    for k, (d, t) in enumerate(zip(dirs, ts, strict=True)):
        g = (o + t * d - np.asarray(grid.origin)) / res
        c0, r0 = np.floor(g).astype(np.int64)
        for r in range(r0 - 1, r0 + 2):
            for c in range(c0 - 1, c0 + 2):
                if not (0 <= r < grid.height and 0 <= c < grid.width and grid.occupied[r, c]):
                    continue
                lo = np.asarray(grid.origin) + res * np.array([c, r])
                with np.errstate(divide="ignore", invalid="ignore"):
                    ta, tb = (lo - o) / d, (lo + res - o) / d
                t_in = np.nanmax(np.minimum(ta, tb))
                t_out = np.nanmin(np.maximum(ta, tb))
                if abs(t_in - t) <= 1e-7:
                    out[k] = max(out[k], t_out - t_in)
    return out


def circle_ref(o, dirs, cxy, cr) -> np.ndarray:
    """Nearest non-negative root of |o + t·d − c| = r per beam (quadratic formula), else inf."""
    out = np.full(len(dirs), np.inf)
    for c, r in zip(np.asarray(cxy).reshape(-1, 2), np.asarray(cr).reshape(-1), strict=True):
        w = c - o
        b = dirs @ w
        cc = w @ w - r * r
        disc = b * b - cc
        t = b - np.sqrt(np.where(disc >= 0, disc, np.nan))
        ok = (disc >= 0) & (t >= 0)
        out = np.where(ok, np.minimum(out, t), out)
    return out


def segment_ref(o, dirs, a, b) -> np.ndarray:
    """Beam/segment hits by solving the 2×2 system [d, a − b]·[t, u] = a − o per pair."""
    out = np.full(len(dirs), np.inf)
    for pa, pb in zip(np.asarray(a).reshape(-1, 2), np.asarray(b).reshape(-1, 2), strict=True):
        m = np.stack([dirs, np.broadcast_to(pa - pb, dirs.shape)], axis=2)  # (n, 2, 2) columns
        rhs = np.broadcast_to(pa - o, dirs.shape)
        ok = np.abs(np.linalg.det(m)) > 1e-12
        sol = np.linalg.solve(m[ok], rhs[ok][..., None])[..., 0]
        t, u = sol[:, 0], sol[:, 1]
        good = (t >= 0) & (u >= 0) & (u <= 1)
        idx = np.flatnonzero(ok)[good]
        out[idx] = np.minimum(out[idx], t[good])
    return out


def clip(t: np.ndarray, spec: LidarSpec) -> np.ndarray:
    return np.clip(np.where(np.isfinite(t), t, spec.range_max), spec.range_min, spec.range_max)


def random_map(rng: np.random.Generator) -> OccupancyGrid:
    """A random map: rectangles, thin walls, diagonal staircases and speckle."""
    h, w = (int(v) for v in rng.integers(20, 60, size=2))
    occ = rng.random((h, w)) < rng.uniform(0.0, 0.03)
    for _ in range(int(rng.integers(2, 8))):
        r, c = int(rng.integers(0, h)), int(rng.integers(0, w))
        occ[r : r + int(rng.integers(1, 8)), c : c + int(rng.integers(1, 8))] = True
    for _ in range(int(rng.integers(0, 3))):  # one-cell diagonal lines (corner-touching cells)
        r, c, n = int(rng.integers(0, h)), int(rng.integers(0, w)), int(rng.integers(3, 15))
        s = 1 if rng.random() < 0.5 else -1
        for k in range(n):
            if 0 <= r + k < h and 0 <= c + s * k < w:
                occ[r + k, c + s * k] = True
    if rng.random() < 0.5:
        occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    res = float(rng.choice([0.05, 0.1, 0.2]))
    origin = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)))
    return OccupancyGrid.from_occupied(occ, res, origin)


def random_spec(rng: np.random.Generator, range_max: float) -> LidarSpec:
    if rng.random() < 0.3:
        n = int(rng.integers(90, 200))
        return LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=n, range_max=range_max)
    half = float(rng.uniform(0.5, 3.0))
    return LidarSpec(angle_min=-half, angle_max=half, num_beams=int(rng.integers(60, 200)),
                     range_max=range_max)


JACKAL = LidarSpec(angle_min=-2.356, angle_max=2.356, num_beams=720, range_max=30.0)


@pytest.fixture(autouse=True, params=["faces", "grid"])
def wall_casting(request, monkeypatch) -> str:
    """Run every test with the walls cast as faces and again by walking the grid."""
    import arena.sensors.lidar2d.model as mod

    monkeypatch.setattr(mod, "FACES_PER_BEAM", math.inf if request.param == "faces" else -1.0)
    return str(request.param)


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

ONE_BEAM = LidarSpec(angle_min=0.0, angle_max=0.0, num_beams=1, range_max=20.0)


def one_beam(grid: OccupancyGrid, x: float, y: float, yaw: float, spec: LidarSpec = ONE_BEAM):
    lidar = Lidar2D(spec)
    lidar.bind(grid)
    return float(lidar.scan(np.array([x, y, yaw]))[0])


@pytest.fixture
def box_room() -> OccupancyGrid:
    """40 × 40 cells at 0.25 m with a one-cell border: inner faces at 0.25 m and 9.75 m."""
    return OccupancyGrid.empty(10.0, 10.0, 0.25)


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


# ------------------------------------------------------------------------------------------------
# Circles and segments (empty map): analytic references
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(20))
def test_circles_and_segments_match_analytic(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    grid = OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False)
    spec = random_spec(rng, range_max=float(rng.uniform(5.0, 25.0)))
    lidar = Lidar2D(spec)
    n_static = int(rng.integers(0, 12))
    sa = rng.uniform(0, 20, size=(n_static, 2))
    sb = sa + rng.normal(0, 1.5, size=(n_static, 2))
    lidar.bind(grid, sa, sb)
    m = int(rng.integers(0, 25))
    cxy = rng.uniform(-2, 22, size=(m, 2))
    cr = rng.uniform(0.1, 1.0, size=m)
    k = int(rng.integers(0, 12))
    da = rng.uniform(0, 20, size=(k, 2))
    db = da + rng.normal(0, 1.0, size=(k, 2))
    for _ in range(5):
        pose = np.array([*rng.uniform(-1, 21, size=2), rng.uniform(-math.pi, math.pi)])
        o, dirs = sensor_frame(spec, pose)
        if np.any(np.linalg.norm(cxy - o, axis=1) <= cr):
            continue
        got = lidar.scan(pose, cxy, cr, da, db)
        ref = np.minimum.reduce([
            circle_ref(o, dirs, cxy, cr), segment_ref(o, dirs, sa, sb), segment_ref(o, dirs, da, db)
        ])
        np.testing.assert_allclose(got, clip(ref, spec), rtol=0, atol=1e-9)


def test_fast_atan2_error_bound() -> None:
    from arena.sensors.lidar2d.kernels import ATAN_ERR, _fast_atan2

    t = np.linspace(-math.pi, math.pi, 20001)
    for rad in (1e-3, 1.0, 1e3):
        y, x = rad * np.sin(t), rad * np.cos(t)
        approx = np.array([_fast_atan2(float(a), float(b)) for a, b in zip(y, x, strict=True)])
        err = np.angle(np.exp(1j * (approx - np.arctan2(y, x))))
        assert np.abs(err).max() < ATAN_ERR


def test_segment_nearly_through_the_origin() -> None:
    # The origin sits 1e-7 m off a long segment: the segment spans almost π as seen from it.
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=360, range_max=10.0)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0 + 1e-7, 0.05])
    a, b = np.array([[5.0, 10.0]]), np.array([[15.0, 10.0]])
    o, dirs = sensor_frame(spec, pose)
    got = lidar.scan(pose, segments_a=a, segments_b=b)
    np.testing.assert_allclose(got, clip(segment_ref(o, dirs, a, b), spec), atol=1e-9)
    assert np.sum(got < spec.range_max) > 100


def test_circle_behind_the_seam_of_a_full_circle_scan() -> None:
    # A circle straight behind (angle ±π) spans the first and the last beams of a full scan.
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=360, range_max=10.0)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0, 0.3])
    cxy = np.array([[10.0 - 3.0 * math.cos(0.3), 10.0 - 3.0 * math.sin(0.3)]])
    got = lidar.scan(pose, cxy, np.array([0.5]))
    o, dirs = sensor_frame(spec, pose)
    np.testing.assert_allclose(got, clip(circle_ref(o, dirs, cxy, [0.5]), spec), atol=1e-9)
    assert got[0] < 3.0 and got[-1] < 3.0 and got[180] == spec.range_max


def test_full_circle_has_no_duplicate_beam() -> None:
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=8, range_max=20.0)
    lidar = Lidar2D(spec)
    wrapped = np.mod(lidar.angles, 2 * math.pi)
    assert len(np.unique(np.round(wrapped, 12))) == 8
    np.testing.assert_allclose(np.diff(lidar.angles), 2 * math.pi / 8)
    # In an asymmetric scene every beam sees its own direction: beam 0 (−π) and beam 4 (0) differ.
    lidar.bind(OccupancyGrid.empty(10.0, 10.0, 0.25))
    r = lidar.scan(np.array([3.0, 5.0, 0.0]))
    assert r[0] == pytest.approx(3.0 - 0.25) and r[4] == pytest.approx(9.75 - 3.0)


def test_segment_special_cases() -> None:
    spec = ONE_BEAM
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(10.0, 10.0, 0.1, walls=False))
    pose = np.array([1.0, 1.0, 0.0])
    a, b = np.array([[4.0, 1.0]]), np.array([[6.0, 1.0]])  # collinear, ahead
    assert lidar.scan(pose, segments_a=a, segments_b=b)[0] == pytest.approx(3.0)
    assert lidar.scan(pose, segments_a=b, segments_b=a)[0] == pytest.approx(3.0)
    a, b = np.array([[4.0, 0.0]]), np.array([[4.0, 1.0]])  # beam hits the endpoint
    assert lidar.scan(pose, segments_a=a, segments_b=b)[0] == pytest.approx(3.0)
    a, b = np.array([[-1.0, 1.0]]), np.array([[0.5, 1.0]])  # collinear, behind
    assert lidar.scan(pose, segments_a=a, segments_b=b)[0] == spec.range_max
    # The origin lies on a segment: every beam reports range_min.
    full = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=16, range_max=5.0,
                     range_min=0.1)
    lid = Lidar2D(full)
    lid.bind(OccupancyGrid.empty(10.0, 10.0, 0.1, walls=False))
    got = lid.scan(pose, segments_a=np.array([[0.0, 0.0]]), segments_b=np.array([[2.0, 2.0]]))
    np.testing.assert_array_equal(got, 0.1)


def test_static_and_dynamic_segments_are_equivalent(box_room) -> None:
    rng = np.random.default_rng(5)
    a = rng.uniform(1, 9, size=(8, 2))
    b = a + rng.normal(0, 1, size=(8, 2))
    l1, l2 = Lidar2D(JACKAL), Lidar2D(JACKAL)
    l1.bind(box_room, a, b)
    l2.bind(box_room)
    pose = np.array([5.0, 5.0, 0.4])
    np.testing.assert_array_equal(l1.scan(pose), l2.scan(pose, segments_a=a, segments_b=b))


# ------------------------------------------------------------------------------------------------
# Clipping, mount, special origins
# ------------------------------------------------------------------------------------------------


def test_range_min_and_range_max_clipping() -> None:
    spec = LidarSpec(angle_min=-0.5, angle_max=0.5, num_beams=11, range_min=0.3, range_max=4.0)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0, 0.0])
    assert np.all(lidar.scan(pose) == 4.0)  # nothing in range
    far = lidar.scan(pose, np.array([[14.2, 10.0]]), np.array([0.1]))  # surface at 4.1 m
    assert np.all(far == 4.0)
    near = lidar.scan(pose, np.array([[10.25, 10.0]]), np.array([0.1]))  # surface at 0.15 m
    assert near[5] == 0.3
    mid = lidar.scan(pose, np.array([[12.0, 10.0]]), np.array([0.5]))
    assert mid[5] == pytest.approx(1.5)


def test_mount_offset_equals_scan_from_sensor_pose(box_room) -> None:
    mounted = LidarSpec(angle_min=-2.0, angle_max=2.0, num_beams=200, range_max=15.0,
                        mount=(0.3, -0.1, 0.7))
    plain = LidarSpec(angle_min=-2.0, angle_max=2.0, num_beams=200, range_max=15.0)
    lm, lp = Lidar2D(mounted), Lidar2D(plain)
    a = np.array([[2.0, 2.0], [7.0, 3.0]])
    b = np.array([[2.5, 7.0], [8.0, 8.0]])
    lm.bind(box_room, a, b)
    lp.bind(box_room, a, b)
    cxy, cr = np.array([[6.0, 6.0], [3.0, 7.5]]), np.array([0.4, 0.3])
    pose = np.array([4.0, 4.5, 1.1])
    o, _ = sensor_frame(mounted, pose)
    sensor_pose = np.array([o[0], o[1], pose[2] + 0.7])
    np.testing.assert_allclose(lm.scan(pose, cxy, cr), lp.scan(sensor_pose, cxy, cr), atol=1e-9)
    assert not np.allclose(lm.scan(pose, cxy, cr), lp.scan(pose, cxy, cr))


def test_origin_inside_or_touching_a_wall_reports_range_min(box_room) -> None:
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=64, range_max=8.0,
                     range_min=0.05)
    lidar = Lidar2D(spec)
    lidar.bind(box_room)
    np.testing.assert_array_equal(lidar.scan(np.array([0.1, 5.0, 0.0])), 0.05)  # inside
    np.testing.assert_array_equal(lidar.scan(np.array([0.25, 5.1, 0.0])), 0.05)  # on the face
    assert np.all(lidar.scan(np.array([0.4, 5.1, 0.0])) > 0.05)


def test_origin_inside_a_circle_reports_range_min(box_room) -> None:
    spec = LidarSpec(angle_min=-1.0, angle_max=1.0, num_beams=32, range_max=8.0, range_min=0.1)
    lidar = Lidar2D(spec)
    lidar.bind(box_room)
    got = lidar.scan(np.array([5.0, 5.0, 0.0]), np.array([[5.1, 5.0]]), np.array([0.3]))
    np.testing.assert_array_equal(got, 0.1)


def test_off_map_origin_sees_the_map_but_no_walls_outside() -> None:
    grid = OccupancyGrid.empty(5.0, 5.0, 0.25)  # border cells span [0, 0.25] etc.
    lidar = Lidar2D(ONE_BEAM)
    lidar.bind(grid)
    assert lidar.scan(np.array([-1.0, 2.1, 0.0]))[0] == pytest.approx(1.0)  # enters the border
    assert lidar.scan(np.array([-1.0, 2.1, math.pi]))[0] == ONE_BEAM.range_max
    got = lidar.scan(np.array([-1.0, 2.1, math.pi]), np.array([[-4.0, 2.1]]), np.array([0.5]))
    assert got[0] == pytest.approx(2.5)
    # From beyond the far side (y > 5) looking down.
    assert lidar.scan(np.array([2.1, 7.0, -math.pi / 2]))[0] == pytest.approx(2.0)


# ------------------------------------------------------------------------------------------------
# Noise, batching, API hygiene
# ------------------------------------------------------------------------------------------------


def test_noise_statistics_and_determinism(box_room) -> None:
    sigma = 0.02
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=720, range_max=30.0,
                     noise_std=sigma)
    lidar = Lidar2D(spec)
    lidar.bind(box_room)
    pose = np.array([4.0, 6.0, 0.2])
    clean = lidar.scan(pose)
    np.testing.assert_array_equal(lidar.scan(pose), clean)  # no rng: deterministic, no noise
    rng = np.random.default_rng(42)
    res = np.stack([lidar.scan(pose, rng=rng) - clean for _ in range(60)])
    n = res.size
    assert abs(res.mean()) < 4 * sigma / math.sqrt(n)
    assert res.std() == pytest.approx(sigma, rel=0.03)
    a = lidar.scan(pose, rng=np.random.default_rng(9))
    b = lidar.scan(pose, rng=np.random.default_rng(9))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, clean)


def test_noise_spares_max_range_and_stays_within_limits() -> None:
    spec = LidarSpec(angle_min=-1.0, angle_max=1.0, num_beams=101, range_max=2.0, range_min=0.2,
                     noise_std=0.5)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0, 0.0])
    cxy, cr = np.array([[10.5, 10.0]]), np.array([0.2])
    clean = lidar.scan(pose, cxy, cr)
    rng = np.random.default_rng(1)
    for _ in range(20):
        noisy = lidar.scan(pose, cxy, cr, rng=rng)
        miss = clean == spec.range_max
        np.testing.assert_array_equal(noisy[miss], spec.range_max)
        assert np.all((noisy >= 0.2) & (noisy <= 2.0))
        assert not np.array_equal(noisy[~miss], clean[~miss])


def test_scan_many_equals_repeated_scan(box_room) -> None:
    rng = np.random.default_rng(11)
    lidar = Lidar2D(JACKAL)
    lidar.bind(box_room, np.array([[3.0, 3.0]]), np.array([[4.0, 6.0]]))
    poses = np.column_stack([rng.uniform(1, 9, size=(5, 2)), rng.uniform(-3, 3, size=5)])
    cxy = rng.uniform(1, 9, size=(6, 2))
    cr = np.full(6, 0.2)
    da = rng.uniform(1, 9, size=(4, 2))
    db = da + 0.5
    many = lidar.scan_many(poses, cxy, cr, da, db)
    for i, p in enumerate(poses):
        np.testing.assert_array_equal(many[i], lidar.scan(p, cxy, cr, da, db))
    # With owners each robot ignores its own circle and segments.
    c_own = np.array([0, 1, 2, 3, 4, -1])
    s_own = np.array([0, 0, 3, -1])
    many = lidar.scan_many(poses, cxy, cr, da, db, circles_owner=c_own, segments_owner=s_own)
    for i, p in enumerate(poses):
        keep_c, keep_s = c_own != i, s_own != i
        one = lidar.scan(p, cxy[keep_c], cr[keep_c], da[keep_s], db[keep_s])
        np.testing.assert_array_equal(many[i], one)


def test_inputs_are_not_mutated_and_read_only_inputs_work(box_room) -> None:
    lidar = Lidar2D(JACKAL)
    sa, sb = np.array([[3.0, 3.0]]), np.array([[4.0, 6.0]])
    lidar.bind(box_room, sa, sb)
    pose = np.array([5.0, 5.0, 0.1])
    cxy, cr = np.array([[7.0, 5.0]]), np.array([0.3])
    da, db = np.array([[2.0, 8.0]]), np.array([[3.0, 8.5]])
    arrays = (pose, cxy, cr, da, db, sa, sb)
    before = [x.copy() for x in arrays]
    first = lidar.scan(pose, cxy, cr, da, db, rng=np.random.default_rng(0))
    for x, y in zip(arrays, before, strict=True):
        np.testing.assert_array_equal(x, y)
    sa[:] = 0.0  # bind copied the static segments
    for x in arrays:
        x.setflags(write=False)
    again = lidar.scan(pose, cxy, cr, da, db)
    np.testing.assert_array_equal(again, lidar.scan(pose.copy(), cxy.copy(), cr.copy(),
                                                    da.copy(), db.copy()))
    assert first.shape == (720,)


def test_usage_errors(box_room) -> None:
    lidar = Lidar2D(JACKAL)
    with pytest.raises(SimulationError):
        lidar.scan(np.zeros(3))
    lidar.bind(box_room)
    with pytest.raises(ValueError, match="pose"):
        lidar.scan(np.zeros(2))
    with pytest.raises(ValueError, match="finite"):
        lidar.scan(np.array([np.nan, 5.0, 0.0]))
    with pytest.raises(ValueError, match="circles_r"):
        lidar.scan(np.array([5.0, 5.0, 0.0]), np.zeros((2, 2)), np.zeros(3))
    with pytest.raises(ValueError, match="segments"):
        lidar.scan(np.array([5.0, 5.0, 0.0]), None, None, np.zeros((2, 2)), np.zeros((1, 2)))


def test_rebinding_switches_worlds() -> None:
    lidar = Lidar2D(ONE_BEAM)
    lidar.bind(OccupancyGrid.empty(10.0, 10.0, 0.25))
    assert lidar.scan(np.array([5.0, 5.1, 0.0]))[0] == pytest.approx(4.75)
    lidar.bind(OccupancyGrid.empty(8.0, 8.0, 0.25))
    assert lidar.scan(np.array([5.0, 5.1, 0.0]))[0] == pytest.approx(2.75)

