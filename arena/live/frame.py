"""What a live viewer is shown of a running episode: its scene once, then one frame per update.

A :class:`LiveScene` is the static part of an episode (map, placed obstacles, robot bodies, the
lidar's geometry); a :class:`LiveFrame` is one moment (robot poses, goal, global plan and the
path the local planner followed, the lidar's hit points, the people with their social states
and groups, contacts). Both are built from the :class:`~arena.episode.runner.EpisodeRunner`
only, so every viewer (the web app's canvas, Foxglove, MCAP files) shows the same thing.

:func:`scene_json` and :func:`frame_json` turn them into the compact JSON the web app's canvas
draws (coordinates rounded to millimetres; the map as a PNG in base64).
"""

from __future__ import annotations

import base64
import io
import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from arena.crowd.state import SocialState
from arena.maps.grid import OccupancyGrid
from arena.render import style
from arena.render.style import agent_state_color
from arena.scene.state import AgentStates
from arena.sensors.spec import LidarSpec, lidar_geometry

if TYPE_CHECKING:
    from arena.episode.runner import EpisodeRunner

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Points of the circle drawn for a round robot body.
CIRCLE_POINTS = 24


@dataclass(frozen=True, eq=False)
class LiveScene:
    """The static part of an episode.

    Attributes:
        episode: episode index; label: its stage or scenario label ("" if none).
        map_name: the map's label.
        dt: s, simulation step; time_limit: s.
        grid: the occupancy grid.
        obstacles: per placed obstacle its ``(k, 2)`` world polygon (m).
        robot_names, robot_models: per robot.
        footprints: per robot its ``(k, 2)`` body-frame polygon (m; a circle as
            :data:`CIRCLE_POINTS` points for a round robot).
        lidar: robot 0's primary 2-D lidar, or ``None``.
        lidars: per robot its 2-D lidars by sensor name (insertion-ordered; empty without).
        primary_lidars: per robot the name of its primary lidar (the stack's), or ``None``.
    """

    episode: int
    label: str
    map_name: str
    dt: float
    time_limit: float
    grid: OccupancyGrid
    obstacles: tuple[FloatArray, ...]
    robot_names: tuple[str, ...]
    robot_models: tuple[str, ...]
    footprints: tuple[FloatArray, ...]
    lidar: LidarSpec | None
    lidars: tuple[Mapping[str, LidarSpec], ...] = ()
    primary_lidars: tuple[str | None, ...] = ()


@dataclass(frozen=True, eq=False)
class LiveFrame:
    """One moment of an episode.

    Attributes:
        time: s since reset; step: simulation steps since reset.
        poses: ``(r, 3)`` robot poses ``[x m, y m, theta rad]``.
        twists: ``(r, 3)`` body twists ``[vx m/s, vy m/s, omega rad/s]``.
        goal: ``(3,)`` robot 0's current goal, or ``None``.
        plan: ``(k, 2)`` m, the global plan (empty without one).
        local_path: ``(m, 2)`` m, the path the local planner followed (the intermediate
            planner's output; the plan itself without one).
        subgoal: ``(2,)`` m, the end of the intermediate planner's path when it differs from the
            plan (Arena's subgoal), else ``None``.
        scan: ``(beams,)`` m, robot 0's primary lidar ranges (empty without a lidar).
        scan_points: ``(n, 2)`` m, world positions of the beams that hit something.
        people: the pedestrians (positions, headings, radii, kinds, social states).
        groups: ``(n,)`` group id per pedestrian, -1 alone.
        collision: ``(r,)`` bool, each robot touches something.
        outcome: how the episode ended, on its last frame; ``None`` while it runs.
        commands: ``(r, 3)`` each robot's command of the last step ``[vx m/s, vy m/s,
            omega rad/s]`` (before limits), or ``None``.
        lidar_scans: per robot its lidars' latest ranges by sensor name (m, ``(beams,)``
            each; the names of :attr:`LiveScene.lidars`).
    """

    time: float
    step: int
    poses: FloatArray
    twists: FloatArray
    goal: FloatArray | None
    plan: FloatArray
    local_path: FloatArray
    subgoal: FloatArray | None
    scan: FloatArray
    scan_points: FloatArray
    people: AgentStates
    groups: IntArray
    collision: NDArray[np.bool_]
    outcome: str | None = None
    commands: FloatArray | None = None
    lidar_scans: tuple[Mapping[str, FloatArray], ...] = ()


def circle_polygon(radius: float, n: int = CIRCLE_POINTS) -> FloatArray:
    """``(n, 2)`` points on a circle of ``radius`` m around the origin."""
    a = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return np.stack([radius * np.cos(a), radius * np.sin(a)], axis=1)


def scene_of(runner: EpisodeRunner) -> LiveScene:
    """The scene of the runner's current episode (after its reset)."""
    episode, state = runner.episode, runner.state
    assert episode is not None
    assert state is not None
    world = runner.backend.world
    footprints = tuple(
        np.asarray(fp, dtype=np.float64) if fp is not None else circle_polygon(float(r))
        for fp, r in zip(state.robots.footprints, state.robots.radii, strict=True)
    )
    return LiveScene(
        episode=int(episode.index), label=episode.label, map_name=episode.map_name,
        dt=float(runner.dt), time_limit=float(episode.time_limit), grid=world.grid,
        obstacles=tuple(np.asarray(o.polygon, dtype=np.float64) for o in world.obstacles),
        robot_names=tuple(state.robots.names), robot_models=tuple(state.robots.models),
        footprints=footprints, lidar=episode.robots[0].model.laser,
        lidars=tuple(
            MappingProxyType({k: v for k, v in r.model.sensors.items() if isinstance(v, LidarSpec)})
            for r in episode.robots),
        primary_lidars=tuple(r.model.primary_lidar for r in episode.robots),
    )


def scan_points(scan: FloatArray, pose: FloatArray, lidar: LidarSpec | None) -> FloatArray:
    """``(n, 2)`` world positions of the beams of ``scan`` that hit something (m)."""
    if lidar is None or scan.size == 0:
        return np.zeros((0, 2))
    angles, origin = lidar_geometry(lidar)
    hit = np.isfinite(scan) & (scan < lidar.range_max - 1e-6) & (scan >= lidar.range_min)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    ox, oy = pose[0] + c * origin[0] - s * origin[1], pose[1] + s * origin[0] + c * origin[1]
    r, a = scan[hit], angles[hit] + pose[2]
    return np.stack([ox + r * np.cos(a), oy + r * np.sin(a)], axis=1)


def frame_of(runner: EpisodeRunner, scene: LiveScene) -> LiveFrame:
    """The runner's current moment.

    The plan, the local path and the goal come from the runner's controller when it is the
    navigation controller (anything with ``stack`` and ``goal``); the groups from its crowd
    driver when that keeps a crowd state with groups (every crowd-simulator model).
    """
    state = runner.state
    assert state is not None
    robots = state.robots
    nav = runner.controller
    stack = getattr(nav, "stack", None)
    goal = getattr(nav, "goal", None)
    plan = np.asarray(stack.path if stack is not None else np.zeros((0, 2)), dtype=np.float64)
    local = np.asarray(
        getattr(stack, "intermediate_path", plan) if stack is not None else plan, dtype=np.float64
    )
    same = local.shape == plan.shape and np.array_equal(local, plan)
    subgoal = None if same or not len(local) else local[-1].copy()
    scan = np.asarray(robots.scans[0], dtype=np.float64) if robots.scans else np.zeros(0)
    n = len(state.agents)
    crowd_state = getattr(runner.crowd, "state", None) if runner.crowd is not None else None
    group = getattr(crowd_state, "group", None)
    groups = (np.asarray(group, dtype=np.int64) if group is not None and len(group) == n
              else np.full(n, -1, dtype=np.int64))
    return LiveFrame(
        time=float(state.time), step=int(state.step), poses=robots.poses.copy(),
        twists=robots.twists.copy(),
        goal=None if goal is None else goal.as_array(),
        plan=plan, local_path=local, subgoal=subgoal, scan=scan,
        scan_points=scan_points(scan, robots.poses[0], scene.lidar), people=state.agents,
        groups=groups, collision=np.asarray(state.collisions.any, dtype=bool).copy(),
        outcome=None if runner.outcome is None else runner.outcome.value,
        commands=robots.commands.copy(),
        lidar_scans=tuple(
            MappingProxyType({k: np.asarray(readings[k], dtype=np.float64) for k in lidars
                              if k in readings})
            for readings, lidars in zip(robots.sensors, scene.lidars, strict=False)),
    )


# -- JSON for the web app's canvas ------------------------------------------------------------
def _mm(a: Any) -> Any:
    """Nested lists of ``a`` rounded to millimetres (JSON-ready)."""
    return np.round(np.asarray(a, dtype=np.float64), 3).tolist()


def _hex(rgb: tuple[float, float, float]) -> str:
    return "#" + "".join(f"{round(255 * c):02x}" for c in rgb)


def grid_png(grid: OccupancyGrid) -> bytes:
    """The grid as a greyscale PNG, north up (free white, occupied black, unknown grey)."""
    from PIL import Image

    img = np.full(grid.data.shape, 205, dtype=np.uint8)
    img[grid.data == 0] = 255
    img[grid.data == 100] = 0
    buf = io.BytesIO()
    Image.fromarray(img[::-1]).save(buf, format="PNG", optimize=True)
    return buf.getvalue()


def scene_json(scene: LiveScene) -> dict[str, Any]:
    """The scene as JSON-ready data (the map as a base64 PNG, row 0 at the top)."""
    g = scene.grid
    return {
        "type": "scene", "episode": scene.episode, "label": scene.label,
        "map_name": scene.map_name, "dt": scene.dt, "time_limit": scene.time_limit,
        "map": {"width": g.width, "height": g.height, "resolution": g.resolution,
                "origin": list(g.origin),
                "png": base64.b64encode(grid_png(g)).decode("ascii")},
        "obstacles": [_mm(p) for p in scene.obstacles],
        "robots": [{"name": n, "model": m, "footprint": _mm(fp)} for n, m, fp in
                   zip(scene.robot_names, scene.robot_models, scene.footprints, strict=True)],
        "states": [s.name.lower() for s in SocialState],
        # the videos' colours, so a live view and a video read alike
        "state_colors": [_hex(agent_state_color(s)) for s in SocialState],
        "kind_colors": [_hex(c) for c in style.AGENT_KIND_COLORS],
        "robot_colors": [_hex(style.robot_color(i)) for i in range(len(scene.robot_names))],
        "collision_color": _hex(style.COLLISION),
    }


def frame_json(frame: LiveFrame) -> dict[str, Any]:
    """The frame as JSON-ready data; people as columns (``x``, ``y``, ``heading`` ...)."""
    p = frame.people
    return {
        "type": "frame", "time": round(frame.time, 6), "step": frame.step,
        "poses": _mm(frame.poses), "twists": _mm(frame.twists),
        "goal": None if frame.goal is None else _mm(frame.goal),
        "plan": _mm(frame.plan), "local_path": _mm(frame.local_path),
        "subgoal": None if frame.subgoal is None else _mm(frame.subgoal),
        "scan": _mm(frame.scan_points),
        "people": {
            "id": p.ids.tolist(), "x": _mm(p.positions[:, 0]), "y": _mm(p.positions[:, 1]),
            "heading": _mm(p.headings), "radius": _mm(p.radii), "kind": p.kinds.tolist(),
            "state": p.states.tolist(), "group": frame.groups.tolist(),
        },
        "collision": frame.collision.tolist(), "outcome": frame.outcome,
    }
