"""The recorded episode: every simulation step of the robot and the people, as arrays.

One :class:`EpisodeRecord` per episode and robot is what the recorder writes, what the metrics
read (pure functions of a record) and what the results store keeps. Robot data is one row per
step (``T`` rows, step 0 = the state after reset); pedestrian data is in long format (one row
per pedestrian and step, ``K`` rows) so that crowds of any size fit one table.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True, eq=False)
class EpisodeMeta:
    """What the episode was and how it ended.

    Attributes:
        episode: episode index in its run.
        seed: the episode's seed.
        stage: benchmark or curriculum stage label ("" if none).
        map_name: map label.
        robot: robot model name.
        robot_radius: m, radius of the robot's bounding circle.
        start, goal: ``(3,)`` ``[x m, y m, theta rad]``.
        goal_radius: m; goal_tolerance_angle: rad or ``None`` (heading ignored).
        time_limit: s.
        dt: s, simulation step.
        outcome: an :class:`~arena.core.types.Outcome` value ("success", "timeout", ...).
        config: the resolved experiment config (plain data) the episode ran with.
    """

    episode: int
    seed: int
    stage: str
    map_name: str
    robot: str
    robot_radius: float
    start: FloatArray
    goal: FloatArray
    goal_radius: float
    goal_tolerance_angle: float | None
    time_limit: float
    dt: float
    outcome: str
    config: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class PerceptionRecord:
    """What a detecting perception plugin (``navigation.perception``) saw, per robot row.

    Attributes:
        perceived: ``(T,)`` bool, the plugin ran on this row's state (a control tick).
        seen: ``(K,)`` bool per pedestrian row: the plugin's sensors showed this person
            (:class:`~arena.perception.stage.Perceived`); the tracking metrics score only them.
        trk_row: ``(M,)`` robot row of each confirmed track (long format, like the people).
        trk_id: ``(M,)`` track id.
        trk_position: ``(M, 2)`` m, world frame.
        det_row: ``(D,)`` robot row of each detection; det_position: ``(D, 2)`` m.
    """

    perceived: BoolArray
    seen: BoolArray
    trk_row: IntArray
    trk_id: IntArray
    trk_position: FloatArray
    det_row: IntArray
    det_position: FloatArray

    def check(self, steps: int, ped_rows: int) -> None:
        """Raise ``ValueError`` unless the shapes fit ``steps`` robot, ``ped_rows`` people rows."""
        if self.perceived.shape != (steps,) or self.seen.shape != (ped_rows,):
            raise ValueError("PerceptionRecord.perceived / seen must have the record's rows")
        for row, pos, name in ((self.trk_row, self.trk_position, "trk"),
                               (self.det_row, self.det_position, "det")):
            if pos.shape != (row.shape[0], 2):
                raise ValueError(f"PerceptionRecord.{name}_position must have shape (n, 2)")
            if row.size and (row.min() < 0 or row.max() >= steps):
                raise ValueError(f"PerceptionRecord.{name}_row must index the robot rows")


@dataclass(frozen=True, eq=False)
class EpisodeRecord:
    """Every step of one episode (struct of arrays).

    Robot, ``T`` rows:
        time: ``(T,)`` s since reset.
        pose: ``(T, 3)`` ``[x m, y m, theta rad]``, world frame.
        velocity: ``(T, 3)`` body twist ``[vx m/s, vy m/s, omega rad/s]`` (measured).
        command: ``(T, 3)`` the command applied during the step that ended at this row
            (row 0: zeros).
        min_range: ``(T,)`` m, smallest laser range (``inf`` without returns).
        collision_wall, collision_obstacle, collision_pedestrian, collision_robot: ``(T,)``
            bool, the robot touches a wall / obstacle / pedestrian / other robot at this row.

    Pedestrians, ``K`` rows (long format):
        ped_row: ``(K,)`` index into the robot rows (the step).
        ped_id: ``(K,)`` stable pedestrian id.
        ped_kind: ``(K,)`` 0 adult, 1 elder, 2 child.
        ped_state: ``(K,)`` social state code (:class:`~arena.crowd.state.SocialState`).
        ped_position: ``(K, 2)`` m; ped_velocity: ``(K, 2)`` m/s; ped_heading: ``(K,)`` rad.
        ped_radius: ``(K,)`` m.

    Counterfactual (optional): ``ped_cf_position`` ``(K, 2)`` m, where each pedestrian row's
    person would have been at that step had there been no robot
    (:mod:`arena.eval.counterfactual`); NaN where the replay has no such person, ``None`` when
    no replay was made.

    Perception (optional): ``perception``, a :class:`PerceptionRecord` when the navigation stack
    planned on detected people (``None`` for the ground truth).

    Events: ``events`` is a list of ``(time s, kind, detail)``, e.g. ``(12.3, "goal_reached",
    "")``, ``(4.0, "teleport", "robot 0")``.
    """

    meta: EpisodeMeta
    time: FloatArray
    pose: FloatArray
    velocity: FloatArray
    command: FloatArray
    min_range: FloatArray
    collision_wall: BoolArray
    collision_obstacle: BoolArray
    collision_pedestrian: BoolArray
    collision_robot: BoolArray
    ped_row: IntArray
    ped_id: IntArray
    ped_kind: IntArray
    ped_state: IntArray
    ped_position: FloatArray
    ped_velocity: FloatArray
    ped_heading: FloatArray
    ped_radius: FloatArray
    events: list[tuple[float, str, str]] = field(default_factory=list)
    ped_cf_position: FloatArray | None = None
    perception: PerceptionRecord | None = None

    def __post_init__(self) -> None:
        t = self.time.shape[0]
        for name in ("pose", "velocity", "command"):
            if getattr(self, name).shape != (t, 3):
                raise ValueError(f"EpisodeRecord.{name} must have shape ({t}, 3)")
        for name in ("min_range", "collision_wall", "collision_obstacle",
                     "collision_pedestrian", "collision_robot"):
            if getattr(self, name).shape != (t,):
                raise ValueError(f"EpisodeRecord.{name} must have shape ({t},)")
        k = self.ped_row.shape[0]
        for name in ("ped_id", "ped_kind", "ped_state", "ped_heading", "ped_radius"):
            if getattr(self, name).shape != (k,):
                raise ValueError(f"EpisodeRecord.{name} must have shape ({k},)")
        for name in ("ped_position", "ped_velocity", "ped_cf_position"):
            value = getattr(self, name)
            if value is not None and value.shape != (k, 2):
                raise ValueError(f"EpisodeRecord.{name} must have shape ({k}, 2)")
        if k and (self.ped_row.min() < 0 or self.ped_row.max() >= t):
            raise ValueError("EpisodeRecord.ped_row must index the robot rows")
        if self.perception is not None:
            self.perception.check(t, k)

    @property
    def steps(self) -> int:
        """Number of robot rows ``T``."""
        return int(self.time.shape[0])

    @property
    def collision(self) -> BoolArray:
        """``(T,)`` the robot touches anything."""
        return (
            self.collision_wall
            | self.collision_obstacle
            | self.collision_pedestrian
            | self.collision_robot
        )

    def pedestrians_at(self, row: int) -> IntArray:
        """Indices into the pedestrian rows that belong to robot row ``row``."""
        return np.flatnonzero(self.ped_row == row)
