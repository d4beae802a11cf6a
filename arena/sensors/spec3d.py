"""Specifications of the 3-D sensors: an RGB-D camera and a multi-ring (3-D) lidar.

The ``Params`` of the ``rgbd`` and ``lidar3d`` sensor types
(:data:`arena.sensors.base.SENSORS`); the MuJoCo backend measures them
(:mod:`arena.sim.mujoco.camera`, :mod:`arena.sim.mujoco.lidar3d`); an ``rgbd`` reading is an
:class:`RgbdFrame`, a ``lidar3d`` reading a ``(rings, num_beams)`` array of ranges (m).
Frames: the robot base frame is x forward, y left, z up from the floor under the robot's
origin (m); a mount's yaw turns about z (rad, counter-clockwise), a camera's pitch tilts its
optical axis down (rad, positive looks at the floor, as ROS's rotation about y).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.sensors.spec import check_fan, fan_increment

MAX_IMAGE_PX = 4096
"""Largest image width or height (px) of a camera."""

MAX_LIDAR3D_RAYS = 1_000_000
"""Most rays (``rings × num_beams``) of one 3-D lidar scan."""


class RgbdSpec(BaseModel):
    """A pinhole RGB-D camera: colour, metric depth and per-pixel person ids.

    Intrinsics follow OpenCV: pixel ``(u, v)`` (column, row from the top-left) has its centre at
    integer coordinates, and the ray through it has direction ``((u - cx) / fx, (v - cy) / fy,
    1)`` in the optical frame (x right, y down, z along the optical axis). Give either ``fovy``
    (then ``fx = fy = (height / 2) / tan(fovy / 2)`` and the principal point is the image
    centre, ``cx = (width - 1) / 2``, ``cy = (height - 1) / 2``) or all of ``fx, fy, cx, cy``;
    the renderer draws square pixels, so ``fx`` must equal ``fy``.

    Depth is the metric distance along the optical axis (z in the optical frame, not the ray
    length) of the nearest surface between ``near`` and ``far``; pixels with no surface in that
    range read ``0`` (no return, as real depth cameras report it). Surfaces nearer than ``near``
    are clipped away (the camera sees past them).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    type: Literal["rgbd"] = Field("rgbd", description="sensor type (registry name)")
    width: int = Field(320, gt=0, le=MAX_IMAGE_PX, description="px, image width")
    height: int = Field(240, gt=0, le=MAX_IMAGE_PX, description="px, image height")
    fovy: float | None = Field(
        None, gt=0, lt=180, description="deg, vertical field of view (60 when no fx..cy given)"
    )
    fx: float | None = Field(None, gt=0, description="px, focal length along image columns")
    fy: float | None = Field(None, gt=0, description="px, focal length along image rows")
    cx: float | None = Field(None, description="px, principal point column (0: first pixel)")
    cy: float | None = Field(None, description="px, principal point row (0: top pixel)")
    near: float = Field(0.05, gt=0, description="m, near clip plane (nearer is not seen)")
    far: float = Field(
        10.0, gt=0, le=1000.0, description="m, far clip plane (farther reads depth 0)"
    )
    update_rate: float = Field(15.0, gt=0, le=1000.0, description="Hz (<= 1000)")
    depth_noise_std: float = Field(
        0.0, ge=0, description="m, std of additive Gaussian depth noise (valid pixels only)"
    )
    mount: tuple[float, float, float, float, float] = Field(
        description="camera pose [x m, y m, z m, yaw rad, pitch rad] in the robot base frame "
        "(pitch > 0 looks down)"
    )

    @model_validator(mode="after")
    def _check(self) -> RgbdSpec:
        given = {k: getattr(self, k) for k in ("fx", "fy", "cx", "cy")}
        named = [k for k, v in given.items() if v is not None]
        if named and self.fovy is not None:
            raise ValueError(f"give either fovy or fx, fy, cx, cy, not both (got fovy and "
                             f"{', '.join(named)})")
        if named and len(named) < 4:
            missing = [k for k, v in given.items() if v is None]
            raise ValueError(f"fx, fy, cx, cy go together: {', '.join(missing)} missing")
        if named and abs(self.fx - self.fy) > 1e-6 * self.fx:  # type: ignore[operator]
            raise ValueError(f"fx ({self.fx}) must equal fy ({self.fy}): the renderer draws "
                             "square pixels")
        if self.near >= self.far:
            raise ValueError(f"near ({self.near}) must be < far ({self.far})")
        if self.mount[2] < 0:
            raise ValueError(f"mount z ({self.mount[2]}) must be >= 0 (above the floor)")
        if not abs(self.mount[4]) < math.pi / 2:
            raise ValueError(f"mount pitch ({self.mount[4]}) must lie in (-pi/2, pi/2)")
        return self

    def intrinsics(self) -> tuple[float, float, float, float]:
        """``(fx, fy, cx, cy)`` in px (derived from ``fovy`` when that is given)."""
        if self.fx is not None:
            return (self.fx, self.fy, self.cx, self.cy)  # type: ignore[return-value]
        fovy = 60.0 if self.fovy is None else self.fovy
        f = (self.height / 2) / math.tan(math.radians(fovy) / 2)
        return (f, f, (self.width - 1) / 2, (self.height - 1) / 2)

    def rays(self) -> NDArray[np.float64]:
        """``(height, width, 3)`` ray directions in the optical frame, z = 1 (x right, y down)."""
        fx, fy, cx, cy = self.intrinsics()
        v, u = np.mgrid[0 : self.height, 0 : self.width].astype(np.float64)
        return np.stack([(u - cx) / fx, (v - cy) / fy, np.ones_like(u)], axis=-1)


class Lidar3DSpec(BaseModel):
    """A multi-ring lidar: ``rings`` cones of ``num_beams`` beams each.

    Ring ``k`` has elevation ``vertical_min + k · (vertical_max - vertical_min) / (rings - 1)``
    (rad above the mount's horizontal plane; one ring sits at ``vertical_min``). Within a ring
    the horizontal angles follow :class:`~arena.sensors.spec.LidarSpec`: beam ``i`` at
    ``angle_min + i · angle_increment`` in the sensor frame, a full circle spread without
    repeating the first beam. Ranges are measured from the mount point along the beam;
    no hit before ``range_max`` reads ``range_max``, a hit nearer than ``range_min`` reads
    ``range_min``.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    type: Literal["lidar3d"] = Field("lidar3d", description="sensor type (registry name)")
    rings: int = Field(16, gt=0, le=1024, description="number of rings (vertical channels)")
    num_beams: int = Field(gt=0, le=10_000, description="beams per ring")
    vertical_min: float = Field(
        -math.radians(15), ge=-math.pi / 2, le=math.pi / 2,
        description="rad, elevation of the lowest ring (negative: below the horizon)",
    )
    vertical_max: float = Field(
        math.radians(15), ge=-math.pi / 2, le=math.pi / 2,
        description="rad, elevation of the highest ring",
    )
    angle_min: float = Field(-math.pi, description="rad, first beam angle of each ring")
    angle_max: float = Field(math.pi, description="rad, last beam angle of each ring")
    range_max: float = Field(
        gt=0, le=1000.0, description="m, beams that hit nothing report this range (<= 1000)"
    )
    range_min: float = Field(0.0, ge=0, description="m, returns closer than this report range_min")
    update_rate: float = Field(10.0, gt=0, le=1000.0, description="Hz (<= 1000)")
    noise_std: float = Field(0.0, ge=0, description="m, std of additive Gaussian range noise")
    mount: tuple[float, float, float, float] = Field(
        description="sensor pose [x m, y m, z m, yaw rad] in the robot base frame"
    )

    @model_validator(mode="after")
    def _check(self) -> Lidar3DSpec:
        check_fan(self.angle_min, self.angle_max, self.range_min, self.range_max)
        if self.vertical_max < self.vertical_min:
            raise ValueError(f"vertical_max ({self.vertical_max}) must be >= vertical_min "
                             f"({self.vertical_min})")
        if self.rings * self.num_beams > MAX_LIDAR3D_RAYS:
            raise ValueError(f"rings x num_beams = {self.rings * self.num_beams:,} rays, more "
                             f"than {MAX_LIDAR3D_RAYS:,}")
        if self.mount[2] < 0:
            raise ValueError(f"mount z ({self.mount[2]}) must be >= 0 (above the floor)")
        return self

    def angles(self) -> NDArray[np.float64]:
        """Horizontal beam angles of a ring in the sensor frame, ``(num_beams,)`` (rad)."""
        inc = fan_increment(self.angle_min, self.angle_max, self.num_beams)
        return self.angle_min + inc * np.arange(self.num_beams, dtype=np.float64)

    def elevations(self) -> NDArray[np.float64]:
        """Ring elevations, ``(rings,)`` (rad, positive up)."""
        inc = (self.vertical_max - self.vertical_min) / max(self.rings - 1, 1)
        return self.vertical_min + inc * np.arange(self.rings, dtype=np.float64)

    def directions(self) -> NDArray[np.float64]:
        """``(rings, num_beams, 3)`` unit beam directions in the sensor frame (x, y, z)."""
        el = self.elevations()[:, None]
        az = self.angles()[None, :]
        return np.stack(np.broadcast_arrays(np.cos(el) * np.cos(az), np.cos(el) * np.sin(az),
                                            np.sin(el)), axis=-1)


def camera_pose(
    spec: RgbdSpec, pose: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(position, forward, up)`` of the camera in the world (m, unit vectors), each ``(3,)``.

    ``pose`` is the robot base pose ``(x m, y m, yaw rad)``; the mount
    ``(x, y, z, yaw, pitch)`` is applied in the base frame, pitch > 0 looking down.
    """
    x, y, yaw = (float(v) for v in np.asarray(pose, dtype=np.float64).reshape(3))
    mx, my, mz, myaw, pitch = spec.mount
    c, s = math.cos(yaw), math.sin(yaw)
    pos = np.array([x + c * mx - s * my, y + s * mx + c * my, mz])
    h = yaw + myaw
    cp, sp = math.cos(pitch), math.sin(pitch)
    forward = np.array([cp * math.cos(h), cp * math.sin(h), -sp])
    up = np.array([sp * math.cos(h), sp * math.sin(h), cp])
    return pos, forward, up


@dataclass(frozen=True, eq=False)
class RgbdFrame:
    """One camera frame in image order (row 0 at the top, column 0 at the left).

    Attributes:
        rgb: ``(H, W, 3)`` uint8 colour.
        depth: ``(H, W)`` float32 metres along the optical axis; ``0`` where no surface lies
            between the spec's ``near`` and ``far``.
        person: ``(H, W)`` int32 person id seen at each pixel, ``-1`` for anything else;
            ``None`` when the camera renders without segmentation.
    """

    rgb: NDArray[np.uint8]
    depth: NDArray[np.float32]
    person: NDArray[np.int32] | None

    def person_pixels(self, n: int) -> NDArray[np.int64]:
        """``(n,)`` pixels showing each of people ``0 … n-1`` (zeros without segmentation)."""
        if self.person is None:
            return np.zeros(n, dtype=np.int64)
        ids = self.person[self.person >= 0]
        counts: NDArray[np.int64] = np.bincount(ids, minlength=n)[:n]
        return counts
