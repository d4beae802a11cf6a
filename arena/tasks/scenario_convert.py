"""Scenario files into a run: pedestrians drawn as agents, obstacles and the episode.

Reads a validated :class:`arena.tasks.scenario.Scenario`; the file schema and its loading live
in :mod:`arena.tasks.scenario`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from arena.core.errors import ConfigError, UnknownNameError
from arena.core.rng import derive_rng
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import make_obstacle
from arena.robots.model import RobotModel
from arena.scene.episode import (
    AgentSpawn,
    Episode,
    RobotSpawn,
)
from arena.scene.state import Obstacle
from arena.tasks.scenario import (
    DEFAULT_VMAX,
    KIND_CODES,
    STARTUP_CODES,
    Param,
    Pedestrian,
    Scenario,
    _model_name,
    _pose3,
    _unique,
)
from arena.tasks.scenario_checks import DEFAULT_PED_RADIUS


def _draw(value: Param | None, default: float, rng: np.random.Generator) -> float:
    """A number, or Arena's draw from N((lo+hi)/2, (hi−lo)/6) clipped to [lo, hi]."""
    if value is None:
        return default
    if isinstance(value, tuple):
        lo, hi = value
        return float(np.clip(rng.normal((lo + hi) / 2, (hi - lo) / 6), lo, hi))
    return float(value)



def scenario_agents(peds: Sequence[Pedestrian], rng: np.random.Generator) -> AgentSpawn:
    """The scenario's dynamic obstacles as pedestrians (``vmax`` ranges drawn from ``rng``)."""
    n = len(peds)
    if n == 0:
        return AgentSpawn.empty()
    k = max(max(len(p.waypoints) for p in peds), 1)
    waypoints = np.full((n, k, 2), np.nan)
    num = np.ones(n, dtype=np.int64)
    for i, p in enumerate(peds):
        # No waypoints: the one waypoint is the start, so the pedestrian stays where it is.
        pts = [w[:2] for w in p.waypoints] or [p.pos[:2]]
        waypoints[i, : len(pts)] = pts
        num[i] = len(pts)
    modes = np.array([p.effective_waypoint_mode for p in peds], dtype=np.int64)
    custom_start = any(p.start_up_mode not in (None, "default") for p in peds)
    return AgentSpawn(
        positions=np.array([p.pos[:2] for p in peds], dtype=np.float64),
        radii=np.full(n, DEFAULT_PED_RADIUS),
        vmax=np.array([_draw(p.vmax, DEFAULT_VMAX, rng) for p in peds]),
        waypoints=waypoints,
        num_waypoints=num,
        waypoint_mode=modes,
        kinds=np.array([KIND_CODES.get(p.kind, 0) for p in peds], dtype=np.int64),
        startup_mode=np.array(
            [STARTUP_CODES[p.start_up_mode or "default"] for p in peds], dtype=np.int64
        )
        if custom_start
        else None,
        wait_time=np.array([p.wait_time or 0.0 for p in peds]) if custom_start else None,
        trigger_radius=np.array([p.trigger_zone_radius or 0.0 for p in peds])
        if custom_start
        else None,
    )


def scenario_obstacles(scenario: Scenario) -> list[Obstacle]:
    """The scenario's static and interactive obstacles with library footprints.

    Raises:
        UnknownNameError: a model not in the obstacle library, naming the entry
            (``obstacles.static[2].model``) and the known models.
    """
    taken: set[str] = set()
    obstacles: list[Obstacle] = []
    for group in ("static", "interactive"):
        for i, o in enumerate(getattr(scenario.obstacles, group)):
            try:
                obstacles.append(
                    make_obstacle(_unique(o.name, taken), _model_name(o.model), _pose3(o.pos))
                )
            except UnknownNameError as e:
                raise e.located(prefix=f"obstacles.{group}[{i}].model") from None
    return obstacles


def scenario_episode(
    scenario: Scenario,
    grid: OccupancyGrid,
    robots: Sequence[RobotModel],
    *,
    index: int = 0,
    seed: int = 0,
    time_limit: float,
    goal_radius: float = 0.3,
    map_name: str | None = None,
) -> Episode:
    """Build the :class:`Episode` a scenario describes.

    As in Arena, scenario robots beyond ``len(robots)`` are dropped; fewer scenario robots than
    ``robots`` is an error. Pedestrians get radius :data:`DEFAULT_PED_RADIUS`, ``vmax``
    :data:`DEFAULT_VMAX` unless set (``[lo, hi]`` ranges are drawn from the episode's seed), and
    kind codes from ``type``; pedsim-only overrides (force factors, chat probabilities ...) have
    no counterpart in :class:`AgentSpawn` and are not used.

    Args:
        scenario: the loaded scenario.
        grid: the map (not checked here; see
            :func:`~arena.tasks.scenario_checks.validate_against_map`).
        robots: the robot models, in scenario order.
        index: episode number.
        seed: the episode's seed.
        time_limit: s.
        goal_radius: m.
        map_name: label for reports (default: the scenario's ``map`` key, else ``scenario``).

    Raises:
        ConfigError: too few robots in the scenario, or an obstacle model not in the library
            (the message lists the known models).
    """
    if len(scenario.robots) < len(robots):
        raise ConfigError(
            f"the scenario has {len(scenario.robots)} robot(s) but {len(robots)} robot model(s) "
            "were given; add start/goal entries or run fewer robots",
            path="robots",
        )
    spawns = tuple(
        RobotSpawn(
            f"robot{k}" if len(robots) > 1 else model.name,
            model,
            Pose2D.from_array(_pose3(entry.start)),
            Pose2D.from_array(_pose3(entry.goal)),
        )
        for k, (model, entry) in enumerate(zip(robots, scenario.robots, strict=False))
    )
    obstacles = scenario_obstacles(scenario)
    rng = derive_rng(seed, "episode", index, "scenario")
    return Episode(
        index=index,
        seed=seed,
        map_name=map_name or scenario.map or "scenario",
        grid=grid,
        obstacles=tuple(obstacles),
        robots=spawns,
        agents=scenario_agents(scenario.obstacles.dynamic, rng),
        time_limit=time_limit,
        goal_radius=goal_radius,
    )
