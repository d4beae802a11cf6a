"""The moving layers of a frame (lidar, trails, paths, goals, people, robots, perceived people).

Each function fills matplotlib artists created once by :class:`~arena.render.frames.FrameRenderer`
with one state's data (the renderer then blits them onto the static background).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.collections import LineCollection, PathCollection, PolyCollection
from matplotlib.text import Text
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.core.geometry import regular_polygon, transform_points
from arena.render import style
from arena.scene.state import AgentStates, RobotStates
from arena.sensors.spec import LidarSpec

if TYPE_CHECKING:
    from arena.render.frames import Overlay

FloatArray = NDArray[np.float64]

ROBOT_CIRCLE_SIDES = 40
"""Sides of the polygon drawn for a circular robot."""


def set_lidar(
    fans_art: PolyCollection, hits_art: PathCollection, robots: RobotStates,
    lidar_specs: Sequence[LidarSpec | None], show: bool,
) -> None:
    """The scanned areas (translucent fans) and hit points of the robots with a lidar spec."""
    fans: list[FloatArray] = []
    fan_colors: list[tuple[float, float, float, float]] = []
    hits: list[FloatArray] = []
    hit_colors: list[style.RGB] = []
    if show:
        for i in range(len(robots)):
            spec = lidar_specs[i] if i < len(lidar_specs) else None
            if spec is None or i >= len(robots.scans):
                continue
            ranges = np.asarray(robots.scans[i], dtype=np.float64).reshape(-1)
            if ranges.size != spec.num_beams:
                raise ConfigError(
                    f"robot {robots.names[i]!r}: scan has {ranges.size} beams but its "
                    f"LidarSpec has num_beams={spec.num_beams}"
                )
            origin, ends, hit = _scan_points(robots.poses[i], spec, ranges)
            color = style.robot_color(i)
            # The scanned area as one translucent polygon: one path instead of one line per
            # beam keeps a 1000-beam scan as cheap to draw as a pedestrian.
            fans.append(ends if spec.full_circle else np.vstack([origin[None], ends]))
            fan_colors.append((*color, style.LIDAR_FAN_ALPHA))
            hits.append(ends[hit])
            hit_colors.extend([style.shade(color, 0.8)] * int(hit.sum()))
    fans_art.set_verts(fans)
    fans_art.set_facecolors(fan_colors if fan_colors else "none")
    pts = np.concatenate(hits) if hits else np.zeros((0, 2))
    hits_art.set_offsets(pts)
    hits_art.set_facecolors(hit_colors if hit_colors else "none")


def set_trails(
    coll: LineCollection, robots: RobotStates, ov: Overlay, recorded: Sequence[FloatArray],
    show: bool,
) -> None:
    """Each robot's past positions: the overlay's trails, else the ``(r, 2)`` recorded ones."""
    segs: list[FloatArray] = []
    colors: list[style.RGB] = []
    if not show:
        pass
    elif ov.trails is not None:
        for i, tr in enumerate(ov.trails):
            if tr is not None and len(tr) >= 2:
                segs.append(np.asarray(tr, dtype=np.float64)[:, :2])
                colors.append(style.shade(style.robot_color(i), style.TRAIL_TINT))
    elif len(recorded) >= 2:
        hist = np.stack(tuple(recorded))  # (k, r, 2)
        for i in range(min(hist.shape[1], len(robots))):
            segs.append(hist[:, i])
            colors.append(style.shade(style.robot_color(i), style.TRAIL_TINT))
    coll.set_segments(segs)
    coll.set_color(colors if colors else "none")


def set_paths(coll: LineCollection, ov: Overlay) -> None:
    """The overlay's paths, one colour per robot."""
    segs: list[FloatArray] = []
    colors: list[style.RGB] = []
    for i, path in enumerate(ov.paths or ()):
        if path is None:
            continue
        p = np.asarray(path, dtype=np.float64).reshape(-1, np.shape(path)[-1])[:, :2]
        if len(p) >= 2:
            segs.append(p)
            colors.append(style.robot_color(i))
    coll.set_segments(segs)
    coll.set_color(colors if colors else "none")


def set_goals(
    marks_art: PathCollection, arrows_art: PolyCollection, subgoals_art: PathCollection,
    arrow: FloatArray, ov: Overlay,
) -> None:
    """Goal rings, goal heading arrows (``arrow``: the arrow polygon, m) and subgoals."""
    marks = np.zeros((0, 2))
    mark_colors: list[style.RGB] = []
    arrows: list[FloatArray] = []
    arrow_colors: list[style.RGB] = []
    if ov.goals is not None:
        g = np.atleast_2d(np.asarray(ov.goals, dtype=np.float64))
        ok = np.all(np.isfinite(g[:, :2]), axis=1)
        marks = g[ok, :2]
        mark_colors = [style.robot_color(i) for i in np.flatnonzero(ok)]
        if g.shape[1] >= 3:
            for i in np.flatnonzero(ok & np.isfinite(g[:, 2])):
                arrows.append(transform_points(arrow, g[i, :3]))
                arrow_colors.append(style.robot_color(int(i)))
    marks_art.set_offsets(marks)
    marks_art.set_edgecolors(mark_colors if mark_colors else "none")
    arrows_art.set_verts(arrows)
    arrows_art.set_facecolors(arrow_colors if arrow_colors else "none")
    arrows_art.set_edgecolors([style.shade(c, 0.6) for c in arrow_colors] or "none")

    subs = np.zeros((0, 2))
    sub_colors: list[style.RGB] = []
    if ov.subgoals is not None:
        sg = np.atleast_2d(np.asarray(ov.subgoals, dtype=np.float64))
        ok = np.all(np.isfinite(sg[:, :2]), axis=1)
        subs = sg[ok, :2]
        sub_colors = [style.shade(style.robot_color(i), 1.35) for i in np.flatnonzero(ok)]
    subgoals_art.set_offsets(subs)
    subgoals_art.set_facecolors(sub_colors if sub_colors else "none")


def set_agents(
    bodies: PolyCollection, ticks_art: LineCollection, circle: FloatArray, agents: AgentStates
) -> None:
    """The people: discs (``circle``: a unit polygon) coloured by social state and kind."""
    n = len(agents)
    if n == 0:
        bodies.set_verts([])
        ticks_art.set_segments([])
        return
    pos = np.asarray(agents.positions, dtype=np.float64)
    rad = np.asarray(agents.radii, dtype=np.float64)
    verts = pos[:, None, :] + rad[:, None, None] * circle[None]
    bodies.set_verts(verts)
    bodies.set_facecolors(style.palette(style.AGENT_STATE_COLORS, agents.states))
    edge = style.palette(style.AGENT_KIND_COLORS, agents.kinds)
    bodies.set_edgecolors(edge)
    head = np.asarray(agents.headings, dtype=np.float64)
    direction = np.stack([np.cos(head), np.sin(head)], axis=-1)
    ticks = np.stack([pos, pos + 1.3 * rad[:, None] * direction], axis=1)  # (n, 2, 2)
    ticks_art.set_segments(ticks)
    ticks_art.set_color(edge)


def set_robots(
    bodies: PolyCollection, heading: LineCollection, robots: RobotStates,
    colliding: NDArray[np.bool_], px: Callable[[float], float],
) -> None:
    """The robots' footprints (red edge while in contact) and heading lines."""
    polys: list[FloatArray] = []
    heads: list[FloatArray] = []
    faces: list[style.RGB] = []
    edges: list[style.RGB] = []
    widths: list[float] = []
    for i in range(len(robots)):
        pose = np.asarray(robots.poses[i], dtype=np.float64)
        fp = robots.footprints[i] if i < len(robots.footprints) else None
        radius = float(robots.radii[i])
        if fp is None:
            body = regular_polygon(radius, ROBOT_CIRCLE_SIDES)
            front = radius
        else:
            body = np.asarray(fp, dtype=np.float64)
            # The heading line ends at the footprint's front-most point along body x.
            front = max(float(body[:, 0].max()), 1e-3)
        polys.append(transform_points(body, pose))
        heads.append(transform_points(np.array([[0.0, 0.0], [front, 0.0]]), pose))
        color = style.robot_color(i)
        faces.append(color)
        hit = bool(colliding[i]) if i < colliding.size else False
        edges.append(style.COLLISION if hit else style.shade(color, 0.55))
        widths.append(px(style.COLLISION_EDGE_PX if hit else style.ROBOT_EDGE_PX))
    bodies.set_verts(polys)
    bodies.set_facecolors(faces if faces else "none")
    bodies.set_edgecolors(edges if edges else "none")
    bodies.set_linewidths(widths if widths else [0.0])
    heading.set_segments(heads)


def _scan_points(
    pose: FloatArray, spec: LidarSpec, ranges: FloatArray
) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """Sensor origin ``(2,)``, beam end points ``(n, 2)`` and hit mask ``(n,)`` in the world.

    Beams at (or beyond) ``range_max`` and non-finite ranges hit nothing: they reach full length
    (bounding the scanned area) but are not drawn as hit points.
    """
    mount = np.asarray(spec.mount, dtype=np.float64)
    origin = transform_points(mount[None, :2], pose)[0]
    yaw = float(pose[2]) + float(mount[2])
    finite = np.isfinite(ranges)
    r = np.where(finite, np.minimum(ranges, spec.range_max), spec.range_max)
    hit = finite & (ranges < spec.range_max - 1e-6)
    ang = yaw + spec.angles()
    ends = origin + r[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    return origin, ends, hit


def set_perception(
    dets_art: PathCollection, tracks_art: PathCollection, labels: Sequence[Text], ov: Overlay,
    label_offset: float,
) -> None:
    """Detected people (crosses) and tracks (rings coloured by id, labelled with the id).

    ``label_offset`` (m) puts an id label up and right of its ring; tracks beyond the label
    pool (:data:`~arena.render.style.MAX_TRACK_LABELS`) keep their ring without a label.
    """
    dets = np.zeros((0, 2)) if ov.detections is None else np.asarray(
        ov.detections, dtype=np.float64).reshape(-1, 2)
    dets_art.set_offsets(dets)
    ids = np.zeros(0, dtype=np.int64)
    pos = np.zeros((0, 2))
    if ov.tracks is not None:
        ids = np.asarray(ov.tracks[0], dtype=np.int64).reshape(-1)
        pos = np.asarray(ov.tracks[1], dtype=np.float64).reshape(-1, 2)
    tracks_art.set_offsets(pos)
    colors = style.palette(style.TRACK_COLORS, ids)
    tracks_art.set_edgecolors(colors)
    for k, label in enumerate(labels):
        if k < len(ids):
            label.set_position((pos[k, 0] + label_offset, pos[k, 1] + label_offset))
            label.set_text(str(int(ids[k])))
            label.set_color(colors[k])
            label.set_visible(True)
        else:
            label.set_visible(False)
