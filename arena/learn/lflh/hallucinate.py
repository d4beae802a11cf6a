"""Computed hallucination: obstacles hugging both sides of a motion's swept footprint.

LfLH (Wang, Xiao, Liu, Warnell, Stone, IROS 2021) *learns* a generative model of the most
constrained obstacle sets in which a motion stays optimal and collision-free. We simplify it to
a *computed* hallucination with the same intent: walls of random thickness at a random
clearance just outside the swept disc footprint, on each side separately, with random gaps
along the way, and nothing ahead of the motion's end (the corridor continues where the motion
goes). The clearance grows with the motion's speed: a fast motion is only the best one when
there is room to brake, so a tight corridor should teach slow commands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.maps.grid import FREE, OCCUPIED, OccupancyGrid


class HallucinationParams(BaseModel):
    """How obstacles are placed around a motion."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    robot_radius: float = Field(0.267, gt=0, description="m, disc footprint (the jackal's)")
    extent: float = Field(
        3.2, gt=0, description="m, half side of the square grid at the robot (>= the scan clip)"
    )
    resolution: float = Field(0.05, gt=0, description="m, grid cell edge")
    clearance_min: float = Field(0.05, ge=0, description="m, gap at standstill")
    clearance_per_speed: float = Field(0.2, ge=0, description="s, extra gap per m/s of speed")
    clearance_spread: float = Field(0.6, ge=0, description="m, random extra gap per side")
    thickness: tuple[float, float] = Field((0.1, 0.5), description="m, wall thickness range")
    gap_length: float = Field(0.3, gt=0, description="m, arc length of one droppable wall piece")
    path_stride: int = Field(
        3, ge=1, description="poses per path vertex: an arc's chord sags < 2 cm at 3 x 5 cm steps"
    )
    gap_probability: float = Field(0.2, ge=0, le=1, description="chance a wall piece is missing")
    open_side_probability: float = Field(
        0.0, ge=0, le=1,
        description="chance a side has no wall at all (0: always walls, the shipped policy)",
    )
    behind_probability: float = Field(0.5, ge=0, le=1, description="chance of a wall behind")


@dataclass(frozen=True, eq=False)
class Hallucination:
    """Obstacles around one motion.

    Attributes:
        grid: the occupancy grid, robot at the world origin heading +x.
        clearance: ``(2,)`` gap (m) between the swept footprint and the wall, ``[left, right]``;
            ``inf`` for a side left open.
    """

    grid: OccupancyGrid
    clearance: NDArray[np.float64]


def path_distance(
    points: NDArray[np.float64], path: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Distance of ``points`` ``(n, 2)`` (m) to the polyline ``path`` ``(k, 2)``.

    Returns:
        ``(n,)`` distances (m), ``(n,)`` arc lengths (m) of the closest path points and ``(n,)``
        signed sides (+1 left of the path's direction there, -1 right, 0 on it).
    """
    a, b = path[:-1], path[1:]
    ab = b - a
    seg = np.linalg.norm(ab, axis=1)
    len2 = np.maximum(seg**2, 1e-12)
    rel = points[:, None, :] - a[None]
    t = np.clip(np.einsum("nkj,kj->nk", rel, ab) / len2, 0.0, 1.0)
    d = np.linalg.norm(rel - t[..., None] * ab[None], axis=-1)
    j = np.argmin(d, axis=1)
    n = np.arange(len(points))
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = cum[j] + t[n, j] * seg[j]
    cross = ab[j, 0] * rel[n, j, 1] - ab[j, 1] * rel[n, j, 0]
    return d[n, j], s, np.sign(cross)


def hallucinate(
    poses: NDArray[np.float64], speed: float, params: HallucinationParams,
    rng: np.random.Generator,
) -> Hallucination:
    """Place walls around the motion whose poses ``(T + 1, 3)`` start at the origin.

    ``speed`` (m/s) is the motion's mean speed; it widens the clearance.

    The swept footprint is the union of discs of ``robot_radius`` at the poses (the jackal's
    bounding disc: its rectangle turns inside it). Every occupied cell lies, corners included,
    at least ``robot_radius + clearance_min`` from the path (less the chord sag of the strided
    path, under 2 cm), so the motion never touches it.
    """
    p = params
    xy = poses[:: p.path_stride, :2]
    if (len(poses) - 1) % p.path_stride:
        xy = np.vstack([xy, poses[-1:, :2]])  # the end vertex always
    if len(xy) < 2:
        xy = np.vstack([xy, xy])
    length = float(np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1)))
    n = round(2 * p.extent / p.resolution)
    centres = (np.arange(n) + 0.5) * p.resolution - p.extent
    gx, gy = np.meshgrid(centres, centres)  # row = y, col = x, as the grid stores them
    pts = np.stack([gx.ravel(), gy.ravel()], axis=-1)
    d, s, side = path_distance(pts, xy)
    half_diag = p.resolution * math.sqrt(0.5)  # a cell's corner is this close to its centre
    clearance = np.empty(2)
    occupied = np.zeros(len(pts), dtype=bool)
    for k, sign in enumerate((1.0, -1.0)):
        c = p.clearance_min + p.clearance_per_speed * speed + rng.uniform(
            0.0, p.clearance_spread)
        w = rng.uniform(*p.thickness)
        clearance[k] = c
        inner = p.robot_radius + c + half_diag
        # no draw at 0: the shipped policy's samples were drawn before this option existed
        if p.open_side_probability > 0 and rng.random() < p.open_side_probability:
            clearance[k] = math.inf
            continue
        band = (d >= inner) & (d <= inner + w) & ((side == sign) | (side == 0))
        # random gaps: drop whole pieces of wall along the arc length
        pieces = int(length // p.gap_length) + 1
        keep = rng.random(pieces + 1) >= p.gap_probability
        band &= keep[np.minimum((s // p.gap_length).astype(int), pieces)]
        occupied |= band
    end, head = xy[-1], poses[-1, 2]
    ahead = (pts - end) @ np.array([math.cos(head), math.sin(head)]) > 0
    occupied &= ~(ahead & (s >= length - 1e-9))  # the corridor stays open past the end
    if rng.random() >= p.behind_probability:
        occupied &= ~((pts[:, 0] < 0) & (s <= 1e-9))
    data = np.where(occupied.reshape(n, n), OCCUPIED, FREE).astype(np.int8)
    grid = OccupancyGrid(data, p.resolution, (-p.extent, -p.extent))
    return Hallucination(grid, clearance)
