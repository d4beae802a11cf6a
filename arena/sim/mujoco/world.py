"""Build a 3-D world from a 2-D scene: walls, obstacle models, robots and human figures.

Usable on its own, without a simulator::

    scene = build_world(grid, obstacles, robots=[("robot", model, pose)], agents=spawn)
    xml = to_mjcf(scene)          # arena.sim.mujoco.mjcf
    sdf = to_sdf(scene)           # arena.sim.mujoco.sdf

Names the simulator uses to move things each step: ``robot/<name>`` (mocap body of each robot),
``person/<id>``, ``person/<id>/leg_l``, ``person/<id>/leg_r`` (see :mod:`.figures`); every
geom of a person is named ``person/<id>/<part>``, which gives per-pixel person ids.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from arena.core.errors import ConfigError, MapError
from arena.maps.obstacles import LIBRARY, CircleFootprint, obstacle_model
from arena.scene.episode import WAYPOINT_LOOP, AgentSpawn
from arena.scene.state import Obstacle
from arena.sim.mujoco.figures import figure_bodies
from arena.sim.mujoco.scene import Actor, Body, Geom, Scene3D, WorldParams
from arena.sim.mujoco.shapes import box, cylinder, obstacle_geoms
from arena.sim.mujoco.terrain import height_field, terrain_boxes
from arena.sim.mujoco.walls import merge_boxes

if TYPE_CHECKING:
    from arena.maps.grid import OccupancyGrid
    from arena.maps.terrain import HeightMap
    from arena.robots.model import RobotModel
    from arena.scene.episode import Episode

RobotPlacement = tuple[str, "RobotModel", ArrayLike]
"""``(name, model, pose [x, y, yaw])`` of one robot."""


def wall_body(grid: OccupancyGrid, params: WorldParams, *, source: str = "map") -> Body:
    """One static body holding the grid's walls as merged boxes ``wall/<k>`` (m).

    Raises:
        MapError: more boxes than ``params.max_wall_boxes`` (a map too large or too ragged).
    """
    rects = merge_boxes(grid.occupied)
    if len(rects) > params.max_wall_boxes:
        raise MapError(
            f"{source}: its walls need {len(rects):,} boxes in 3-D, more than "
            f"max_wall_boxes={params.max_wall_boxes:,} (a smaller or coarser map)"
        )
    res = grid.resolution
    ox, oy = grid.origin
    h = params.wall_height
    geoms = tuple(
        box(f"wall/{k}", ox + c0 * res, ox + c1 * res, oy + r0 * res, oy + r1 * res, 0.0, h, "wall")
        for k, (r0, c0, r1, c1) in enumerate(rects.tolist())
    )
    return Body("walls", "wall", (0.0, 0.0, 0.0), 0.0, geoms)


def obstacle_body(obstacle: Obstacle) -> Body:
    """A static body of the obstacle's library model, sized to its footprint and height.

    Raises:
        ConfigError: the model has no ``shape3d`` in the obstacle library.
    """
    model = obstacle_model(obstacle.model)
    if model.shape3d is None:
        raise ConfigError(
            f"{LIBRARY}: obstacle model {obstacle.model!r} has no field 'shape3d' (how to build "
            "it in 3-D), expected e.g. shape3d: {kind: box}"
        )
    fp = np.asarray(obstacle.footprint, dtype=np.float64)
    x0, y0 = fp.min(axis=0)
    x1, y1 = fp.max(axis=0)
    round_ = isinstance(model.footprint, CircleFootprint)
    if round_:  # the 16-gon's bounding box is a little inside the circle it stands for
        r = float(np.max(np.hypot(*fp.T)))
        x0, y0, x1, y1 = -r, -r, r, r
    parts = obstacle_geoms(model.shape3d, (float(x0), float(y0), float(x1), float(y1)), round_,
                           float(obstacle.height))
    name = f"obstacle/{obstacle.name}"
    geoms = tuple(Geom(f"{name}/{g.name}", g.type, g.size, g.pos, g.material) for g in parts)
    x, y, yaw = (float(v) for v in obstacle.pose)
    return Body(name, "obstacle", (x, y, 0.0), yaw, geoms)


def robot_height(model: RobotModel) -> float:
    """The model's body height (m), or a one-line :class:`ConfigError` when it has none."""
    if model.height is None:
        raise ConfigError(
            f"robot model {model.name!r}: field 'height' is not set, expected the body height "
            "in metres (add height: to the robot's YAML) to place it in a 3-D world"
        )
    return float(model.height)


def robot_body(name: str, model: RobotModel, pose: ArrayLike) -> Body:
    """The mocap body ``robot/<name>``: the footprint extruded to the model's height.

    Raises:
        ConfigError: the model has no height, or a footprint other than a circle or rectangle.
    """
    height = robot_height(model)
    poly = model.footprint_polygon()
    gname = f"robot/{name}/body"
    if poly is None:
        geom = cylinder(gname, 0.0, 0.0, model.circumscribed_radius, 0.0, height, "robot")
    else:
        x0, y0 = poly.min(axis=0)
        x1, y1 = poly.max(axis=0)
        corners = {(float(x), float(y)) for x, y in poly}
        if len(poly) != 4 or corners != {(x0, y0), (x1, y0), (x1, y1), (x0, y1)}:
            raise ConfigError(
                f"robot model {model.name!r}: field 'footprint' is a polygon that is not an "
                "axis-aligned rectangle; 3-D worlds expected a circle or a rectangle"
            )
        geom = box(gname, float(x0), float(x1), float(y0), float(y1), 0.0, height, "robot")
    x, y, yaw = (float(v) for v in np.asarray(pose, dtype=np.float64).reshape(3))
    return Body(f"robot/{name}", "robot", (x, y, 0.0), yaw, (geom,), mocap=True)


def _route(agents: AgentSpawn, i: int) -> tuple[tuple[float, float, float, float], ...]:
    """``((t, x, y, yaw), ...)`` from the start through the waypoints at the agent's ``vmax``."""
    pts = np.vstack([agents.positions[i], agents.waypoints[i, : agents.num_waypoints[i]]])
    if agents.waypoint_mode[i] == WAYPOINT_LOOP:
        pts = np.vstack([pts, pts[:1]])
    steps = np.diff(pts, axis=0)
    length = np.hypot(*steps.T)
    keep = np.concatenate([[True], length > 1e-9])  # repeated points add no waypoint
    pts, steps, length = pts[keep], steps[length > 1e-9], length[length > 1e-9]
    if len(length) == 0:
        return ()
    times = np.concatenate([[0.0], np.cumsum(length / agents.vmax[i])])
    yaws = np.arctan2(steps[:, 1], steps[:, 0])
    yaws = np.concatenate([yaws, yaws[-1:]])
    return tuple((float(t), float(x), float(y), float(a))
                 for t, (x, y), a in zip(times, pts, yaws, strict=True))


def build_world(
    grid: OccupancyGrid,
    obstacles: Sequence[Obstacle] = (),
    *,
    robots: Sequence[RobotPlacement] = (),
    agents: AgentSpawn | None = None,
    params: WorldParams | None = None,
    name: str = "arena",
    source: str = "map",
    terrain: HeightMap | None = None,
) -> Scene3D:
    """The 3-D world of a map with its obstacles, robots and pedestrians.

    Args:
        grid: the static map; its occupied cells become wall boxes ``params.wall_height`` tall.
        obstacles: placed library obstacles.
        robots: ``(name, model, pose)`` per robot; each model needs a ``height``.
        agents: pedestrians (start positions; people with ``vmax > 0`` and waypoints also get
            an :class:`~.scene.Actor` route for exporters).
        params: heights, lights and colours.
        name: the world's name.
        source: what to name in errors (a file, a generator).
        terrain: the ground's heights (m) on the map's cells, built as ``params.terrain`` says
            (:mod:`.terrain`); walls, obstacles and robots still stand at z = 0.

    Raises:
        MapError, ConfigError: see :func:`wall_body`, :func:`obstacle_body`, :func:`robot_body`;
            a height map that does not cover the map, or needs too many boxes.
    """
    params = params or WorldParams()
    ground = None
    if terrain is not None:
        terrain.check_covers(grid, what=f"height map of {source}")
        ground = (height_field(terrain) if params.terrain == "hfield"
                  else terrain_boxes(terrain, max_boxes=params.max_wall_boxes))
    static = (wall_body(grid, params, source=source), *(obstacle_body(o) for o in obstacles))
    robot_bodies = tuple(robot_body(n, m, p) for n, m, p in robots)
    people: list[Body] = []
    actors: list[Actor] = []
    if agents is not None:
        for i in range(len(agents)):
            x, y = (float(v) for v in agents.positions[i])
            first = agents.waypoints[i, 0] - agents.positions[i]
            heading = math.atan2(first[1], first[0]) if np.hypot(*first) > 1e-9 else 0.0
            people += figure_bodies(i, int(agents.kinds[i]), x, y, heading)
            route = _route(agents, i) if agents.vmax[i] > 0 else ()
            if route:
                actors.append(Actor(f"person_{i}", i, route,
                                    bool(agents.waypoint_mode[i] == WAYPOINT_LOOP)))
    ox, oy = grid.origin
    w, h = grid.size_m
    return Scene3D(name, (ox, oy, ox + w, oy + h), static, robot_bodies, tuple(people),
                   tuple(actors), params, ground)


def build_episode_world(episode: Episode, params: WorldParams | None = None) -> Scene3D:
    """The 3-D world of an episode: its map, obstacles, robots at their start poses and people."""
    robots = [(r.name, r.model, r.start.as_array()) for r in episode.robots]
    return build_world(episode.grid, episode.obstacles, robots=robots, agents=episode.agents,
                       params=params, name=episode.map_name, source=f"map {episode.map_name!r}")
