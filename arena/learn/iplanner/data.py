"""Training data of iPlanner: depth images at random poses on generated maps, and the maps' SDFs.

For each map (``barn_maps`` BARN-like maps with the held-out barn suite's generator parameters
and ``indoor_maps`` ``rosnav_indoor`` maps, each drawn from ``derive_rng(seed, "iplanner",
"map", kind, i)``: never from a suite's stage seed, so no held-out map is trained on) the
3-D world is built (:func:`arena.sim.mujoco.world.build_world`, the map's obstacles included)
and the training camera (:data:`~.geometry.CAMERA`) renders ``poses_per_map`` depth images at
robot poses drawn uniformly over the cells at least ``min_clearance`` from a wall, heading
uniform. The robot's own body is not in the world (the camera does not see it).

There are no labels: the loss (:mod:`.loss`) reads the obstacle cost from the map's signed
distance field (the Euclidean distance transform of the occupancy grid with the obstacles
burnt in, negative inside walls; m) wherever the network's trajectory goes, so the dataset
keeps each map's SDF whole (``MapStack``) and each image's pose, instead of a crop per image.
Goals are drawn afresh for every batch (:func:`sample_goals`): iPlanner pairs each image with
several goals too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field
from scipy import ndimage

import arena.maps.generators  # noqa: F401  (registers the map generators)
from arena.core.rng import derive_rng
from arena.learn.iplanner.geometry import CAMERA, INPUT_SHAPE, depth_input
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import burn_obstacles
from arena.maps.sources import MAP_SOURCES

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]

BARN_MAP: dict[str, Any] = {"type": "barn", "width": 12.0, "height": 12.0, "cell_size": 0.25,
                            "fill_pct": 0.22, "smooth_iter": 4, "robot_radius": 0.4}
"""The barn suite's generator parameters (``arena/tasks/data/suites/barn.yaml``)."""


class DataParams(BaseModel):
    """How many maps and images, and where the robot may stand."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    barn_maps: int = Field(48, ge=0, description="BARN-like maps (the barn suite's generator)")
    indoor_maps: int = Field(12, ge=0, description="rosnav_indoor maps (30 × 30 m)")
    poses_per_map: int = Field(400, gt=0, description="depth images per map")
    min_clearance: float = Field(0.3, gt=0, description="m, wall distance of a sampled pose")
    goal_min: float = Field(0.5, gt=0, description="m, nearest training goal")
    goal_max: float = Field(4.0, gt=0, description="m, farthest training goal")
    goal_bearing: float = Field(
        math.radians(75), gt=0, le=math.pi, description="rad, largest |bearing| of a goal"
    )
    goal_clearance: float = Field(0.35, ge=0, description="m, wall distance a goal should keep")


def signed_distance(grid: OccupancyGrid) -> F32:
    """``(H, W)`` float32 signed distance (m) of each cell centre to the wall boundary.

    Positive in free space (distance to the nearest occupied cell centre less half a cell),
    negative inside walls (less half a cell as well), so the zero crossing lies on the cell edge.
    """
    occ = grid.occupied
    r = grid.resolution
    outside = ndimage.distance_transform_edt(~occ) * r if occ.any() else np.full(occ.shape, 1e3)
    inside = ndimage.distance_transform_edt(occ) * r
    return np.where(occ, 0.5 * r - inside, outside - 0.5 * r).astype(np.float32)


@dataclass(frozen=True, eq=False)
class MapStack:
    """Several maps' SDFs in one flat buffer (gathered by index in numpy and torch).

    Attributes:
        sdf: ``(total,)`` float32 m, map ``i`` rows first from ``offset[i]``.
        offset: ``(M,)`` int64 start of each map in ``sdf``.
        shape: ``(M, 2)`` int64 rows, columns.
        origin: ``(M, 2)`` float64 world position of each map's cell ``(0, 0)`` corner (m).
        resolution: ``(M,)`` float64 m per cell.
    """

    sdf: F32
    offset: NDArray[np.int64]
    shape: NDArray[np.int64]
    origin: F64
    resolution: F64

    @classmethod
    def from_grids(cls, sdfs: list[F32], grids: list[OccupancyGrid]) -> MapStack:
        """Stack the SDFs of ``grids`` (same order)."""
        sizes = [s.size for s in sdfs]
        offset = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        return cls(np.concatenate([s.reshape(-1) for s in sdfs]).astype(np.float32), offset,
                   np.array([s.shape for s in sdfs], dtype=np.int64).reshape(-1, 2),
                   np.array([g.origin for g in grids], dtype=np.float64).reshape(-1, 2),
                   np.array([g.resolution for g in grids], dtype=np.float64))

    def corners(self, maps: NDArray[np.int64], xy: F64) -> tuple[NDArray[np.int64], F64]:
        """Bilinear stencil of world points ``xy`` ``(N, P, 2)`` on maps ``maps`` ``(N,)``.

        Returns ``(index (N, P, 4), weights (N, P, 4))`` into :attr:`sdf`: the four cell
        centres around each point (clamped to the map: beyond it the border cell's value holds).
        """
        res = self.resolution[maps][:, None]
        u = (xy[..., 0] - self.origin[maps, 0][:, None]) / res - 0.5
        v = (xy[..., 1] - self.origin[maps, 1][:, None]) / res - 0.5
        rows, cols = self.shape[maps, 0][:, None], self.shape[maps, 1][:, None]
        u = np.clip(u, 0.0, cols - 1.0)
        v = np.clip(v, 0.0, rows - 1.0)
        c0 = np.minimum(np.floor(u).astype(np.int64), cols - 2).clip(0)
        r0 = np.minimum(np.floor(v).astype(np.int64), rows - 2).clip(0)
        fu, fv = u - c0, v - r0
        base = self.offset[maps][:, None] + r0 * cols + c0
        idx = np.stack([base, base + 1, base + cols, base + cols + 1], axis=-1)
        w = np.stack([(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv], axis=-1)
        return idx, w

    def distance(self, maps: NDArray[np.int64], xy: F64) -> F64:
        """Bilinear SDF (m) at world points ``xy`` ``(N, P, 2)`` of maps ``maps`` ``(N,)``."""
        idx, w = self.corners(np.asarray(maps, dtype=np.int64), np.asarray(xy, dtype=np.float64))
        out: F64 = np.einsum("npk,npk->np", self.sdf[idx].astype(np.float64), w)
        return out


@dataclass(frozen=True, eq=False)
class Dataset:
    """Rendered training images.

    Attributes:
        depth: ``(N, 48, 80)`` float16 network inputs in [0, 1] (:func:`~.geometry.depth_input`).
        pose: ``(N, 3)`` robot poses ``[x m, y m, θ rad]`` (world).
        map_index: ``(N,)`` int64 index into ``maps``.
        maps: the maps' SDFs.
    """

    depth: NDArray[np.float16]
    pose: F64
    map_index: NDArray[np.int64]
    maps: MapStack

    def __len__(self) -> int:
        return int(self.depth.shape[0])


def to_world(points: F64, pose: F64) -> F64:
    """Robot-frame points ``(N, P, 2)`` in the world, for poses ``(N, 3)``."""
    c, s = np.cos(pose[:, 2])[:, None], np.sin(pose[:, 2])[:, None]
    x, y = points[..., 0], points[..., 1]
    return np.stack([pose[:, 0:1] + c * x - s * y, pose[:, 1:2] + s * x + c * y], axis=-1)


def sample_goals(data: Dataset, rows: NDArray[np.int64], params: DataParams,
                 rng: np.random.Generator, candidates: int = 8) -> F64:
    """Goals ``(n, 2)`` (m, robot frame) for the images ``rows``.

    ``candidates`` goals per image, distance and bearing uniform in the params' ranges; the
    first keeping ``goal_clearance`` from walls is taken, else the one farthest from walls (a
    global path's subgoal lies in free space).
    """
    n = len(rows)
    r = rng.uniform(params.goal_min, params.goal_max, (n, candidates))
    b = rng.uniform(-params.goal_bearing, params.goal_bearing, (n, candidates))
    local = np.stack([r * np.cos(b), r * np.sin(b)], axis=-1)
    d = data.maps.distance(data.map_index[rows], to_world(local, data.pose[rows]))
    ok = d >= params.goal_clearance
    pick = np.where(ok.any(axis=1), ok.argmax(axis=1), d.argmax(axis=1))
    out: F64 = local[np.arange(n), pick]
    return out


def _map_specs(params: DataParams, seed: int) -> list[tuple[dict[str, Any], np.random.Generator]]:
    specs = [(BARN_MAP, derive_rng(seed, "iplanner", "map", "barn", i))
             for i in range(params.barn_maps)]
    specs += [({"type": "rosnav_indoor"}, derive_rng(seed, "iplanner", "map", "indoor", i))
              for i in range(params.indoor_maps)]
    return specs


def make_dataset(params: DataParams, seed: int) -> Dataset:
    """Render the dataset (needs the mujoco extra and headless GL; see the module docstring)."""
    from arena.sim.mujoco.camera import RgbdCamera
    from arena.sim.mujoco.mjcf import compile_model, import_mujoco
    from arena.sim.mujoco.world import build_world

    mj = import_mujoco()
    depth: list[NDArray[np.float16]] = []
    poses: list[F64] = []
    index: list[NDArray[np.int64]] = []
    sdfs: list[F32] = []
    grids: list[OccupancyGrid] = []
    for m, (block, rng) in enumerate(_map_specs(params, seed)):
        result = MAP_SOURCES.build(block, path="map").build(rng)
        grid = burn_obstacles(result.grid, result.obstacles)
        sdf = signed_distance(grid)
        model = compile_model(build_world(result.grid, result.obstacles,
                                          source=f"iplanner map {m}"))
        state = mj.MjData(model)
        mj.mj_forward(model, state)
        camera = RgbdCamera(model, CAMERA, segmentation=False)
        try:
            cells = np.argwhere(sdf >= params.min_clearance)
            pick = cells[rng.integers(len(cells), size=params.poses_per_map)]
            xy = grid.origin + (pick[:, ::-1] + rng.uniform(0, 1, (len(pick), 2))) \
                * grid.resolution
            pose = np.column_stack([xy, rng.uniform(-math.pi, math.pi, len(pick))])
            for p in pose:
                frame = camera.render(state, p)
                depth.append(depth_input(frame.depth, INPUT_SHAPE)[0].astype(np.float16))
        finally:
            camera.close()
        poses.append(pose)
        index.append(np.full(len(pose), m, dtype=np.int64))
        sdfs.append(sdf)
        grids.append(grid)
    return Dataset(np.stack(depth), np.concatenate(poses), np.concatenate(index),
                   MapStack.from_grids(sdfs, grids))
