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
- **Narrow passages.** The map is inflated by the robot's bounding circle (``robot_radius +
  inflation_margin``), which closes doors the robot fits through sideways-on: a jackal (0.267 m
  circle, 0.33 m wide) and Arena's 0.6 m doors. Where that map has no route (or the start or
  goal lies in its inflated zone), the stack plans on the map inflated by the footprint's
  inscribed radius instead (``footprint_radius + inflation_margin``): like a ROS costmap's
  lethal zone, cells where the footprint collides in every heading. :attr:`footprint_plan`
  says which one the path came from. Routes the circle fits through are always preferred, even
  when longer. (Not with a global costmap, which plans on its own inscribed radius.)
- **Coarse maps** are planned on their cells split to at most ``planning_resolution`` (0.1 m):
  distances are measured centre to centre, so on Arena's 0.4–0.5 m maps an inflation below one
  cell marked nothing and plans passed 0.25 m from walls, closer than the robot's radius.
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

move_base_flex-like features (all opt-in; with the defaults the stack behaves as before):

- **Rates.** The global planner runs at reset, every ``replan_period`` s, on deviation, and at
  once when the path ahead is blocked (``replan_on_blocked``); the intermediate planner every
  ``intermediate_period`` s; the local planner every control tick (``step``).
- **Global costmap** (``navigation.global_costmap: {...}``). The global plan is made on a
  :class:`~arena.nav.costmap.GlobalCostmap` of the static map, inflated with inscribed radius
  ``robot_radius + inflation_margin`` (its lethal/inscribed cells are exactly the inflated map's
  occupied cells) and a decaying cost out to ``inflation_radius``. With ``cost_weight > 0`` the
  cost-aware search :func:`~arena.nav.global_planners.plan_on_costmap` plans (keeping clear of
  walls); with 0 the configured global planner plans on the lethal cells. ``use_scan: true``
  folds every scan into its obstacle layer (marks persist until raytraced free or cleared).
- **Local costmap** (``navigation.local_costmap: {...}``): a rolling window updated every tick
  from the scan (and pedestrians), given to the local planner as ``LocalObservation.costmap``.
- **Blocked path.** With ``replan_on_blocked`` the next ``blocked_lookahead`` m of path are
  checked every tick (at most one blocked replan per 0.5 s): a laser return within
  ``robot_radius`` of the path, or an inscribed/lethal local-costmap cell on it, triggers a
  replan with the current scan marked on the planning grid (inflated like the map; in the
  global costmap: folded into its obstacle layer). Periodic replans then keep marking the scan
  so the path does not flip back. Readings at ``scan_range_max`` count as no return.
- **Oscillation and recovery.** With ``oscillation_timeout > 0`` a robot that has not moved
  ``oscillation_distance`` m within that time runs the next of ``recovery_behaviors``
  (``clear_costmap``, ``rotate``, ``back_up``; see :mod:`arena.nav.recovery`); the status is
  ``RECOVERING`` during a motion recovery. Once every behaviour has run without the robot
  getting away, the status becomes ``STUCK`` (commands only brake; the episode ends ``stuck``).
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
from arena.nav.costmap import (
    INSCRIBED,
    Costmap,
    CostmapParams,
    GlobalCostmap,
    LocalCostmap,
    update_obstacles,
)
from arena.nav.global_planners import (
    GLOBAL_PLANNERS,
    GlobalPlanner,
    plan_on_costmap,
    segment_is_free,
)
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
    infer_kinematics,
    limit_command,
)
from arena.nav.recovery import (
    RECOVERY_BEHAVIORS,
    OscillationMonitor,
    RecoveryName,
    RecoveryRun,
    mark_points,
    rear_is_free,
    sample_path,
    scan_to_world,
)


class NavStatus(enum.StrEnum):
    """Where a navigation run stands. Values are stable strings."""

    ACTIVE = "active"
    """Following a path toward the goal."""
    GOAL_REACHED = "goal_reached"
    """Within the goal tolerances; commands only brake."""
    FAILED = "failed"
    """The initial plan failed; the typed error is in :attr:`NavigationStack.last_error`."""
    RECOVERING = "recovering"
    """Running a motion recovery behaviour (rotate, back up) after getting stuck."""
    STUCK = "stuck"
    """Stuck and every recovery behaviour has been tried; commands only brake."""


def _planner_block(value: Any) -> Any:
    """Normalise the shorthand ``"name"`` to ``{"type": "name"}``."""
    return {"type": value} if isinstance(value, str) else value


class CostmapConfig(BaseModel):
    """Layer parameters of a costmap built by the stack (SI units, ``costmap_2d`` defaults).

    The inscribed radius is not configured here: the stack uses ``robot_radius +
    inflation_margin``, so cells the robot centre may not enter are those of the inflated map.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    inflation_radius: float | None = Field(
        None, ge=0, description="m, extent of the cost decay; None = inscribed radius + 0.5 m"
    )
    cost_scaling_factor: float = Field(
        10.0, ge=0, description="1/m, exponential decay rate of the inflation cost"
    )
    obstacle_range: float = Field(2.5, gt=0, description="m, returns closer than this mark")
    raytrace_range: float = Field(3.0, gt=0, description="m, free space cleared up to this range")

    def params(self, inscribed_radius: float, *, use_semantic: bool) -> CostmapParams:
        """The :class:`CostmapParams` for a robot of ``inscribed_radius`` (m)."""
        inflation = (
            inscribed_radius + 0.5 if self.inflation_radius is None else self.inflation_radius
        )
        return CostmapParams(
            inscribed_radius=inscribed_radius,
            inflation_radius=max(inflation, inscribed_radius),
            cost_scaling_factor=self.cost_scaling_factor,
            obstacle_range=self.obstacle_range,
            raytrace_range=self.raytrace_range,
            use_semantic=use_semantic,
        )


class GlobalCostmapConfig(CostmapConfig):
    """The ``navigation.global_costmap`` block: plan on a layered costmap of the static map."""

    use_scan: bool = Field(
        False, description="fold every laser scan into the obstacle layer (else only on a block)"
    )
    cost_weight: float = Field(
        3.0, ge=0,
        description="extra cost per metre at cost 252 for the cost-aware search; 0 = plan with "
        "the configured global planner on the costmap's lethal (inscribed) cells",
    )


class LocalCostmapConfig(CostmapConfig):
    """The ``navigation.local_costmap`` block: a rolling window updated every control tick."""

    width: float = Field(6.0, gt=0, description="m, window width")
    height: float = Field(6.0, gt=0, description="m, window height")
    use_pedestrians: bool = Field(True, description="add the pedestrian (semantic) layer")


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
    scan_sensor: str = Field(
        "laser", pattern=r"^[A-Za-z_][A-Za-z0-9_]*$",
        description="the robot's lidar2d sensor the stack and its costmaps read",
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
    planning_resolution: float = Field(
        0.1, gt=0, description="m; a map with coarser cells is planned on its cells split to at "
        "most this size, so the inflation is exact to within it"
    )
    goal_tolerance_xy: float = Field(0.3, gt=0, description="m, distance that counts as arrived")
    goal_tolerance_yaw: float | None = Field(
        None, gt=0, description="rad, heading error that counts as arrived; None ignores heading"
    )
    max_path_deviation: float = Field(
        0.5, gt=0, description="m from the path beyond which the stack replans at once"
    )
    global_costmap: GlobalCostmapConfig | None = Field(
        None, description="plan on a layered global costmap; None = on the inflated map"
    )
    local_costmap: LocalCostmapConfig | None = Field(
        None, description="rolling local costmap given to the local planner; None = none"
    )
    replan_on_blocked: bool = Field(
        False, description="replan at once (with the scan marked) when the path ahead is blocked"
    )
    blocked_lookahead: float = Field(
        2.0, gt=0, description="m of path ahead of the robot checked for blocking"
    )
    oscillation_timeout: float = Field(
        0.0, ge=0, description="s without oscillation_distance of motion that count as stuck; "
        "0 disables oscillation detection and recovery"
    )
    oscillation_distance: float = Field(
        0.2, gt=0, description="m the robot must move to count as making progress"
    )
    recovery_behaviors: tuple[RecoveryName, ...] = Field(
        RECOVERY_BEHAVIORS, description="recovery behaviours, in order, when stuck"
    )
    back_up_distance: float = Field(0.3, gt=0, description="m reversed by the back_up recovery")
    back_up_speed: float = Field(0.1, gt=0, description="m/s of the back_up recovery")
    rotate_speed: float = Field(
        1.0, gt=0, description="rad/s of the rotate recovery (capped by the robot's limit)"
    )

    # The planner blocks are checked against their registries where the file and key path are
    # known (the experiment loader, :meth:`NavigationStack.from_config`), not here: a pydantic
    # error would lose the UnknownNameError type and the exact key path inside the block.
    @field_validator("global_planner", "local_planner", "intermediate_planner", mode="before")
    @classmethod
    def _shorthand(cls, v: Any) -> Any:
        return _planner_block(v)


_DEFAULTS = NavigationConfig()
_BLOCKED_REPLAN_INTERVAL = 0.5
"""s, least time between two replans triggered by a blocked path."""
_PATH_SAMPLE_STEP = 0.1
"""m, spacing of the path samples checked for blocking."""


_MAX_PLANNING_CELLS = 16_000_000
"""Most cells :func:`subdivide` makes (4000 × 4000; the search keeps ~10 arrays of that size)."""


def subdivide(grid: OccupancyGrid, max_resolution: float) -> OccupancyGrid:
    """``grid`` with each cell split into ``k × k`` equal cells of at most ``max_resolution`` m.

    The same walls at a finer raster (``grid`` itself when its cells are small enough): a
    distance map measures centre to centre, so on a 0.5 m map an inflation below 0.5 m marks
    no cell and a plan through the cells next to a wall keeps only 0.25 m from it, less than a
    jackal's radius (the robot drove into the wall and stalled). On cells of ``max_resolution``
    the inflation errs by at most half of it. The split stops short of
    :data:`_MAX_PLANNING_CELLS` cells (a 1 km map of 0.5 m cells gets 0.25 m ones).
    """
    k = math.ceil(grid.resolution / max_resolution - 1e-9)
    k = min(k, max(int(math.sqrt(_MAX_PLANNING_CELLS / grid.data.size)), 1))
    if k <= 1:
        return grid
    data = np.repeat(np.repeat(grid.data, k, axis=0), k, axis=1)
    return OccupancyGrid(data, grid.resolution / k, grid.origin, grid.unknown_is_occupied)


def _ped_array(peds: Pedestrians) -> NDArray[np.float64]:
    """``(n, 4)`` ``[x, y, vx, vy]`` rows (m, m/s, world frame) of ``peds``."""
    pos = np.asarray(peds.positions, dtype=np.float64).reshape(-1, 2)
    vel = np.asarray(peds.velocities, dtype=np.float64).reshape(-1, 2)
    if len(vel) != len(pos):
        vel = np.zeros_like(pos)
    return np.hstack([pos, vel])


class NavigationStack:
    """Global planner + local planner with replanning and goal checking, for one robot.

    Args:
        global_planner: plans on the inflated map.
        local_planner: turns the path into commands.
        robot_radius: radius of the robot's bounding circle (m).
        inflation_margin: clearance added to ``robot_radius`` when inflating the map (m).
        footprint_radius: inscribed radius of the robot's footprint (m): the largest disc about
            the robot origin inside it. Where the map inflated by ``robot_radius`` closes every
            route, the plan is made on the map inflated by ``footprint_radius +
            inflation_margin`` (see "Narrow passages" in the module docstring). ``None`` (or
            not below ``robot_radius``) plans with ``robot_radius`` only.
        planning_resolution: largest cell size planned on (m); coarser maps are subdivided.
        replan_period: seconds between replans; 0 plans only at reset (and on deviation).
        goal_tolerance: ``(xy m, yaw rad or None)``; ``None`` ignores the heading.
        max_path_deviation: distance from the path (m) that triggers an immediate replan.
        kinematics: the robot's kinematics name; checked against the local planner's
            ``supports`` and passed on in every observation. ``None`` lets the planner infer it.
        intermediate_planner: refines the path between the two; ``None`` = ``bypass``.
        intermediate_period: seconds between intermediate-planner calls; 0 = every tick.
        intermediate_window: radius (m) of the local window given to the intermediate planner.
        global_costmap: plan on a :class:`~arena.nav.costmap.GlobalCostmap` (``None``: on the
            inflated occupancy grid, as before).
        local_costmap: keep a :class:`~arena.nav.costmap.LocalCostmap` rolling window updated
            every tick (``None``: none).
        replan_on_blocked: replan at once, with the current scan marked on the planning grid,
            when a laser return (or a lethal local-costmap cell) blocks the path ahead.
        blocked_lookahead: length of path ahead checked for blocking (m).
        oscillation_timeout: seconds without ``oscillation_distance`` of motion before a
            recovery behaviour runs; 0 disables detection and recovery.
        oscillation_distance: motion that counts as progress (m).
        recovery_behaviors: the recovery behaviours in order (see :mod:`arena.nav.recovery`).
        back_up_distance: distance reversed by ``back_up`` (m).
        back_up_speed: reversing speed of ``back_up`` (m/s).
        rotate_speed: turn rate of ``rotate`` (rad/s), capped by the robot's ``omega_max``.
        scan_range_max: the laser's maximum range (m); readings at it count as no hit.

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
        footprint_radius: float | None = None,
        planning_resolution: float = _DEFAULTS.planning_resolution,
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
        global_costmap: GlobalCostmapConfig | None = None,
        local_costmap: LocalCostmapConfig | None = None,
        replan_on_blocked: bool = _DEFAULTS.replan_on_blocked,
        blocked_lookahead: float = _DEFAULTS.blocked_lookahead,
        oscillation_timeout: float = _DEFAULTS.oscillation_timeout,
        oscillation_distance: float = _DEFAULTS.oscillation_distance,
        recovery_behaviors: tuple[RecoveryName, ...] = _DEFAULTS.recovery_behaviors,
        back_up_distance: float = _DEFAULTS.back_up_distance,
        back_up_speed: float = _DEFAULTS.back_up_speed,
        rotate_speed: float = _DEFAULTS.rotate_speed,
        scan_range_max: float = math.inf,
    ) -> None:
        if not robot_radius > 0:
            raise ConfigError(f"robot_radius must be > 0 m, got {robot_radius}")
        if footprint_radius is not None and not footprint_radius > 0:
            raise ConfigError(f"footprint_radius must be > 0 m, got {footprint_radius}")
        if not planning_resolution > 0:
            raise ConfigError(f"planning_resolution must be > 0 m, got {planning_resolution}")
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
        supports: frozenset[str] = getattr(local_planner, "supports", frozenset())
        if kinematics is not None and kinematics not in supports:
            raise ConfigError(
                f"local planner {type(local_planner).__name__} cannot drive {kinematics!r} robots "
                f"(supports: {', '.join(sorted(supports)) or 'none'})"
            )
        self.global_planner = global_planner
        self.local_planner = local_planner
        self.robot_radius = float(robot_radius)
        self.inflation_margin = float(inflation_margin)
        self.footprint_radius = (
            None if footprint_radius is None or footprint_radius >= robot_radius
            else float(footprint_radius)
        )
        self.planning_resolution = float(planning_resolution)
        self.replan_period = float(replan_period)
        self.goal_tolerance_xy = float(goal_tolerance[0])
        self.goal_tolerance_yaw = None if goal_tolerance[1] is None else float(goal_tolerance[1])
        self.max_path_deviation = float(max_path_deviation)
        self.kinematics = kinematics
        self.grid: OccupancyGrid | None = None
        self.inflated: OccupancyGrid | None = None
        """The planning grid inflated by ``robot_radius + inflation_margin``."""
        self.inflated_footprint: OccupancyGrid | None = None
        """The planning grid inflated by ``footprint_radius + inflation_margin`` (or ``None``)."""
        self.footprint_plan = False
        """Whether the current path was planned with the footprint radius (a narrow passage)."""
        self.goal = Pose2D()
        self.status = NavStatus.FAILED
        self.last_error: PlanningError | None = None
        self.replans = 0
        self._path = np.zeros((0, 2))
        self._nearest_free: dict[int, NDArray[np.int64]] = {}
        self._wide_labels: NDArray[np.int32] | None = None
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
        bad = [
            name
            for name in recovery_behaviors
            if name not in ("clear_costmap", "rotate", "back_up")
        ]
        if (
            bad or not blocked_lookahead > 0 or oscillation_timeout < 0
            or not (oscillation_distance > 0 and back_up_distance > 0)
            or not (back_up_speed > 0 and rotate_speed > 0)
        ):
            raise ConfigError(
                "invalid recovery settings: unknown behaviours "
                f"{bad}, or a non-positive distance, speed or lookahead"
            )
        self.global_costmap_config = global_costmap
        self.local_costmap_config = local_costmap
        self.global_costmap: GlobalCostmap | None = None
        """The global costmap (``None`` unless configured); built at :meth:`reset`."""
        self.local_costmap: LocalCostmap | None = None
        """The rolling local costmap (``None`` unless configured); updated every tick."""
        self.replan_on_blocked = bool(replan_on_blocked)
        self.blocked_lookahead = float(blocked_lookahead)
        self.oscillation = OscillationMonitor(oscillation_timeout, oscillation_distance)
        self.recovery_behaviors: tuple[RecoveryName, ...] = tuple(recovery_behaviors)
        self.back_up_distance = float(back_up_distance)
        self.back_up_speed = float(back_up_speed)
        self.rotate_speed = float(rotate_speed)
        self.scan_range_max = float(scan_range_max)
        self.blocked_replans = 0
        """Replans triggered by a blocked path since :meth:`reset`."""
        self.recoveries: list[RecoveryName] = []
        """Recovery behaviours run since :meth:`reset`, in order."""
        self._recovery_index = 0
        self._recovery: RecoveryRun | None = None
        self._stuck_xy: NDArray[np.float64] | None = None
        self._scan_world = np.zeros((0, 2))
        self._samples = np.zeros((0, 2))
        self._sample_s = np.zeros(0)
        self._last_blocked = -math.inf

    @classmethod
    def from_config(
        cls,
        cfg: NavigationConfig | Mapping[str, Any] | None,
        robot_radius: float,
        source: str | None = None,
        *,
        footprint_radius: float | None = None,
        kinematics: str | None = None,
        path: str | None = "navigation",
        local_planner: LocalPlanner | None = None,
        scan_range_max: float = math.inf,
        goal_tolerance: tuple[float, float | None] | None = None,
    ) -> NavigationStack:
        """Build both planners through their registries from a ``navigation`` block.

        Args:
            cfg: the block (a model, a plain mapping, or ``None`` for all defaults).
            robot_radius: radius of the robot's bounding circle (m).
            source: file the block came from, for error messages.
            footprint_radius: the footprint's inscribed radius (m), for narrow passages.
            kinematics: the robot's kinematics name (checked against the local planner).
            path: key path of the block inside ``source``, for error messages.
            local_planner: a planner instance used instead of the block's (a trainer's).
            scan_range_max: m, laser ranges at or past it are free space (the sensor's max).
            goal_tolerance: ``(xy m, yaw rad or None)`` instead of the block's.

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
        lp = local_planner if local_planner is not None else LOCAL_PLANNERS.build(
            cfg.local_planner, source=source, path=sub("local_planner")
        )
        ip = INTERMEDIATE_PLANNERS.build(
            cfg.intermediate_planner, source=source, path=sub("intermediate_planner")
        )
        try:
            return cls(
                gp, lp, robot_radius=robot_radius, inflation_margin=cfg.inflation_margin,
                footprint_radius=footprint_radius,
                planning_resolution=cfg.planning_resolution,
                replan_period=cfg.replan_period,
                goal_tolerance=goal_tolerance or (cfg.goal_tolerance_xy, cfg.goal_tolerance_yaw),
                max_path_deviation=cfg.max_path_deviation, kinematics=kinematics,
                intermediate_planner=ip, intermediate_period=cfg.intermediate_period,
                intermediate_window=cfg.intermediate_window,
                global_costmap=cfg.global_costmap, local_costmap=cfg.local_costmap,
                replan_on_blocked=cfg.replan_on_blocked,
                blocked_lookahead=cfg.blocked_lookahead,
                oscillation_timeout=cfg.oscillation_timeout,
                oscillation_distance=cfg.oscillation_distance,
                recovery_behaviors=cfg.recovery_behaviors,
                back_up_distance=cfg.back_up_distance, back_up_speed=cfg.back_up_speed,
                rotate_speed=cfg.rotate_speed, scan_range_max=scan_range_max,
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
            fine = subdivide(grid, self.planning_resolution)
            self.inflated = fine.inflate(self.robot_radius + self.inflation_margin)
            self.inflated_footprint = (
                None if self.footprint_radius is None
                else fine.inflate(self.footprint_radius + self.inflation_margin)
            )
            self._nearest_free = {}
            self._wide_labels = None
            self.global_costmap = None
        inscribed = self.robot_radius + self.inflation_margin
        gcfg, lcfg = self.global_costmap_config, self.local_costmap_config
        if gcfg is not None:
            if self.global_costmap is None:
                self.global_costmap = GlobalCostmap(
                    subdivide(grid, self.planning_resolution),
                    gcfg.params(inscribed, use_semantic=False),
                )
            else:  # same map: forget the previous episode's obstacles
                self.global_costmap.obstacles.costs[:] = 0
                self.global_costmap.update()
        if lcfg is not None:
            self.local_costmap = LocalCostmap(
                grid, lcfg.width, lcfg.height,
                lcfg.params(self.robot_radius, use_semantic=lcfg.use_pedestrians),
            )
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
        self.blocked_replans = 0
        self.recoveries = []
        self._recovery_index = 0
        self._recovery = None
        self._stuck_xy = None
        self._scan_world = np.zeros((0, 2))
        self._last_blocked = -math.inf
        self.oscillation.reset(start.xy, self._time)
        try:
            self._set_path(self._plan_from(start))
        except PlanningError as e:
            self.last_error = e
            self.status = NavStatus.FAILED
            raise
        self.status = NavStatus.ACTIVE
        return self.status

    def replan(self, pose: Pose2D, *, mark_scan: bool | None = None) -> bool:
        """Plan again from ``pose``; on failure keep the old path and record :attr:`last_error`.

        Args:
            pose: the robot's pose (m, rad).
            mark_scan: plan with the last scan's returns marked on the planning grid (inflated
                like the map); ``None`` = :attr:`replan_on_blocked`.

        Returns:
            Whether a new path was set.
        """
        self._require_reset()
        self.replans += 1
        if mark_scan is None:
            mark_scan = self.replan_on_blocked
        try:
            self._set_path(self._plan_from(pose, mark_scan=mark_scan))
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
        running = (NavStatus.ACTIVE, NavStatus.RECOVERING)
        if self.status in running and self.goal_reached(Pose2D.from_array(q)):
            self.status = NavStatus.GOAL_REACHED
            self._recovery = None
        if self.status not in running:
            return limit_command(np.zeros(3), v, obs.limits, obs.dt)

        self._sense(obs, q, pedestrians)
        if self.status is NavStatus.RECOVERING:
            cmd = self._recover(obs, q, v)
            if cmd is not None:
                return cmd
        if self.oscillation.enabled and self._stuck(q):
            cmd = self._start_recovery(obs, q, v)
            if cmd is not None:
                return cmd

        due = self.replan_period > 0 and self._time - self._last_plan_time >= self.replan_period
        strayed = (
            self._time >= self._retry_after
            and self.cross_track_error(q[:2]) > self.max_path_deviation
        )
        if due or strayed:
            self.replan(Pose2D.from_array(q))
        elif self._path_blocked(q):
            self.blocked_replans += 1
            self._last_blocked = self._time
            self.replan(Pose2D.from_array(q), mark_scan=True)

        path = self._intermediate(obs, q, v, pedestrians)
        local_obs = dataclasses.replace(
            obs, path=path, goal=self.goal,
            kinematics=obs.kinematics if obs.kinematics is not None else self.kinematics,
            goal_yaw_tolerance=(
                obs.goal_yaw_tolerance
                if obs.goal_yaw_tolerance is not None
                else self.goal_tolerance_yaw
            ),
            goal_xy_tolerance=(
                obs.goal_xy_tolerance
                if obs.goal_xy_tolerance is not None
                else self.goal_tolerance_xy
            ),
            pedestrians=(
                _ped_array(pedestrians)
                if pedestrians is not None and len(pedestrians) and not np.size(obs.pedestrians)
                else obs.pedestrians
            ),
            costmap=(
                self.local_costmap.master if self.local_costmap is not None else obs.costmap
            ),
        )
        return np.asarray(self.local_planner.compute(local_obs), dtype=np.float64).reshape(3)

    @property
    def intermediate_path(self) -> NDArray[np.float64]:
        """The path the local planner followed at the last :meth:`step` (m, ``(m, 2)``)."""
        return self._inter_path if self._inter_path is not None else self._path

    # -- sensing, blocking, recovery ------------------------------------------------------------
    def _sense(
        self, obs: LocalObservation, q: NDArray[np.float64], pedestrians: Pedestrians | None
    ) -> None:
        """Fold this tick's scan into the costmaps and keep its returns (world frame)."""
        ranges = np.asarray(obs.scan_ranges, dtype=np.float64).reshape(-1)
        angles = np.asarray(obs.scan_angles, dtype=np.float64).reshape(-1)
        self._obs = obs
        self._scan_world = scan_to_world(q, ranges, angles, obs.scan_origin, self.scan_range_max)
        lcm = self.local_costmap
        if lcm is not None:
            peds = pedestrians if pedestrians is not None and len(pedestrians) else None
            lcm.update(
                q,
                scan_ranges=ranges if ranges.size and ranges.shape == angles.shape else None,
                scan_angles=angles, scan_origin=obs.scan_origin, range_max=self.scan_range_max,
                ped_positions=None if peds is None else peds.positions,
                ped_velocities=None if peds is None else peds.velocities,
            )
        gcfg = self.global_costmap_config
        if gcfg is not None and gcfg.use_scan:
            self._fold_scan_into_global()

    def _fold_scan_into_global(self) -> None:
        """Mark and clear the last scan in the global obstacle layer (recomposed when planning)."""
        gcm, obs = self.global_costmap, getattr(self, "_obs", None)
        if gcm is None or obs is None:
            return
        ranges = np.asarray(obs.scan_ranges, dtype=np.float64).reshape(-1)
        angles = np.asarray(obs.scan_angles, dtype=np.float64).reshape(-1)
        if ranges.size == 0 or ranges.shape != angles.shape:
            return
        q = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        c, s = math.cos(q[2]), math.sin(q[2])
        so = np.asarray(obs.scan_origin, dtype=np.float64).reshape(2)
        sensor = q[:2] + np.array([c * so[0] - s * so[1], s * so[0] + c * so[1]])
        p = gcm.params
        update_obstacles(
            gcm.obstacles, sensor, angles + q[2], ranges, obstacle_range=p.obstacle_range,
            raytrace_range=p.raytrace_range, range_max=self.scan_range_max,
        )

    def _path_blocked(self, q: NDArray[np.float64]) -> bool:
        """Whether the next ``blocked_lookahead`` m of path are blocked (rate-limited).

        Blocked: a lethal or inscribed cell of the local costmap on the path, or a laser return
        within ``robot_radius`` of it.
        """
        if (
            not self.replan_on_blocked
            or self._time < self._retry_after
            or self._time - self._last_blocked < _BLOCKED_REPLAN_INTERVAL
            or len(self._samples) == 0
        ):
            return False
        i0 = int(np.argmin(np.hypot(*(self._samples - q[:2]).T)))
        s0 = self._sample_s[i0]
        within = (self._sample_s >= s0) & (self._sample_s <= s0 + self.blocked_lookahead)
        ahead = self._samples[within]
        if self.local_costmap is not None:
            costs = self.local_costmap.master.cost_at(ahead, off_map=0)
            if bool(np.any((costs >= INSCRIBED) & (costs != 255))):
                return True
        pts = self._scan_world
        if len(pts) == 0 or len(ahead) == 0:
            return False
        d2 = np.sum((ahead[:, None, :] - pts[None, :, :]) ** 2, axis=-1)
        return bool(np.min(d2) < self.robot_radius**2)

    def _clear_costmaps(self) -> None:
        """Forget the obstacle layers (recovery ``clear_costmap``)."""
        if self.global_costmap is not None:
            self.global_costmap.obstacles.costs[:] = 0
            self.global_costmap.update()
        if self.local_costmap is not None:
            self.local_costmap.obstacles.costs[:] = 0

    def _stuck(self, q: NDArray[np.float64]) -> bool:
        """Feed the oscillation monitor; re-arm the recoveries once the robot got away."""
        if self._stuck_xy is not None and float(np.hypot(*(q[:2] - self._stuck_xy))) > (
            self.oscillation.distance + self.back_up_distance
        ):
            self._stuck_xy = None
            self._recovery_index = 0
        return self.oscillation.update(q[:2], self._time)

    def _start_recovery(
        self, obs: LocalObservation, q: NDArray[np.float64], v: NDArray[np.float64]
    ) -> NDArray[np.float64] | None:
        """Run the next applicable recovery; ``None`` lets the normal tick go on."""
        if self._stuck_xy is None:
            self._stuck_xy = q[:2].copy()
        lim = obs.limits
        drive = obs.kinematics or self.kinematics or infer_kinematics(lim)
        while self._recovery_index < len(self.recovery_behaviors):
            name = self.recovery_behaviors[self._recovery_index]
            self._recovery_index += 1
            if name == "clear_costmap":
                self.recoveries.append(name)
                self._clear_costmaps()
                self.local_planner.reset()
                self.oscillation.reset(q[:2], self._time)
                self.replan(Pose2D.from_array(q), mark_scan=False)
                return None
            if name == "rotate" and drive != "ackermann" and lim.omega_max > 0:
                omega = min(self.rotate_speed, float(lim.omega_max))
                deadline = self._time + 1.5 * 2 * math.pi / omega + 2.0
            elif name == "back_up" and lim.vx_min < 0 and rear_is_free(
                q, self._scan_world, self.robot_radius, self.back_up_distance
            ):
                speed = min(self.back_up_speed, -float(lim.vx_min))
                deadline = self._time + 2.0 * self.back_up_distance / speed + 2.0
            else:
                continue
            self.recoveries.append(name)
            self._recovery = RecoveryRun(name, q[:2].copy(), self._time, float(q[2]), 0.0, deadline)
            self.status = NavStatus.RECOVERING
            cmd = self._recover(obs, q, v)
            if cmd is not None:
                return cmd
        if self.status is NavStatus.ACTIVE:
            self.status = NavStatus.STUCK
            return limit_command(np.zeros(3), v, lim, obs.dt)
        return None

    def _recover(
        self, obs: LocalObservation, q: NDArray[np.float64], v: NDArray[np.float64]
    ) -> NDArray[np.float64] | None:
        """One tick of the running motion recovery; ``None`` once it has finished."""
        run = self._recovery
        lim = obs.limits
        if run is None:
            self.status = NavStatus.ACTIVE
            return None
        if run.name == "rotate":
            run.track(float(q[2]))
            done = run.turned >= 2 * math.pi - 0.05
            cmd = np.array([0.0, 0.0, min(self.rotate_speed, float(lim.omega_max))])
        else:
            travelled = float(np.hypot(*(q[:2] - run.start_xy)))
            left = self.back_up_distance - travelled
            done = left <= 1e-3 or not rear_is_free(
                q, self._scan_world, self.robot_radius, max(left, 0.0)
            )
            cmd = np.array([-min(self.back_up_speed, -float(lim.vx_min)), 0.0, 0.0])
        if done or self._time >= run.deadline:
            self._recovery = None
            self.status = NavStatus.ACTIVE
            self.local_planner.reset()
            self.oscillation.reset(q[:2], self._time)
            self.replan(Pose2D.from_array(q))
            return None
        return limit_command(cmd, v, lim, obs.dt)

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
            global_costmap=(
                self.global_costmap.master if self.global_costmap is not None else None
            ),
            local_costmap=self.local_costmap.master if self.local_costmap is not None else None,
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
        self._samples, self._sample_s = sample_path(p, _PATH_SAMPLE_STEP)
        self._last_plan_time = self._time
        self._retry_after = -math.inf

    def _planning_grid(
        self, mark_scan: bool, *, footprint: bool = False
    ) -> tuple[OccupancyGrid, Costmap | None]:
        """The occupancy grid to plan on, and the global costmap's master when configured.

        Without a global costmap: the inflated map (by the footprint radius when ``footprint``),
        with the last scan's returns marked (inflated alike) when ``mark_scan``. With one: its
        lethal/inscribed cells, after folding the last scan into its obstacle layer when
        ``mark_scan`` (every tick already with ``use_scan``).
        """
        assert self.inflated is not None
        gcm, gcfg = self.global_costmap, self.global_costmap_config
        if gcm is not None and gcfg is not None:
            if mark_scan and not gcfg.use_scan:
                self._fold_scan_into_global()
            master = gcm.update()
            return master.to_occupancy(INSCRIBED), master
        grid, radius = self.inflated, self.robot_radius
        if footprint and self.inflated_footprint is not None and self.footprint_radius:
            grid, radius = self.inflated_footprint, self.footprint_radius
        if mark_scan and len(self._scan_world):
            return mark_points(grid, self._scan_world, radius + self.inflation_margin), None
        return grid, None

    def _plan_on(
        self, grid: OccupancyGrid, costmap: Costmap | None, start: Pose2D
    ) -> NDArray[np.float64]:
        gcfg = self.global_costmap_config
        if costmap is not None and gcfg is not None and gcfg.cost_weight > 0:
            return plan_on_costmap(
                costmap, start, self.goal, cost_weight=gcfg.cost_weight, heuristic_weight=1.0,
                smooth=True,
            )
        return self.global_planner.plan(grid, start, self.goal)

    def _plan_from(self, start: Pose2D, *, mark_scan: bool = False) -> NDArray[np.float64]:
        """Plan with the robot radius; where that fails, with the footprint's (narrow passages)."""
        narrow = self.inflated_footprint is not None and self.global_costmap is None
        if not (narrow and self._apart_for_the_circle(start)):
            try:
                path = self._plan_with(start, mark_scan, footprint=False)
            except PlanningError:
                if not narrow:
                    raise
            else:
                self.footprint_plan = False
                return path
        path = self._plan_with(start, mark_scan, footprint=True)
        self.footprint_plan = True
        return path

    def _apart_for_the_circle(self, start: Pose2D) -> bool:
        """Whether start and goal lie in different free regions of :attr:`inflated`.

        Then planning with the robot radius surely fails (a scan marked on the grid only blocks
        more), so a replan in a narrow passage need not search the whole region first. The
        8-connected regions are labelled once per map; a start in the inflated zone is not
        judged (its way out is found by the planning).
        """
        assert self.inflated is not None
        if self._wide_labels is None:
            self._wide_labels = ndimage.label(
                ~self.inflated.occupied, structure=np.ones((3, 3), dtype=bool)
            )[0]
        cells = self.inflated.world_to_cell(np.array([start.xy, self.goal.xy]))
        if not bool(np.all(self.inflated.in_bounds(cells))):
            return False
        a, b = self._wide_labels[cells[:, 0], cells[:, 1]]
        return bool(a > 0 and b > 0 and a != b)

    def _plan_with(
        self, start: Pose2D, mark_scan: bool, *, footprint: bool
    ) -> NDArray[np.float64]:
        assert self.inflated is not None
        assert self.grid is not None
        grid, costmap = self._planning_grid(mark_scan, footprint=footprint)
        try:
            return self._plan_on(grid, costmap, start)
        except StartOccupied:
            free = self._free_cell_near(grid, start)
            if free is None:
                raise
        via = Pose2D(float(free[0]), float(free[1]), start.theta)
        path = self._plan_on(grid, costmap, via)
        return np.vstack([start.xy[None, :], path])

    def _free_cell_near(
        self, grid: OccupancyGrid, start: Pose2D
    ) -> NDArray[np.float64] | None:
        """Centre (m) of ``grid``'s free cell nearest to ``start``, if safely reachable."""
        assert self.grid is not None
        cell = grid.world_to_cell(start.xy)
        blocked = grid.occupied
        if not bool(grid.in_bounds(cell)) or bool(blocked.all()):
            return None
        # The inflated maps (not those with a scan marked) keep their nearest-free-cell table.
        key = 0 if grid is self.inflated else 1 if grid is self.inflated_footprint else -1
        if key in self._nearest_free:
            idx = self._nearest_free[key]
        else:
            # One EDT with indices gives every cell's nearest free cell; computed on first need.
            _, idx = ndimage.distance_transform_edt(blocked, return_indices=True)
            if key >= 0:
                self._nearest_free[key] = idx
        r, c = int(cell[0]), int(cell[1])
        free_cell = idx[:, r, c]
        centre = grid.cell_to_world(free_cell)
        if not segment_is_free(self.grid, start.xy, centre):
            return None
        return centre
