"""The navigation stack of a ``navigation`` block: :func:`stack_from_config`."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from arena.core.errors import ConfigError
from arena.nav.config import NavigationConfig, navigation_config
from arena.nav.global_planners import GLOBAL_PLANNERS
from arena.nav.intermediate import INTERMEDIATE_PLANNERS
from arena.nav.local_planners import LOCAL_PLANNERS, LocalPlanner
from arena.nav.stack import NavigationStack


def stack_from_config(
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
    cfg = navigation_config(cfg, source, path)
    sub = (lambda key: f"{path}.{key}") if path else (lambda key: key)
    gp = GLOBAL_PLANNERS.build(cfg.global_planner, source=source, path=sub("global_planner"))
    lp = local_planner if local_planner is not None else LOCAL_PLANNERS.build(
        cfg.local_planner, source=source, path=sub("local_planner")
    )
    ip = INTERMEDIATE_PLANNERS.build(
        cfg.intermediate_planner, source=source, path=sub("intermediate_planner")
    )
    try:
        return NavigationStack(
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
