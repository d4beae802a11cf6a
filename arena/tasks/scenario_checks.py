"""Checks of a scenario that go beyond its format: layout, and positions against a map.

:func:`check_layout` refuses what no map can make valid (start == goal, two people on one
spot); :func:`validate_against_map` checks every position lies on the map and out of walls (and
robot starts and goals out of unknown space);
:func:`check_robot_bodies` checks each robot's real footprint at its start and goal against the
walls and placed obstacles with the simulator's own contact tests.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from arena.core.errors import ConfigError
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import RobotSpawn
from arena.scene.state import Obstacle, StaticWorld
from arena.sim.contacts import Footprint, ObstacleIndex, first_obstacle_hit, hits_grid

if TYPE_CHECKING:  # read, never built here: scenario.py imports these checks
    from arena.tasks.scenario import Scenario

_ROBOT, _PERSON, _OBSTACLE = "robot", "person", "obstacle"

DEFAULT_PED_RADIUS = 0.3
"""m, body radius of a scenario pedestrian (the format has no radius key)."""


def _points(scenario: Scenario) -> list[tuple[str, Sequence[float], str]]:
    """Every position of the scenario as (key path, xy, what stands there)."""
    pts: list[tuple[str, Sequence[float], str]] = []
    for i, r in enumerate(scenario.robots):
        pts += [(f"robots[{i}].start", r.start, _ROBOT), (f"robots[{i}].goal", r.goal, _ROBOT)]
    for group in ("static", "interactive"):
        for i, o in enumerate(getattr(scenario.obstacles, group)):
            pts.append((f"obstacles.{group}[{i}].pos", o.pos, _OBSTACLE))
    for i, p in enumerate(scenario.obstacles.dynamic):
        pts.append((f"obstacles.dynamic[{i}].pos", p.pos, _PERSON))
        for j, w in enumerate(p.waypoints):
            pts.append((f"obstacles.dynamic[{i}].waypoints[{j}]", w, _PERSON))
    return pts


def validate_against_map(
    scenario: Scenario, grid: OccupancyGrid, *, source: str | None = None
) -> list[str]:
    """Check that every position lies on ``grid``, robots/pedestrians not in walls.

    A robot's start and goal must also lie in known space: an unknown (-1) cell is outside the
    mapped building (the simulator may drive through unknown space unless
    ``unknown_is_occupied``, but a task placed there is a mistake). An obstacle may stand
    against (or partly in) a wall: only its being on the map is checked.

    Args:
        scenario: the scenario.
        grid: the map it runs on.
        source: the scenario file, for messages.

    Returns:
        Findings that are not errors (none at present; kept for the CLI's list).

    Raises:
        ConfigError: led by the first offending entry (e.g. ``obstacles.dynamic[3].waypoints[1]``),
            followed by every other one.
    """
    xmin, ymin, xmax, ymax = grid.bounds
    problems: list[tuple[str, str]] = []
    for path, pos, what in _points(scenario):
        xy = np.array([float(pos[0]), float(pos[1])])
        where = f"({xy[0]:g}, {xy[1]:g})"
        if not bool(grid.contains(xy)):
            problems.append(
                (
                    path,
                    f"{where} lies outside the map (x in [{xmin:g}, {xmax:g}], "
                    f"y in [{ymin:g}, {ymax:g}])",
                )
            )
        elif what != _OBSTACLE and bool(grid.is_occupied(xy)):
            problems.append((path, f"{where} lies inside a wall of the map"))
        elif what == _ROBOT and int(grid.data[tuple(grid.world_to_cell(xy))]) < 0:
            problems.append(
                (path, f"{where} lies in unknown space of the map (cell -1, outside the "
                       "mapped area); a robot needs a known free start and goal")
            )
    if problems:
        # The first problem leads (file and key path first); the rest are listed after it.
        (path, text), rest = problems[0], problems[1:]
        more = "".join(f"; {p}: {t}" for p, t in rest)
        raise ConfigError(text + more, source=source, path=path)
    return []


MIN_GOAL_DISTANCE = 0.3
"""m; a robot goal closer than this to its start (the default ``task.goal_radius``) would be
reached at the first step: :func:`check_layout` refuses it as ``start == goal``."""


ONE_SPOT = 0.01
"""m; two pedestrian starts closer than this are one spot (a refused scenario)."""


def check_layout(
    scenario: Scenario, *, goal_radius: float = MIN_GOAL_DISTANCE, source: str | None = None
) -> None:
    """Refuse what no map can make valid: start == goal, two people on one spot.

    A goal within ``goal_radius`` of its start, or two pedestrians closer than
    :data:`ONE_SPOT` at their starts, raise. Pedestrians whose bodies (radius
    :data:`DEFAULT_PED_RADIUS`) merely overlap load with one warning, as Arena loads them.

    Raises:
        ConfigError: naming the entry (``robots[0].goal``, ``obstacles.dynamic[4].pos``).
    """
    for i, r in enumerate(scenario.robots):
        d = float(np.hypot(r.goal[0] - r.start[0], r.goal[1] - r.start[1]))
        if d <= goal_radius:
            raise ConfigError(
                f"the goal ({r.goal[0]:g}, {r.goal[1]:g}) is {d:.3g} m from the start: start == "
                f"goal within the goal radius {goal_radius:g} m (the episode would end at once)",
                source=source, path=f"robots[{i}].goal",
            )
    peds = scenario.obstacles.dynamic
    if len(peds) > 1:
        from scipy.spatial import cKDTree

        xy = np.array([p.pos[:2] for p in peds], dtype=np.float64)
        tree = cKDTree(xy)
        same = tree.query_pairs(ONE_SPOT)
        if same:
            i, j = min(same, key=lambda ij: (ij[1], ij[0]))  # the first entry on a taken spot
            gap = float(np.hypot(*(xy[j] - xy[i])))
            unset = [k for k in (i, j) if "pos" not in peds[k].model_fields_set]
            why = ""
            if unset:
                keys = " and ".join(f"obstacles.dynamic[{k}]" for k in unset)
                why = (f"; {keys} {'has' if len(unset) == 1 else 'have'} no pos, so Arena "
                       "starts them at [0, 0, 0]")
            raise ConfigError(
                f"starts {gap:.3g} m from obstacles.dynamic[{i}] ({peds[i].name!r}): two "
                f"people on one spot (closer than {ONE_SPOT:g} m, the direction between them "
                f"is undefined for every crowd model){why}",
                source=source, path=f"obstacles.dynamic[{j}].pos",
            )
        overlapping = tree.query_pairs(2 * DEFAULT_PED_RADIUS * (1 - 1e-9))
        if overlapping:
            # Arena's own worlds place people 0.5 m apart (floor, hospital, map_empty_medium):
            # Arena loads them and the crowd model pushes them apart, so do we, and say so.
            i, j = min(overlapping, key=lambda ij: (ij[1], ij[0]))
            gap = float(np.hypot(*(xy[j] - xy[i])))
            warnings.warn(
                f"{source or 'scenario'}: obstacles.dynamic[{j}] starts {gap:.3g} m from "
                f"obstacles.dynamic[{i}]: {len(overlapping)} pair(s) of people start with "
                f"overlapping bodies (radius {DEFAULT_PED_RADIUS:g} m); the crowd model pushes "
                f"them apart",
                UserWarning, stacklevel=2,
            )


def check_robot_bodies(
    spawns: Sequence[RobotSpawn],
    grid: OccupancyGrid,
    obstacles: Sequence[Obstacle],
    *,
    source: str | None = None,
) -> None:
    """Check each robot's real footprint at its start and goal against walls and obstacles.

    Uses the simulator's own contact tests: a point check misses a body half inside a shelf.

    Args:
        spawns: the robots, in scenario order (``robots[k]``).
        grid: the map.
        obstacles: the placed obstacles to test against.
        source: the scenario file, for messages.

    Raises:
        ConfigError: ``robots[k].start`` (or ``.goal``) and what the body overlaps.
    """
    index = ObstacleIndex.build(StaticWorld.build(grid, tuple(obstacles)))
    for k, spawn in enumerate(spawns):
        model = spawn.model
        fp = Footprint.make(model.footprint_polygon(), model.circumscribed_radius)
        for key, pose in (("start", spawn.start), ("goal", spawn.goal)):
            p = np.array([pose.x, pose.y, pose.theta], dtype=np.float64)
            where = f"({pose.x:g}, {pose.y:g}, {pose.theta:g})"
            body = f"the body of {model.name!r} (reach {fp.reach:.2f} m) at {where}"
            if hits_grid(grid, fp, p):
                raise ConfigError(f"{body} overlaps a wall or leaves the map",
                                  source=source, path=f"robots[{k}].{key}")
            j = first_obstacle_hit(index, fp, p)
            if j >= 0:
                ob = obstacles[j]
                raise ConfigError(f"{body} overlaps obstacle {ob.name!r} ({ob.model})",
                                  source=source, path=f"robots[{k}].{key}")


__all__ = ["MIN_GOAL_DISTANCE", "ONE_SPOT", "check_layout", "check_robot_bodies",
           "validate_against_map"]
