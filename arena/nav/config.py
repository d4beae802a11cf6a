"""The ``navigation`` block of an experiment and the stack's status (:class:`NavigationConfig`).

:func:`navigation_config` validates a block from a file (planner blocks through their
registries, so that an unknown planner keeps its close-match hint and exact key path);
:func:`~arena.nav.build.stack_from_config` turns it into a
:class:`~arena.nav.stack.NavigationStack`.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from arena.core.errors import from_validation_error
from arena.nav.costmap import CostmapParams
from arena.nav.global_planners import GLOBAL_PLANNERS
from arena.nav.intermediate import INTERMEDIATE_PLANNERS
from arena.nav.local_planners import LOCAL_PLANNERS
from arena.nav.recovery import RECOVERY_BEHAVIORS, RecoveryName


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
    perception: dict[str, Any] = Field(
        default_factory=lambda: {"type": "ground_truth"},
        description="where the planners' people come from {type: ground_truth | lidar, ...}",
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
    # known (the experiment loader, :func:`navigation_config`), not here: a pydantic
    # error would lose the UnknownNameError type and the exact key path inside the block.
    @field_validator("global_planner", "local_planner", "intermediate_planner", "perception",
                     mode="before")
    @classmethod
    def _shorthand(cls, v: Any) -> Any:
        return _planner_block(v)


DEFAULTS = NavigationConfig()
"""The block with every default (the stack's keyword defaults)."""


def navigation_config(
    cfg: NavigationConfig | Mapping[str, Any] | None,
    source: str | None = None,
    path: str | None = "navigation",
) -> NavigationConfig:
    """``cfg`` validated (``None``: the defaults).

    Args:
        cfg: the block (a model, a plain mapping, or ``None`` for all defaults).
        source: file the block came from, for error messages.
        path: key path of the block inside ``source``, for error messages.

    Raises:
        ConfigError: naming ``source`` and the key path when the block is invalid.
    """
    if cfg is None:
        return DEFAULTS
    if isinstance(cfg, NavigationConfig):
        return cfg
    raw = dict(cfg)
    # Check the planner blocks through their registries first: their errors keep their type
    # (UnknownNameError with a close match) and the exact key path.
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
                source=source, path=f"{path}.{key}" if path else key,
            )
    try:
        return NavigationConfig.model_validate(raw)
    except ValidationError as e:
        raise from_validation_error(e, source=source, prefix=path) from None
