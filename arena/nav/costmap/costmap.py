"""Layered costmaps: the whole-map :class:`GlobalCostmap` and the rolling :class:`LocalCostmap`.

Both compose the layers of :mod:`arena.nav.costmap.layers` in ``costmap_2d`` order::

    master = inflate(max(static, obstacle, pedestrian bodies)) ⊔ personal space

(``⊔``: cell-wise maximum, unknown cells kept unknown). The obstacle layer has memory: marks
persist until a later beam clears them. The local costmap is a window of fixed size centred on
the robot (``rolling_window``); when the robot moves, the window's origin snaps to the static
map's cell lattice and the obstacle memory shifts with it (cells entering the window start free).

Defaults follow ``costmap_2d`` / Arena's move_base_flex configs, in SI units.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.crowd.semantic import SemanticData
from arena.maps.grid import OccupancyGrid
from arena.nav.costmap.layers import (
    FREE_SPACE,
    LETHAL,
    NO_INFORMATION,
    Costmap,
    inflate,
    social_costs,
    static_costs,
    static_window,
    update_obstacles,
)


class CostmapParams(BaseModel):
    """Parameters shared by the global and local costmaps (SI units, ROS-like defaults)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    inscribed_radius: float = Field(
        0.3, ge=0.0, description="m, robot inscribed radius (cost 253 within it of an obstacle)"
    )
    inflation_radius: float = Field(
        0.55, ge=0.0, description="m, inflation extent (costmap_2d default 0.55)"
    )
    cost_scaling_factor: float = Field(
        10.0, ge=0.0, description="1/m, exponential decay rate of the inflation cost (default 10)"
    )
    obstacle_range: float = Field(
        2.5, gt=0.0, description="m, returns closer than this mark obstacles (default 2.5)"
    )
    raytrace_range: float = Field(
        3.0, gt=0.0, description="m, free space is cleared up to this range (default 3.0)"
    )
    track_unknown: bool = Field(False, description="unknown map cells stay 255 (else free)")
    inflate_unknown: bool = Field(False, description="let low inflation costs overwrite 255")
    # Semantic (pedestrian) layer.
    use_semantic: bool = Field(True, description="add the pedestrian layer")
    presence_radius: float = Field(0.35, ge=0.0, description="m, pedestrian body radius")
    presence_cost: int = Field(LETHAL, ge=0, le=LETHAL, description="cost of body cells")
    social_amplitude: int = Field(200, ge=0, le=252, description="personal-space peak cost")
    social_sigma_side: float = Field(0.45, gt=0.0, description="m, lateral personal space σ")
    social_sigma_rear: float = Field(0.45, gt=0.0, description="m, rear (and at rest) σ")
    social_front_gain: float = Field(
        1.0, ge=0.0, description="s, frontal σ grows by this many metres per m/s of speed"
    )


class _Layered:
    """Shared composition of the layers; subclasses own the geometry."""

    params: CostmapParams
    obstacles: Costmap
    master: Costmap

    def _compose(
        self,
        static: NDArray[np.uint8],
        positions: ArrayLike | None,
        velocities: ArrayLike | None,
    ) -> None:
        p = self.params
        geo = self.obstacles
        base = np.maximum(np.where(static == NO_INFORMATION, 0, static), geo.costs)
        social = None
        if p.use_semantic and positions is not None:
            pos = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
            vel = (
                np.zeros_like(pos)
                if velocities is None
                else np.asarray(velocities, dtype=np.float64).reshape(-1, 2)
            )
            body = social_costs(
                geo.shape, geo.resolution, geo.origin, pos, vel,
                presence_radius=p.presence_radius, presence_cost=p.presence_cost, amplitude=0,
                sigma_side=p.social_sigma_side, sigma_rear=p.social_sigma_rear,
                front_gain=p.social_front_gain,
            )
            base = np.maximum(base, body)
            social = social_costs(
                geo.shape, geo.resolution, geo.origin, pos, vel,
                presence_radius=0.0, presence_cost=0, amplitude=p.social_amplitude,
                sigma_side=p.social_sigma_side, sigma_rear=p.social_sigma_rear,
                front_gain=p.social_front_gain,
            )
        # Unknown static cells stay unknown unless something is observed there.
        unknown = (static == NO_INFORMATION) & (base == FREE_SPACE)
        base = base.astype(np.uint8)
        base[unknown] = NO_INFORMATION
        out = inflate(
            base, geo.resolution, inscribed_radius=p.inscribed_radius,
            inflation_radius=p.inflation_radius, cost_scaling_factor=p.cost_scaling_factor,
            inflate_unknown=p.inflate_unknown,
        )
        if social is not None:
            known = out != NO_INFORMATION
            out = np.where(known, np.maximum(out, social), out).astype(np.uint8)
        self.master = Costmap(out, geo.resolution, geo.origin)


class GlobalCostmap(_Layered):
    """Costmap over the whole static map (``costmap_2d`` global costmap).

    Args:
        grid: the static map (uninflated).
        params: layer parameters; defaults if omitted.
    """

    def __init__(self, grid: OccupancyGrid, params: CostmapParams | None = None) -> None:
        self.params = params if params is not None else CostmapParams()
        self.grid = grid
        self._static = static_costs(grid, track_unknown=self.params.track_unknown)
        self.obstacles = Costmap.like(grid, FREE_SPACE)
        self._compose(self._static, None, None)

    def update(
        self,
        *,
        sensor_xy: ArrayLike | None = None,
        beam_angles: ArrayLike | None = None,
        ranges: ArrayLike | None = None,
        range_max: float = math.inf,
        ped_positions: ArrayLike | None = None,
        ped_velocities: ArrayLike | None = None,
        semantic: Mapping[str, SemanticData] | None = None,
    ) -> Costmap:
        """Fold in one scan and the current pedestrians; return the updated :attr:`master`.

        Args:
            sensor_xy: ``(2,)`` sensor position, world frame (m).
            beam_angles: ``(n,)`` beam directions, world frame (rad).
            ranges: ``(n,)`` ranges (m).
            range_max: the sensor's maximum range (m); such readings only clear.
            ped_positions: ``(m, 2)`` pedestrian positions (m).
            ped_velocities: ``(m, 2)`` their velocities (m/s).
            semantic: the crowd's semantic layers (:func:`arena.crowd.semantic.semantic_points`)
                instead of ``ped_positions`` / ``ped_velocities``.
        """
        if semantic is not None:
            ped_positions, ped_velocities = pedestrians_from_semantic(semantic)
        if sensor_xy is not None and beam_angles is not None and ranges is not None:
            update_obstacles(
                self.obstacles, sensor_xy, beam_angles, ranges,
                obstacle_range=self.params.obstacle_range,
                raytrace_range=self.params.raytrace_range, range_max=range_max,
            )
        self._compose(self._static, ped_positions, ped_velocities)
        return self.master


def pedestrians_from_semantic(
    semantic: Mapping[str, SemanticData],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Pedestrian positions and velocities from the crowd's semantic layers.

    Reads the ``pedestrian`` layer's locations and the ``pedestrian_vel_x`` /
    ``pedestrian_vel_y`` evidence (see :mod:`arena.crowd.semantic`), which list the same people
    in the same order.

    Returns:
        ``(m, 2)`` positions (m) and ``(m, 2)`` velocities (m/s), world frame.
    """
    people = semantic["pedestrian"]
    pos = np.asarray(people.locations, dtype=np.float64).reshape(-1, 2)
    vx = np.asarray(semantic["pedestrian_vel_x"].evidence, dtype=np.float64).reshape(-1)
    vy = np.asarray(semantic["pedestrian_vel_y"].evidence, dtype=np.float64).reshape(-1)
    if not len(vx) == len(vy) == len(pos):
        raise ValueError("semantic layers pedestrian / pedestrian_vel_x / _y differ in length")
    return pos, np.stack([vx, vy], axis=1)


class LocalCostmap(_Layered):
    """Rolling-window costmap centred on the robot (``costmap_2d`` local costmap).

    The window is ``width × height`` metres on the static map's cell lattice (same resolution);
    cells off the static map count as free (unknown with ``track_unknown``).

    Args:
        grid: the static map.
        width: window width (m), default 6.0.
        height: window height (m), default 6.0.
        params: layer parameters.
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        width: float = 6.0,
        height: float = 6.0,
        params: CostmapParams | None = None,
    ) -> None:
        if not (width > 0 and height > 0):
            raise ValueError(f"window size must be positive, got {width} x {height} m")
        self.params = params if params is not None else CostmapParams()
        self.grid = grid
        self._static = static_costs(grid, track_unknown=self.params.track_unknown)
        self.cols = max(1, round(width / grid.resolution))
        self.rows = max(1, round(height / grid.resolution))
        self._row0 = 0
        self._col0 = 0
        self.obstacles = Costmap(
            np.zeros((self.rows, self.cols), dtype=np.uint8), grid.resolution, grid.origin
        )
        self.master = Costmap(self.obstacles.costs.copy(), grid.resolution, grid.origin)

    def _move_to(self, xy: NDArray[np.float64]) -> None:
        """Re-centre the window on ``xy`` (m), shifting the obstacle memory (numpy slicing)."""
        res = self.grid.resolution
        col0 = math.floor((xy[0] - self.grid.origin[0]) / res) - self.cols // 2
        row0 = math.floor((xy[1] - self.grid.origin[1]) / res) - self.rows // 2
        dr, dc = row0 - self._row0, col0 - self._col0
        if dr or dc:
            old = self.obstacles.costs
            new = np.zeros_like(old)
            h, w = old.shape
            if abs(dr) < h and abs(dc) < w:
                new[max(-dr, 0) : h - max(dr, 0), max(-dc, 0) : w - max(dc, 0)] = old[
                    max(dr, 0) : h - max(-dr, 0), max(dc, 0) : w - max(-dc, 0)
                ]
            self.obstacles.costs = new
        self._row0, self._col0 = row0, col0
        self.obstacles.origin = (
            self.grid.origin[0] + col0 * res,
            self.grid.origin[1] + row0 * res,
        )

    def update(
        self,
        robot_pose: ArrayLike,
        *,
        scan_ranges: ArrayLike | None = None,
        scan_angles: ArrayLike | None = None,
        scan_origin: ArrayLike = (0.0, 0.0),
        range_max: float = math.inf,
        ped_positions: ArrayLike | None = None,
        ped_velocities: ArrayLike | None = None,
        semantic: Mapping[str, SemanticData] | None = None,
    ) -> Costmap:
        """One tick: follow the robot, fold in the scan and the pedestrians.

        Args:
            robot_pose: ``(3,)`` ``[x m, y m, yaw rad]``, world frame.
            scan_ranges: ``(n,)`` ranges (m) of a scan, or ``None``.
            scan_angles: ``(n,)`` beam angles in the robot frame (rad).
            scan_origin: ``(2,)`` sensor position in the robot frame (m).
            range_max: the sensor's maximum range (m); such readings only clear.
            ped_positions: ``(m, 2)`` pedestrian positions (m), world frame.
            ped_velocities: ``(m, 2)`` their velocities (m/s).
            semantic: the crowd's semantic layers instead of the two arrays above.

        Returns:
            The updated :attr:`master` window.
        """
        if semantic is not None:
            ped_positions, ped_velocities = pedestrians_from_semantic(semantic)
        pose = np.asarray(robot_pose, dtype=np.float64).reshape(3)
        self._move_to(pose[:2])
        if scan_ranges is not None and scan_angles is not None:
            c, s = math.cos(pose[2]), math.sin(pose[2])
            so = np.asarray(scan_origin, dtype=np.float64).reshape(2)
            sensor = pose[:2] + np.array([c * so[0] - s * so[1], s * so[0] + c * so[1]])
            update_obstacles(
                self.obstacles, sensor, np.asarray(scan_angles, dtype=np.float64) + pose[2],
                scan_ranges, obstacle_range=self.params.obstacle_range,
                raytrace_range=self.params.raytrace_range, range_max=range_max,
            )
        static = static_window(
            self._static, self._row0, self._col0, self.rows, self.cols,
            off_map=NO_INFORMATION if self.params.track_unknown else FREE_SPACE,
        )
        self._compose(static, ped_positions, ped_velocities)
        return self.master
