"""The navigation pipeline: a global planner feeding a local planner.

Data flow per episode: :meth:`NavigationStack.reset` inflates the static map once by
``robot_radius + inflation_margin`` and plans a global path; every control tick
:meth:`NavigationStack.step` checks the goal, replans when due, and asks the local planner for a
body-frame command. An intermediate planner (:mod:`arena.nav.intermediate`) sits between the two:
every ``intermediate_period`` seconds it sees the global path and the pedestrians (passed to
:meth:`NavigationStack.step`) and returns the path the local planner follows plus parameter
overrides (e.g. ``max_speed``). The default ``bypass`` leaves both untouched.

Policies (documented here because tasks and metrics depend on them):

- **Start inside the inflated zone.** A robot that got closer to a wall than the inflation radius
  has its own cell occupied in the inflated map. Rather than failing, the stack plans from the
  nearest free cell of the inflated map and prepends the robot's position, provided the straight
  segment from the robot to that cell crosses no occupied cell of the *uninflated* map. Only a
  robot whose position is blocked in the raw map (or walled off from free space) fails with
  :class:`~arena.core.errors.StartOccupied`.
- **Goal inside the inflated zone** fails with :class:`~arena.core.errors.GoalOccupied`: goals
  must be sampled with at least ``robot_radius + inflation_margin`` of clearance.
- **Failures.** If the plan made by :meth:`~NavigationStack.reset` fails, :attr:`status` becomes
  ``FAILED``, the typed error is kept in :attr:`last_error` and raised (never a ``None`` path);
  :meth:`~NavigationStack.step` then only brakes. A later replan that fails keeps the previous
  path (the static map has not changed, so the old path is still valid), records the error in
  :attr:`last_error` and retries after ``max(replan_period, 1 s)``.
- **Replanning** happens every ``replan_period`` seconds (0 = never) and whenever the robot is
  more than ``max_path_deviation`` from the path (pushed by a pedestrian, say).
- **Goal reached** when within ``goal_tolerance_xy`` and, if ``goal_tolerance_yaw`` is set, with
  the heading within it too; the stack then passes the tolerance to the local planner
  (``LocalObservation.goal_yaw_tolerance``), and planners that can turn on the spot (pure
  pursuit) align the heading at the goal. Car-like (Ackermann) robots cannot turn on the spot:
  they reach a goal heading only if the approach happens to end with it. The status then stays
  ``GOAL_REACHED``.
- **Parameter overrides** from the intermediate planner apply to the local planner when it has a
  pydantic ``params`` model with a field of that name (pure pursuit: ``max_speed``), else an
  attribute of that name; other keys are ignored. Each output replaces the previous overrides
  (values not overridden return to the configured ones); :meth:`NavigationStack.reset` restores
  the configured parameters.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator
from scipy import ndimage

from arena.core.errors import ConfigError, PlanningError, StartOccupied, from_validation_error
from arena.core.geometry import point_segment_distance
from arena.core.types import Pose2D, wrap_angle_scalar
from arena.maps.grid import OccupancyGrid
from arena.nav.global_planners import GLOBAL_PLANNERS, GlobalPlanner, segment_is_free
from arena.nav.intermediate import (
    INTERMEDIATE_PLANNERS,
    IntermediateInput,
    IntermediatePlanner,
    Pedestrians,
)
from arena.nav.local_planners import (
    LOCAL_PLANNERS,
    LocalObservation,
    LocalPlanner,
    limit_command,
)


class NavStatus(enum.StrEnum):
    """Where a navigation run stands. Values are stable strings."""

    ACTIVE = "active"
    """Following a path toward the goal."""
    GOAL_REACHED = "goal_reached"
    """Within the goal tolerances; commands only brake."""
    FAILED = "failed"
    """The initial plan failed; the typed error is in :attr:`NavigationStack.last_error`."""


def _planner_block(value: Any) -> Any:
    """Normalise the shorthand ``"name"`` to ``{"type": "name"}``."""
    return {"type": value} if isinstance(value, str) else value


class NavigationConfig(BaseModel):
    """The ``navigation`` block of an experiment: which planners, and the stack's policies."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    global_planner: dict[str, Any] = Field(
        default_factory=lambda: {"type": "astar"},
        description="global planner block {type: name, **params}",
    )
    local_planner: dict[str, Any] = Field(
        default_factory=lambda: {"type": "pure_pursuit"},
        description="local planner block {type: name, **params}",
    )
    intermediate_planner: dict[str, Any] = Field(
        default_factory=lambda: {"type": "bypass"},
        description="intermediate planner block {type: name, **params}",
    )
    intermediate_period: float = Field(
        0.0, ge=0, description="s between intermediate-planner calls; 0 = every control tick"
    )
    intermediate_window: float = Field(
        5.0, gt=0, description="m, radius of the local window given to the intermediate planner"
    )
    replan_period: float = Field(1.0, ge=0, description="s between global replans; 0 = never")
    inflation_margin: float = Field(
        0.05, ge=0, description="m of clearance added to the robot radius when inflating the map"
    )
    goal_tolerance_xy: float = Field(0.3, gt=0, description="m, distance that counts as arrived")
    goal_tolerance_yaw: float | None = Field(
        None, gt=0, description="rad, heading error that counts as arrived; None ignores heading"
    )
    max_path_deviation: float = Field(
        0.5, gt=0, description="m from the path beyond which the stack replans at once"
    )

    # The planner blocks are checked against their registries where the file and key path are
    # known (the experiment loader, :meth:`NavigationStack.from_config`), not here: a pydantic
    # error would lose the UnknownNameError type and the exact key path inside the block.
    @field_validator("global_planner", "local_planner", "intermediate_planner", mode="before")
    @classmethod
    def _shorthand(cls, v: Any) -> Any:
        return _planner_block(v)


_DEFAULTS = NavigationConfig()


class NavigationStack:
    """Global planner + local planner with replanning and goal checking, for one robot.

    Args:
        global_planner: plans on the inflated map.
        local_planner: turns the path into commands.
        robot_radius: radius of the robot's bounding circle (m).
        inflation_margin: clearance added to ``robot_radius`` when inflating the map (m).
        replan_period: seconds between replans; 0 plans only at reset (and on deviation).
        goal_tolerance: ``(xy m, yaw rad or None)``; ``None`` ignores the heading.
        max_path_deviation: distance from the path (m) that triggers an immediate replan.
        kinematics: the robot's kinematics name; checked against the local planner's
            ``supports`` and passed on in every observation. ``None`` lets the planner infer it.
        intermediate_planner: refines the path between the two; ``None`` = ``bypass``.
        intermediate_period: seconds between intermediate-planner calls; 0 = every tick.
        intermediate_window: radius (m) of the local window given to the intermediate planner.

    Raises:
        ConfigError: the local planner cannot drive ``kinematics``, or an argument is invalid.
    """

    def __init__(
        self,
        global_planner: GlobalPlanner,
        local_planner: LocalPlanner,
        *,
        robot_radius: float,
        inflation_margin: float = _DEFAULTS.inflation_margin,
        replan_period: float = _DEFAULTS.replan_period,
        goal_tolerance: tuple[float, float | None] = (
            _DEFAULTS.goal_tolerance_xy,
            _DEFAULTS.goal_tolerance_yaw,
        ),
        max_path_deviation: float = _DEFAULTS.max_path_deviation,
        kinematics: str | None = None,
        intermediate_planner: IntermediatePlanner | None = None,
        intermediate_period: float = _DEFAULTS.intermediate_period,
        intermediate_window: float = _DEFAULTS.intermediate_window,
    ) -> None:
        if not robot_radius > 0:
            raise ConfigError(f"robot_radius must be > 0 m, got {robot_radius}")
        if inflation_margin < 0 or replan_period < 0 or not max_path_deviation > 0:
            raise ConfigError(
                "inflation_margin and replan_period must be >= 0 and max_path_deviation > 0, got "
                f"{inflation_margin}, {replan_period}, {max_path_deviation}"
            )
        if intermediate_period < 0 or not intermediate_window > 0:
            raise ConfigError(
                "intermediate_period must be >= 0 and intermediate_window > 0, got "
                f"{intermediate_period}, {intermediate_window}"
            )
        supports = getattr(local_planner, "supports", frozenset())
        if kinematics is not None and kinematics not in supports:
            raise ConfigError(
                f"local planner {type(local_planner).__name__} cannot drive {kinematics!r} robots "
                f"(supports: {', '.join(sorted(supports)) or 'none'})"
            )
        self.global_planner = global_planner
        self.local_planner = local_planner
        self.robot_radius = float(robot_radius)
        self.inflation_margin = float(inflation_margin)
        self.replan_period = float(replan_period)
        self.goal_tolerance_xy = float(goal_tolerance[0])
        self.goal_tolerance_yaw = None if goal_tolerance[1] is None else float(goal_tolerance[1])
        self.max_path_deviation = float(max_path_deviation)
        self.kinematics = kinematics
        self.grid: OccupancyGrid | None = None
        self.inflated: OccupancyGrid | None = None
        self.goal = Pose2D()
        self.status = NavStatus.FAILED
        self.last_error: PlanningError | None = None
        self.replans = 0
        self._path = np.zeros((0, 2))
        self._nearest_free: NDArray[np.int64] | None = None
        self._time = 0.0
        self._last_plan_time = 0.0
        self._retry_after = -math.inf
        self.intermediate_planner: IntermediatePlanner = (
            intermediate_planner
            if intermediate_planner is not None
            else INTERMEDIATE_PLANNERS.build("bypass")
        )
        self.intermediate_period = float(intermediate_period)
        self.intermediate_window = float(intermediate_window)
        self.overrides: dict[str, float] = {}
        self._base_params = getattr(local_planner, "params", None)
        self._base_attrs: dict[str, Any] = {}
        self._inter_path: NDArray[np.float64] | None = None
        self._inter_time = -math.inf

    @classmethod
    def from_config(
        cls,
        cfg: NavigationConfig | Mapping[str, Any] | None,
        robot_radius: float,
        source: str | None = None,
        *,
        kinematics: str | None = None,
        path: str | None = "navigation",
    ) -> NavigationStack:
        """Build both planners through their registries from a ``navigation`` block.

        Args:
            cfg: the block (a model, a plain mapping, or ``None`` for all defaults).
            robot_radius: radius of the robot's bounding circle (m).
            source: file the block came from, for error messages.
            kinematics: the robot's kinematics name (checked against the local planner).
            path: key path of the block inside ``source``, for error messages.

        Raises:
            ConfigError: naming ``source`` and the key path when the block is invalid.
        """
        sub = (lambda key: f"{path}.{key}") if path else (lambda key: key)
        if cfg is None:
            cfg = _DEFAULTS
        elif not isinstance(cfg, NavigationConfig):
            raw = dict(cfg)
            # Check the planner blocks through their registries first: their errors keep their
            # type (UnknownNameError with a close match) and the exact key path.
            blocks: tuple[tuple[str, Any], ...] = (
                ("global_planner", GLOBAL_PLANNERS),
                ("local_planner", LOCAL_PLANNERS),
                ("intermediate_planner", INTERMEDIATE_PLANNERS),
            )
            for key, registry in blocks:
                if key in raw:
                    spec = raw[key]
                    registry.validate(
                        {"type": spec} if isinstance(spec, str) else spec,
                        source=source, path=sub(key),
                    )
            try:
                cfg = NavigationConfig.model_validate(raw)
            except ValidationError as e:
                raise from_validation_error(e, source=source, prefix=path) from None
        gp = GLOBAL_PLANNERS.build(cfg.global_planner, source=source, path=sub("global_planner"))
        lp = LOCAL_PLANNERS.build(cfg.local_planner, source=source, path=sub("local_planner"))
        ip = INTERMEDIATE_PLANNERS.build(
            cfg.intermediate_planner, source=source, path=sub("intermediate_planner")
        )
        try:
            return cls(
                gp, lp, robot_radius=robot_radius, inflation_margin=cfg.inflation_margin,
                replan_period=cfg.replan_period,
                goal_tolerance=(cfg.goal_tolerance_xy, cfg.goal_tolerance_yaw),
                max_path_deviation=cfg.max_path_deviation, kinematics=kinematics,
                intermediate_planner=ip, intermediate_period=cfg.intermediate_period,
                intermediate_window=cfg.intermediate_window,
            )
        except ConfigError as e:
            raise e.located(source=source, prefix=path) from None

    # -- state ----------------------------------------------------------------------------------
    @property
    def path(self) -> NDArray[np.float64]:
        """The current global path ``(k, 2)`` (m, world frame; read-only); ``(0, 2)`` if none."""
        return self._path

    @property
    def time(self) -> float:
        """``obs.time`` of the last :meth:`step`, or the reset time (s)."""
        return self._time

    def goal_reached(self, pose: Pose2D | ArrayLike) -> bool:
        """Whether ``pose`` satisfies the goal tolerances (position, and heading if set)."""
        p = pose if isinstance(pose, Pose2D) else Pose2D.from_array(np.asarray(pose).reshape(-1))
        if p.distance_to(self.goal) > self.goal_tolerance_xy:
            return False
        if self.goal_tolerance_yaw is None:
            return True
        return abs(wrap_angle_scalar(p.theta - self.goal.theta)) <= self.goal_tolerance_yaw

    def cross_track_error(self, xy: ArrayLike) -> float:
        """Distance (m) from the point ``(2,)`` to the current path (``inf`` without a path)."""
        path = self._path
        if len(path) == 0:
            return math.inf
        if len(path) == 1:
            return float(np.hypot(*(np.asarray(xy, dtype=np.float64) - path[0])))
        return float(np.min(point_segment_distance(np.asarray(xy)[None, :2], path[:-1], path[1:])))

    # -- episode --------------------------------------------------------------------------------
    def reset(
        self, grid: OccupancyGrid, start: Pose2D, goal: Pose2D, *, time: float = 0.0
    ) -> NavStatus:
        """Start a new run: inflate ``grid`` once, plan from ``start`` to ``goal``.

        Args:
            grid: the static map (uninflated).
            start: the robot's pose (m, rad).
            goal: the goal pose (m, rad).
            time: simulation time of the reset (s).

        Returns:
            The new :attr:`status`, ``ACTIVE``.

        Raises:
            StartOccupied: the robot cannot get out of the inflated zone (see module docstring).
            GoalOccupied: the goal lies in the inflated zone or off the map.
            NoPathFound: the goal is not reachable. Before any of these propagates,
                :attr:`status` is set to ``FAILED`` and the error kept in :attr:`last_error`, so
                a caller that catches it can still :meth:`step` (which then only brakes).
        """
        if grid is not self.grid or self.inflated is None:
            # Grids are immutable, so episodes on the same map share one inflation (an EDT).
            self.inflated = grid.inflate(self.robot_radius + self.inflation_margin)
            self._nearest_free = None
        self.grid = grid
        self.goal = goal
        self.local_planner.reset()
        self.intermediate_planner.reset()
        self._apply_overrides({})
        self._inter_path = None
        self._inter_time = -math.inf
        self._path = np.zeros((0, 2))
        self._path.setflags(write=False)
        self._time = float(time)
        self._retry_after = -math.inf
        self.replans = 0
        self.last_error = None
        try:
            self._set_path(self._plan_from(start))
        except PlanningError as e:
            self.last_error = e
            self.status = NavStatus.FAILED
            raise
        self.status = NavStatus.ACTIVE
        return self.status

    def replan(self, pose: Pose2D) -> bool:
        """Plan again from ``pose``; on failure keep the old path and record :attr:`last_error`.

        Returns:
            Whether a new path was set.
        """
        self._require_reset()
        self.replans += 1
        try:
            self._set_path(self._plan_from(pose))
        except PlanningError as e:
            self.last_error = e
            self._last_plan_time = self._time
            self._retry_after = self._time + max(self.replan_period, 1.0)
            return False
        return True

    def step(
        self, obs: LocalObservation, pedestrians: Pedestrians | None = None
    ) -> NDArray[np.float64]:
        """One control tick: check the goal, replan if due, return the local planner's command.

        Args:
            obs: the robot's observation this tick. Its ``path`` and ``goal`` are replaced by the
                stack's own (the caller may pass :attr:`path` or an empty array); ``kinematics``
                falls back to the stack's when ``None``. ``obs.time`` (s) drives the replanning
                period, so it must advance.
            pedestrians: pedestrians around the robot (world frame), for the intermediate
                planner; ``None`` means none known.

        Returns:
            ``(3,)`` body twist command ``[vx, vy, omega]``; a braking command (zero within the
            acceleration limits) once the goal is reached or when the initial plan failed.
        """
        self._require_reset()
        q = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        v = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        self._time = float(obs.time)
        if self.status is NavStatus.ACTIVE and self.goal_reached(Pose2D.from_array(q)):
            self.status = NavStatus.GOAL_REACHED
        if self.status is not NavStatus.ACTIVE:
            return limit_command(np.zeros(3), v, obs.limits, obs.dt)

        due = self.replan_period > 0 and self._time - self._last_plan_time >= self.replan_period
        strayed = (
            self._time >= self._retry_after
            and self.cross_track_error(q[:2]) > self.max_path_deviation
        )
        if due or strayed:
            self.replan(Pose2D.from_array(q))

        path = self._intermediate(obs, q, v, pedestrians)
        local_obs = dataclasses.replace(
            obs, path=path, goal=self.goal,
            kinematics=obs.kinematics if obs.kinematics is not None else self.kinematics,
            goal_yaw_tolerance=(
                obs.goal_yaw_tolerance
                if obs.goal_yaw_tolerance is not None
                else self.goal_tolerance_yaw
            ),
        )
        return np.asarray(self.local_planner.compute(local_obs), dtype=np.float64).reshape(3)

    @property
    def intermediate_path(self) -> NDArray[np.float64]:
        """The path the local planner followed at the last :meth:`step` (m, ``(m, 2)``)."""
        return self._inter_path if self._inter_path is not None else self._path

    # -- internals ------------------------------------------------------------------------------
    def _base_speed(self, obs: LocalObservation) -> float:
        """The local planner's configured cruise speed (m/s): its ``max_speed`` or ``vx_max``."""
        configured = getattr(self._base_params, "max_speed", None)
        if configured is None:
            current = getattr(self.local_planner, "max_speed", None)
            configured = self._base_attrs.get("max_speed", current)
        vmax = float(obs.limits.vx_max)
        return min(vmax, float(configured)) if isinstance(configured, int | float) else vmax

    def _intermediate(
        self,
        obs: LocalObservation,
        q: NDArray[np.float64],
        v: NDArray[np.float64],
        pedestrians: Pedestrians | None,
    ) -> NDArray[np.float64]:
        """Call the intermediate planner when due; return the path for the local planner."""
        due = self._inter_path is None or (
            self._time - self._inter_time >= self.intermediate_period - 1e-9
        )
        if not due:
            assert self._inter_path is not None
            return self._inter_path
        points = obs.scan_points() if np.size(obs.scan_ranges) else np.zeros((0, 2))
        if len(points):
            c, s = math.cos(q[2]), math.sin(q[2])
            points = points @ np.array([[c, s], [-s, c]]) + q[:2]
        inp = IntermediateInput(
            pose=q, twist=v, path=self._path, goal=self.goal.as_array(),
            max_speed=self._base_speed(obs), robot_radius=self.robot_radius,
            pedestrians=pedestrians if pedestrians is not None else Pedestrians(),
            obstacle_points=points, window=self.intermediate_window, time=self._time,
        )
        out = self.intermediate_planner.plan(inp)
        if out.path is self._path:
            path = self._path
        else:
            path = np.array(out.path, dtype=np.float64).reshape(-1, 2)
            path.setflags(write=False)
        self._apply_overrides(dict(out.overrides))
        self._inter_path = path
        self._inter_time = self._time
        return path

    def _apply_overrides(self, overrides: dict[str, float]) -> None:
        """Set the local planner's parameters to the configured ones updated by ``overrides``."""
        if overrides == self.overrides:
            return
        lp = self.local_planner
        base = self._base_params
        fields = type(base).model_fields if isinstance(base, BaseModel) else {}
        in_params = {k: val for k, val in overrides.items() if k in fields}
        if isinstance(base, BaseModel):
            new = base.model_copy(update=in_params) if in_params else base
            lp.params = new  # type: ignore[attr-defined]
        for k in list(self._base_attrs):
            if k not in overrides:
                setattr(lp, k, self._base_attrs.pop(k))
        for k, val in overrides.items():
            if k not in fields and hasattr(lp, k) and not callable(getattr(lp, k)):
                self._base_attrs.setdefault(k, getattr(lp, k))
                setattr(lp, k, val)
        self.overrides = dict(overrides)

    def _require_reset(self) -> None:
        if self.inflated is None:
            raise RuntimeError("NavigationStack.reset(grid, start, goal) must be called first")

    def _set_path(self, path: NDArray[np.float64]) -> None:
        p = np.array(path, dtype=np.float64).reshape(-1, 2)
        p.setflags(write=False)
        self._path = p
        self._last_plan_time = self._time
        self._retry_after = -math.inf

    def _plan_from(self, start: Pose2D) -> NDArray[np.float64]:
        assert self.inflated is not None
        assert self.grid is not None
        try:
            return self.global_planner.plan(self.inflated, start, self.goal)
        except StartOccupied:
            free = self._free_cell_near(start)
            if free is None:
                raise
        via = Pose2D(float(free[0]), float(free[1]), start.theta)
        path = self.global_planner.plan(self.inflated, via, self.goal)
        return np.vstack([start.xy[None, :], path])

    def _free_cell_near(self, start: Pose2D) -> NDArray[np.float64] | None:
        """Centre (m) of the inflated map's free cell nearest to ``start``, if safely reachable."""
        assert self.inflated is not None
        assert self.grid is not None
        cell = self.inflated.world_to_cell(start.xy)
        blocked = self.inflated.occupied
        if not bool(self.inflated.in_bounds(cell)) or bool(blocked.all()):
            return None
        if self._nearest_free is None:
            # One EDT with indices gives every cell's nearest free cell; computed on first need.
            _, idx = ndimage.distance_transform_edt(blocked, return_indices=True)
            self._nearest_free = idx
        r, c = int(cell[0]), int(cell[1])
        free_cell = self._nearest_free[:, r, c]
        centre = self.inflated.cell_to_world(free_cell)
        if not segment_is_free(self.grid, start.xy, centre):
            return None
        return centre
