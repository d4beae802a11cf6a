"""Training data of the motion-cost network: random terrain patches, an edge on each, labels.

Each sample is a square patch of ground (``PATCH`` m a side, 0.05 or 0.1 m cells, as the
planner's maps) made of random parts: a plane of up to 45°, a straight step of up to ±0.45 m,
a raised or sunken box, and 3×3-smoothed cell noise of up to 0.1 m standard deviation (each
part present with its own probability), lifted so the lowest cell is at 0. An edge of random
length (0.15 m to the network's ``max_length``) and heading passes near the centre. Heights
between cell centres are bilinear, exactly as :meth:`arena.maps.terrain.HeightMap.at` reads a
map, so the network sees the ground as the planner will give it.

Inputs: :func:`~arena.learn.artplanner.features.edge_features` (the coarse patch the planner
feeds the network). Labels: :func:`~arena.learn.artplanner.stepping.stepping_labels` on the
dense foot tracks (feasible, time per metre). Every draw comes from one seeded generator.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from arena.learn.artplanner.features import EdgeFeatureParams, edge_features
from arena.learn.artplanner.stepping import SteppingParams, stepping_labels, track_points

PATCH = 2.4
"""m, side of a training patch (an edge of 1 m plus the body's overhang fits with room)."""
CHUNK = 4000
"""Samples generated at once."""


def _bilinear(patches: NDArray[np.float64], res: float, pts: NDArray[np.float64]
              ) -> NDArray[np.float64]:
    """Heights of ``patches`` ``(n, R, R)`` at points ``(n, ..., 2)`` (m, patch centre at 0)."""
    n, rows, cols = patches.shape
    shape = pts.shape[:-1]
    q = pts.reshape(n, -1, 2)
    u = np.clip(q[..., 0] / res + cols / 2 - 0.5, 0.0, cols - 1.0)
    v = np.clip(q[..., 1] / res + rows / 2 - 0.5, 0.0, rows - 1.0)
    c0 = np.minimum(np.floor(u).astype(np.int64), cols - 2)
    r0 = np.minimum(np.floor(v).astype(np.int64), rows - 2)
    fu, fv = u - c0, v - r0
    k = np.arange(n)[:, None]
    z = (patches[k, r0, c0] * (1 - fu) * (1 - fv) + patches[k, r0, c0 + 1] * fu * (1 - fv)
         + patches[k, r0 + 1, c0] * (1 - fu) * fv + patches[k, r0 + 1, c0 + 1] * fu * fv)
    return np.asarray(z.reshape(shape), dtype=np.float64)


def random_patches(n: int, res: float, rng: np.random.Generator) -> NDArray[np.float64]:
    """``(n, R, R)`` random ground heights (m, ``≥ 0``) at cell centres, ``R = PATCH / res``."""
    cells = round(PATCH / res)
    c = (np.arange(cells) + 0.5) * res - PATCH / 2
    x, y = np.meshgrid(c, c)  # (R, R), row = y
    z = np.zeros((n, cells, cells))

    def direction() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        a = rng.uniform(-np.pi, np.pi, n)
        return np.cos(a)[:, None, None], np.sin(a)[:, None, None]

    on = rng.random(n) < 0.5  # a plane
    slope = np.tan(np.radians(rng.uniform(0, 45, n)))
    dx, dy = direction()
    z += (on * slope)[:, None, None] * (dx * x + dy * y)
    on = rng.random(n) < 0.55  # a straight step
    rise = rng.uniform(-0.45, 0.45, n) * on
    off = rng.uniform(-0.8, 0.8, n)[:, None, None]
    dx, dy = direction()
    z += rise[:, None, None] * ((dx * x + dy * y) > off)
    on = rng.random(n) < 0.3  # a box
    cx, cy = (rng.uniform(-0.8, 0.8, (2, n))[:, :, None, None])
    hx, hy = rng.uniform(0.15, 0.75, (2, n))[:, :, None, None]
    dx, dy = direction()
    lx = dx * (x - cx) + dy * (y - cy)
    ly = -dy * (x - cx) + dx * (y - cy)
    z += (rng.uniform(-0.4, 0.4, n) * on)[:, None, None] * ((np.abs(lx) < hx) & (np.abs(ly) < hy))
    on = rng.random(n) < 0.35  # rough ground
    noise = ndimage.uniform_filter(rng.normal(0, 1, z.shape), size=(1, 3, 3), mode="nearest")
    noise /= np.maximum(noise.std(axis=(1, 2), keepdims=True), 1e-12)
    z += (rng.uniform(0, 0.1, n) * on)[:, None, None] * noise
    return np.asarray(z - z.min(axis=(1, 2), keepdims=True), dtype=np.float64)


def make_dataset(n: int, features: EdgeFeatureParams, stepping: SteppingParams,
                 seed: int) -> tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.float32]]:
    """``(x (n, D), feasible (n,), time per metre (n,) s/m)`` of ``n`` random edges.

    Deterministic given ``seed``.
    """
    rng = np.random.default_rng(seed)
    xs, fs, ts = [], [], []
    done = 0
    while done < n:
        m = min(CHUNK, n - done)
        res = float(rng.choice([0.05, 0.1]))
        patches = random_patches(m, res, rng)
        length = rng.uniform(0.15, features.max_length, m)
        heading = rng.uniform(-np.pi, np.pi, m)
        centre = rng.uniform(-0.15, 0.15, (m, 2))
        d = np.stack([np.cos(heading), np.sin(heading)], axis=1) * length[:, None]
        a, b = centre - d / 2, centre + d / 2

        def height(pts: NDArray[np.float64], patches: NDArray[np.float64] = patches,
                   res: float = res) -> NDArray[np.float64]:
            return _bilinear(patches, res, pts)

        xs.append(edge_features(height, a, b, features))
        ok, t = stepping_labels(height(track_points(a, b, stepping)), length, stepping)
        fs.append(ok.astype(np.float32))
        ts.append(t.astype(np.float32))
        done += m
    return np.concatenate(xs), np.concatenate(fs), np.concatenate(ts)
