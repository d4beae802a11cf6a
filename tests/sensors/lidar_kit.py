"""Shared parts of the 2-D lidar tests: independent references, maps and the casting switch.

Imported explicitly by ``test_lidar2d_walls.py`` and ``test_lidar2d.py``. Importing the autouse
fixture :func:`wall_casting` into a test module runs every test of that module once with the
walls cast as faces and once by walking the grid (a conftest would also reach other modules).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

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



ONE_BEAM = LidarSpec(angle_min=0.0, angle_max=0.0, num_beams=1, range_max=20.0)


def one_beam(grid: OccupancyGrid, x: float, y: float, yaw: float, spec: LidarSpec = ONE_BEAM):
    lidar = Lidar2D(spec)
    lidar.bind(grid)
    return float(lidar.scan(np.array([x, y, yaw]))[0])
