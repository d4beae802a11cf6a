"""Where the navigation stack's people come from: ``navigation.perception: {type: ...}``.

Every planner and intermediate planner that uses people reads them from one
:class:`~arena.nav.intermediate.base.Pedestrians` per control tick (the local planner through
``LocalObservation.pedestrians``, the costmaps' semantic layer, the intermediate planner).
A perception plugin (registry :data:`PERCEPTION`) makes it from the tick's :class:`Senses`:

* ``ground_truth`` (the default): the simulator's people, with their types and social states;
* ``lidar``: the robot's own scan (the stack's ``scan_sensor``) through the
  :class:`~arena.perception.lidar_detector.LidarPeopleDetector`;
* ``rgbd``: the frame of the robot's ``rgbd`` camera ``sensor`` (3-D backend) through the
  :class:`~arena.perception.rgbd_detector.RgbdPeopleDetector`;
* ``fused``: both, detections of the two within ``fuse_radius`` taken as one person (at the
  lidar's position: a scan measures range more precisely than a shrunk depth image).

The detecting plugins move their detections to the world frame and track them
(:class:`~arena.perception.tracker.Tracker`): the planners get the confirmed tracks' positions
and velocities; types and social states are unknown (empty), since sensors show neither.
After each tick such a plugin's ``last`` (:class:`Perceived`) holds the detections, the tracks
and which ground-truth people its sensors showed: the episode's record keeps them for the
tracking metrics (:mod:`arena.eval.metrics.tracking`) and the frames draw them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.core.registry import Registry
from arena.nav.intermediate.base import Pedestrians
from arena.perception.lidar_detector import LidarPeopleDetector
from arena.perception.tracker import Tracker, TrackerParams, Tracks
from arena.robots.model import RobotModel
from arena.scene.state import AgentStates
from arena.sensors.spec import LidarReading
from arena.sensors.spec3d import RgbdFrame, RgbdSpec

F64 = NDArray[np.float64]

LIDAR_SEEN_HITS = 3
"""A scan shows a person when at least this many beams end on their body (radius + 0.1 m)."""

CAMERA_SEEN_FRACTION = 0.002
"""A frame shows a person when at least this fraction of its pixels do (150 of 320 × 240)."""


@dataclass(frozen=True, eq=False)
class Senses:
    """What the robot senses at one control tick, with the ground truth beside it.

    Attributes:
        time: s.
        pose: ``(3,)`` robot pose ``[x m, y m, θ rad]``, world frame.
        scan: the stack's lidar reading (``navigation.scan_sensor``).
        range_max: m, that lidar's range (a beam reading it returned nothing).
        readings: every sensor's reading by name (lidars as :class:`LidarReading`, cameras as
            :class:`~arena.sensors.spec3d.RgbdFrame`).
        agents: the simulator's people: only ``ground_truth`` hands them to the planners; the
            detecting plugins read them only to note whom their sensors showed.
    """

    time: float
    pose: F64
    scan: LidarReading
    range_max: float
    readings: Mapping[str, Any] = field(default_factory=dict)
    agents: AgentStates | None = None


@dataclass(frozen=True, eq=False)
class Perceived:
    """One tick of a detecting plugin, for the record and the pictures (world frame).

    Attributes:
        detections: ``(d, 2)`` this tick's detections (m).
        tracks: the confirmed tracks after this tick.
        seen: ``(n,)`` bool per ground-truth person (``Senses.agents`` order): the plugin's
            sensors showed them (at least :data:`LIDAR_SEEN_HITS` beams, or
            :data:`CAMERA_SEEN_FRACTION` of the frame's pixels); ``(0,)`` without agents.
    """

    detections: F64
    tracks: Tracks
    seen: NDArray[np.bool_]


@runtime_checkable
class PeoplePerception(Protocol):
    """Turns what the robot senses into the people its navigation stack sees."""

    Params: ClassVar[type[BaseModel]]
    last: Perceived | None
    """The latest tick's detections and tracks (``None`` for ``ground_truth``)."""

    def reset(self) -> None:
        """A new episode: forget everything (tracks, ids)."""
        ...

    def people(self, senses: Senses) -> Pedestrians:
        """The people at ``senses.time`` in the world frame."""
        ...


PERCEPTION: Registry[PeoplePerception] = Registry(
    "people perception", entry_points="arena.perception"
)
"""People perception plugins by ``navigation.perception.type``; built as ``cls(params,
robot)`` (the robot model: which sensors it carries)."""


class GroundTruthParams(BaseModel):
    """``navigation.perception`` of ``ground_truth``: no parameters."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["ground_truth"] = "ground_truth"


@PERCEPTION.register("ground_truth", tags=("default",))
class GroundTruthPeople:
    """The simulator's people as they are (positions, velocities, types, social states)."""

    Params = GroundTruthParams
    last: Perceived | None = None

    def __init__(self, params: GroundTruthParams | None = None, robot: Any = None) -> None:
        self.params = params or GroundTruthParams()

    def reset(self) -> None:
        """Nothing to forget."""

    def people(self, senses: Senses) -> Pedestrians:
        """The ground truth."""
        a = senses.agents
        if a is None:
            return Pedestrians()
        return Pedestrians(positions=a.positions, velocities=a.velocities, kinds=a.kinds,
                           states=a.states)


class LidarDetection(BaseModel):
    """The lidar detector's settings."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    min_score: float = Field(0.7, ge=0, le=1, description="segments scoring less are no people")
    merge_radius: float = Field(0.5, gt=0, description="m, segments closer are one person")


class RgbdDetection(BaseModel):
    """The RGB-D detector's settings."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    sensor: str = Field("camera", description="the robot's rgbd sensor to detect people in")
    pixel_score: float = Field(0.5, ge=0, le=1, description="pixels scoring less are no one's")
    min_score: float = Field(0.8, ge=0, le=1, description="people scoring less are dropped")
    merge_radius: float = Field(0.4, gt=0, description="m, blobs closer are one person")


def _tracker() -> TrackerParams:
    """The perception stage's tracker: a track is confirmed by 3 associated frames.

    With 2 (the tracker's own default), twice as many false tracks got through on the 3-D
    backend's furniture (measured in canteen and office episodes).
    """
    return TrackerParams(confirm_hits=3)


class LidarPeopleParams(LidarDetection):
    """``navigation.perception`` of ``lidar``."""

    type: Literal["lidar"] = "lidar"
    tracker: TrackerParams = Field(default_factory=_tracker)


class RgbdPeopleParams(RgbdDetection):
    """``navigation.perception`` of ``rgbd``."""

    type: Literal["rgbd"] = "rgbd"
    tracker: TrackerParams = Field(default_factory=_tracker)


class FusedPeopleParams(BaseModel):
    """``navigation.perception`` of ``fused``."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["fused"] = "fused"
    lidar: LidarDetection = Field(default_factory=LidarDetection)
    rgbd: RgbdDetection = Field(default_factory=RgbdDetection)
    fuse_radius: float = Field(0.5, gt=0, description="m, a lidar and a camera detection "
                               "closer than this are one person")
    tracker: TrackerParams = Field(default_factory=_tracker)


def camera_spec(robot: RobotModel | None, sensor: str, path: str) -> RgbdSpec:
    """The spec of ``robot``'s rgbd sensor ``sensor``, or a one-line :class:`ConfigError`."""
    if robot is None:
        raise ConfigError("camera people perception needs the robot model", path=path)
    spec = robot.sensors.get(sensor)
    if not isinstance(spec, RgbdSpec):
        cams = [n for n, s in robot.sensors.items() if isinstance(s, RgbdSpec)]
        raise ConfigError(
            f"robot {robot.name!r} has no rgbd sensor {sensor!r}; expected one of its cameras: "
            f"{', '.join(cams) if cams else 'none (add one under sensors:)'}", path=path)
    return spec


def check_perception(
    block: Mapping[str, Any] | str, robot: RobotModel, *, source: str | None = None,
    path: str = "navigation.perception",
) -> None:
    """Validate a perception block against ``robot`` (its camera exists): one-line errors."""
    _, params = PERCEPTION.validate(block, source=source, path=path)
    rgbd = getattr(params, "rgbd", params)
    if isinstance(rgbd, RgbdDetection):
        try:
            camera_spec(robot, rgbd.sensor, f"{path}.{'rgbd.' if rgbd is not params else ''}"
                        "sensor")
        except ConfigError as e:
            raise e.located(source=source) from None


def to_world(xy: F64, pose: F64, origin: Any = (0.0, 0.0)) -> F64:
    """Points ``(k, 2)`` of a frame at ``origin`` (base frame, no turn) on ``pose``: world."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    if not len(xy):
        return np.zeros((0, 2))
    c, s = np.cos(pose[2]), np.sin(pose[2])
    rot = np.array([[c, -s], [s, c]])
    return (xy + np.asarray(origin, dtype=np.float64)) @ rot.T + pose[:2]


def lidar_seen(senses: Senses) -> NDArray[np.bool_]:
    """``(n,)`` the scan shows each ground-truth person (:data:`LIDAR_SEEN_HITS` beams)."""
    a = senses.agents
    if a is None:
        return np.zeros(0, dtype=bool)
    scan = senses.scan
    r = np.asarray(scan.ranges, dtype=np.float64)
    ok = np.isfinite(r) & (r < senses.range_max)
    local = np.stack([r * np.cos(scan.angles), r * np.sin(scan.angles)], axis=1)[ok]
    hits = to_world(local, senses.pose, scan.origin)
    pos = np.asarray(a.positions, dtype=np.float64).reshape(-1, 2)
    if not len(hits) or not len(pos):
        return np.zeros(len(pos), dtype=bool)
    d = np.hypot(*(hits[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    counts = (d <= np.asarray(a.radii)[None, :] + 0.1).sum(axis=0)
    seen: NDArray[np.bool_] = counts >= LIDAR_SEEN_HITS
    return seen


def camera_seen(frame: RgbdFrame, n: int) -> NDArray[np.bool_]:
    """``(n,)`` the frame shows each person (:data:`CAMERA_SEEN_FRACTION` of its pixels)."""
    seen: NDArray[np.bool_] = frame.person_pixels(n) >= CAMERA_SEEN_FRACTION * frame.depth.size
    return seen


class _Detecting:
    """Shared by the detecting plugins: detections -> tracker -> people, and ``last``."""

    last: Perceived | None

    def __init__(self, tracker: TrackerParams) -> None:
        self.tracker = Tracker(tracker)
        self.last = None

    def reset(self) -> None:
        """Forget the tracks."""
        self.tracker.reset()
        self.last = None

    def _track(self, senses: Senses, world: F64, seen: NDArray[np.bool_]) -> Pedestrians:
        tracks = self.tracker.update(senses.time, world)
        self.last = Perceived(world, tracks, seen)
        return Pedestrians(positions=tracks.positions, velocities=tracks.velocities)


class _LidarPart:
    def __init__(self, p: LidarDetection) -> None:
        self.detector = LidarPeopleDetector(min_score=p.min_score, merge_radius=p.merge_radius)

    def detect(self, senses: Senses) -> F64:
        scan = senses.scan
        xy, _ = self.detector.detect(scan.ranges, scan.angles, senses.range_max)
        return to_world(xy, senses.pose, scan.origin)


class _CameraPart:
    def __init__(self, p: RgbdDetection, robot: RobotModel | None, path: str) -> None:
        from arena.perception.rgbd_detector import RgbdPeopleDetector

        self.sensor = p.sensor
        self.spec = camera_spec(robot, p.sensor, path)
        self.min_score = p.min_score
        self.detector = RgbdPeopleDetector(pixel_score=p.pixel_score,
                                           merge_radius=p.merge_radius)
        self._frame: RgbdFrame | None = None
        self._found = np.zeros((0, 2))

    def frame(self, senses: Senses) -> RgbdFrame:
        frame = senses.readings.get(self.sensor)
        if not isinstance(frame, RgbdFrame):
            raise ConfigError(f"no rgbd frame from sensor {self.sensor!r} (the camera needs the "
                              "mujoco backend)", path="navigation.perception")
        return frame

    def detect(self, senses: Senses) -> F64:
        frame = self.frame(senses)
        if frame is not self._frame:  # a camera holds its frame for 1 / update_rate s
            xy, score = self.detector.detect(frame, self.spec)
            self._frame, self._found = frame, xy[score >= self.min_score]
        return to_world(self._found, senses.pose)

    def seen(self, senses: Senses) -> NDArray[np.bool_]:
        n = 0 if senses.agents is None else len(senses.agents.positions)
        return camera_seen(self.frame(senses), n) if n else np.zeros(0, dtype=bool)


@PERCEPTION.register("lidar")
class LidarPeople(_Detecting):
    """People detected in the robot's scan and tracked (see the module docstring)."""

    Params = LidarPeopleParams

    def __init__(self, params: LidarPeopleParams | None = None, robot: Any = None) -> None:
        self.params = params or LidarPeopleParams()
        super().__init__(self.params.tracker)
        self.part = _LidarPart(self.params)

    def people(self, senses: Senses) -> Pedestrians:
        """Detect in the scan, move the detections to the world frame, track them."""
        return self._track(senses, self.part.detect(senses), lidar_seen(senses))


@PERCEPTION.register("rgbd")
class RgbdPeople(_Detecting):
    """People detected in the robot's RGB-D camera frames and tracked (module docstring)."""

    Params = RgbdPeopleParams

    def __init__(self, params: RgbdPeopleParams | None = None,
                 robot: RobotModel | None = None) -> None:
        self.params = params or RgbdPeopleParams()
        super().__init__(self.params.tracker)
        self.part = _CameraPart(self.params, robot, "navigation.perception.sensor")

    def people(self, senses: Senses) -> Pedestrians:
        """Detect in the camera's frame, move the detections to the world frame, track them."""
        return self._track(senses, self.part.detect(senses), self.part.seen(senses))


@PERCEPTION.register("fused")
class FusedPeople(_Detecting):
    """People from the lidar and the RGB-D camera together (see the module docstring)."""

    Params = FusedPeopleParams

    def __init__(self, params: FusedPeopleParams | None = None,
                 robot: RobotModel | None = None) -> None:
        self.params = params or FusedPeopleParams()
        super().__init__(self.params.tracker)
        self.lidar = _LidarPart(self.params.lidar)
        self.camera = _CameraPart(self.params.rgbd, robot, "navigation.perception.rgbd.sensor")

    def people(self, senses: Senses) -> Pedestrians:
        """Both detectors' people, a camera detection near a lidar one dropped; tracked."""
        lid, cam = self.lidar.detect(senses), self.camera.detect(senses)
        if len(lid) and len(cam):
            d = np.hypot(*(cam[:, None, :] - lid[None, :, :]).transpose(2, 0, 1))
            cam = cam[d.min(axis=1) > self.params.fuse_radius]
        seen = lidar_seen(senses)
        if seen.size:
            seen = seen | self.camera.seen(senses)
        return self._track(senses, np.concatenate([lid, cam]), seen)
