"""Where the navigation stack's people come from: ``navigation.perception: {type: ...}``.

Every planner and intermediate planner that uses people reads them from one
:class:`~arena.nav.intermediate.base.Pedestrians` per control tick (the local planner through
``LocalObservation.pedestrians``, the costmaps' semantic layer, the intermediate planner).
A perception plugin (registry :data:`PERCEPTION`) makes it:

* ``ground_truth`` (the default): the simulator's people, with their types and social states;
* ``lidar``: the robot's own scan (the stack's ``scan_sensor``) through the
  :class:`~arena.perception.lidar_detector.LidarPeopleDetector` and the
  :class:`~arena.perception.tracker.Tracker`: confirmed tracks with their estimated positions
  and velocities; types and social states are unknown (empty), since a scan does not show them.
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.registry import Registry
from arena.nav.intermediate.base import Pedestrians
from arena.perception.lidar_detector import LidarPeopleDetector
from arena.perception.tracker import Tracker, TrackerParams
from arena.scene.state import AgentStates
from arena.sensors.spec import LidarReading

F64 = NDArray[np.float64]


@runtime_checkable
class PeoplePerception(Protocol):
    """Turns what the robot senses into the people its navigation stack sees."""

    Params: ClassVar[type[BaseModel]]

    def reset(self) -> None:
        """A new episode: forget everything (tracks, ids)."""
        ...

    def people(
        self, time: float, pose: F64, scan: LidarReading, range_max: float, agents: AgentStates
    ) -> Pedestrians:
        """The people at ``time`` (s) for a robot at ``pose`` ``[x, y, θ]`` (world frame).

        ``scan`` is the stack's lidar reading (robot frame geometry), ``range_max`` its
        sensor's range (m, a beam reading it returned nothing); ``agents`` the simulator's
        ground truth, which only ``ground_truth`` may read.
        """
        ...


PERCEPTION: Registry[PeoplePerception] = Registry(
    "people perception", entry_points="arena.perception"
)
"""People perception plugins by ``navigation.perception.type``."""


class GroundTruthParams(BaseModel):
    """``navigation.perception`` of ``ground_truth``: no parameters."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["ground_truth"] = "ground_truth"


@PERCEPTION.register("ground_truth", tags=("default",))
class GroundTruthPeople:
    """The simulator's people as they are (positions, velocities, types, social states)."""

    Params = GroundTruthParams

    def __init__(self, params: GroundTruthParams | None = None) -> None:
        self.params = params or GroundTruthParams()

    def reset(self) -> None:
        """Nothing to forget."""

    def people(
        self, time: float, pose: F64, scan: LidarReading, range_max: float, agents: AgentStates
    ) -> Pedestrians:
        """The ground truth."""
        return Pedestrians(positions=agents.positions, velocities=agents.velocities,
                           kinds=agents.kinds, states=agents.states)


class LidarPeopleParams(BaseModel):
    """``navigation.perception`` of ``lidar``."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["lidar"] = "lidar"
    min_score: float = Field(0.5, ge=0, le=1, description="segments scoring less are no people")
    merge_radius: float = Field(0.5, gt=0, description="m, segments closer are one person")
    tracker: TrackerParams = Field(default_factory=TrackerParams)


@PERCEPTION.register("lidar")
class LidarPeople:
    """People detected in the robot's scan and tracked (see the module docstring)."""

    Params = LidarPeopleParams

    def __init__(self, params: LidarPeopleParams | None = None) -> None:
        self.params = params or LidarPeopleParams()
        self.detector = LidarPeopleDetector(min_score=self.params.min_score,
                                            merge_radius=self.params.merge_radius)
        self.tracker = Tracker(self.params.tracker)

    def reset(self) -> None:
        """Forget the tracks."""
        self.tracker.reset()

    def people(
        self, time: float, pose: F64, scan: LidarReading, range_max: float, agents: Any
    ) -> Pedestrians:
        """Detect in ``scan``, move the detections to the world frame, track them."""
        xy, _ = self.detector.detect(scan.ranges, scan.angles, range_max)
        c, s = np.cos(pose[2]), np.sin(pose[2])
        rot = np.array([[c, -s], [s, c]])
        world = (xy + np.asarray(scan.origin, dtype=np.float64)) @ rot.T + pose[:2] if len(
            xy) else np.zeros((0, 2))
        tracks = self.tracker.update(time, world)
        return Pedestrians(positions=tracks.positions, velocities=tracks.velocities)
