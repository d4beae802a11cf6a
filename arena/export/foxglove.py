"""Arena episodes in Foxglove's standard schemas: live over its WebSocket, or into MCAP files.

:class:`FoxgloveSink` is a :class:`~arena.live.hook.LiveSink`: it turns each scene and frame
into Foxglove messages on these topics (frames: ``map``, ``base_link``, ``laser``; other robots'
frames are prefixed with their name, ``<name>/base_link``):

============  =====================  ==========================================================
topic         schema                 what
============  =====================  ==========================================================
/map          foxglove.Grid          the occupancy grid (int8: 0 free, 100 occupied, -1 unknown)
/obstacles    foxglove.SceneUpdate   placed obstacles as outlines at their height
/robot        foxglove.SceneUpdate   each robot's footprint, locked to its base_link
/tf           foxglove.FrameTransforms  map → base_link per robot, base_link → laser
/scan         foxglove.LaserScan     robot 0's primary lidar, in its laser frame
/people       foxglove.SceneUpdate   people as cylinders coloured by social state, heading
                                     arrows, group links
/plan         foxglove.PosesInFrame  the global plan
/local_plan   foxglove.PosesInFrame  the path the local planner followed
/goal         foxglove.PoseInFrame   robot 0's goal
============  =====================  ==========================================================

Scene topics (``/map``, ``/obstacles``, ``/robot``) are logged once per episode; frame topics
with every frame. Message times are ``start_ns`` plus the simulated time, so an MCAP file's
timeline is the episode's. Needs the ``foxglove-sdk`` package (``pip install arena[web]``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from arena.core.errors import ConfigError
from arena.live.frame import LiveFrame, LiveScene
from arena.render.style import agent_state_color

#: Height of a drawn person (m) and of obstacle outlines without a height.
PERSON_HEIGHT = 1.7
#: Topic → Foxglove schema name, for documentation and tests.
TOPICS: dict[str, str] = {
    "/map": "foxglove.Grid",
    "/obstacles": "foxglove.SceneUpdate",
    "/robot": "foxglove.SceneUpdate",
    "/tf": "foxglove.FrameTransforms",
    "/scan": "foxglove.LaserScan",
    "/people": "foxglove.SceneUpdate",
    "/plan": "foxglove.PosesInFrame",
    "/local_plan": "foxglove.PosesInFrame",
    "/goal": "foxglove.PoseInFrame",
}
#: Topics logged once per episode (the rest with every frame).
SCENE_TOPICS = ("/map", "/obstacles", "/robot")


def foxglove_module() -> Any:
    """The ``foxglove`` package, or a one-line error naming the extra to install."""
    try:
        import foxglove
        import foxglove.channels
        import foxglove.messages
    except ImportError:
        raise ConfigError(
            "Foxglove output needs the foxglove-sdk package: pip install 'arena[web]'"
        ) from None
    return foxglove


class FoxgloveSink:
    """Logs scenes and frames on Foxglove channels of ``context`` (see the module doc).

    Args:
        context: the ``foxglove.Context`` its channels belong to (an MCAP writer's or a
            WebSocket server's); ``None``: the SDK's default context.
        rate: most frames per second of wall time (live servers); ``None``: every frame (files).
        start_ns: ns since the Unix epoch of simulated time 0 (``None``: the wall time of each
            scene, for live viewing).
        clock: wall clock (s), replaceable in tests.
    """

    def __init__(
        self,
        context: Any = None,
        *,
        rate: float | None = None,
        start_ns: int | None = 0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        fg = foxglove_module()
        self._m = fg.messages
        ch = fg.channels
        kinds = {
            "foxglove.Grid": ch.GridChannel, "foxglove.SceneUpdate": ch.SceneUpdateChannel,
            "foxglove.FrameTransforms": ch.FrameTransformsChannel,
            "foxglove.LaserScan": ch.LaserScanChannel,
            "foxglove.PosesInFrame": ch.PosesInFrameChannel,
            "foxglove.PoseInFrame": ch.PoseInFrameChannel,
        }
        self.channels = {t: kinds[s](t, context=context) for t, s in TOPICS.items()}
        self.rate = rate
        self._start_fixed = start_ns
        self._start = 0 if start_ns is None else int(start_ns)
        self._clock = clock
        self._last = -math.inf
        self._last_step = -1
        self._scene: LiveScene | None = None
        self.messages = 0
        """Messages logged (for tests and benchmarks)."""

    def close(self) -> None:
        """Close the channels (their context's sinks see no more messages)."""
        for channel in self.channels.values():
            channel.close()

    # -- LiveSink ---------------------------------------------------------------------------------
    def wants_frame(self, time: float) -> bool:
        """Every frame (files), or one per ``1 / rate`` s of wall time (live)."""
        return self.rate is None or self._clock() - self._last >= 1.0 / self.rate

    def scene(self, scene: LiveScene) -> None:
        """Log the scene topics (``/map``, ``/obstacles``, ``/robot``) at the episode's start."""
        self._scene, self._last_step = scene, -1
        if self._start_fixed is None:
            self._start = time.time_ns()
        m, ts, ns = self._m, self._stamp(0.0), self._ns(0.0)
        g = scene.grid
        self._log("/map", m.Grid(
            timestamp=ts, frame_id="map",
            pose=m.Pose(position=m.Vector3(x=g.origin[0], y=g.origin[1], z=0.0),
                        orientation=_quat(0.0)),
            column_count=g.width, cell_size=m.Vector2(x=g.resolution, y=g.resolution),
            row_stride=g.width, cell_stride=1,
            fields=[m.PackedElementField(name="occupancy", offset=0,
                                         type=m.PackedElementFieldNumericType.Int8)],
            data=np.ascontiguousarray(g.data, dtype=np.int8).tobytes(),
        ), ns)
        outlines = [self._line(np.column_stack([p, np.zeros(len(p))]), (0.45, 0.3, 0.15, 1.0),
                               loop=True) for p in scene.obstacles]
        self._log("/obstacles", m.SceneUpdate(entities=[m.SceneEntity(
            timestamp=ts, frame_id="map", id="obstacles", lines=outlines)]), ns)
        bodies = [m.SceneEntity(
            timestamp=ts, frame_id=self._base(i), id=f"robot/{name}", frame_locked=True,
            lines=[self._line(np.column_stack([fp, np.full(len(fp), 0.05)]),
                              (0.1, 0.35, 0.8, 1.0), loop=True)])
            for i, (name, fp) in enumerate(zip(scene.robot_names, scene.footprints, strict=True))]
        self._log("/robot", m.SceneUpdate(entities=bodies), ns)

    def frame(self, frame: LiveFrame, *, last: bool = False) -> None:
        """Log the frame topics at the frame's time."""
        scene = self._scene
        if scene is None or frame.step == self._last_step:
            return  # the last frame repeats the last step's (with its outcome): logged once
        self._last, self._last_step = self._clock(), frame.step
        m, ts, ns = self._m, self._stamp(frame.time), self._ns(frame.time)
        transforms = [m.FrameTransform(
            timestamp=ts, parent_frame_id="map", child_frame_id=self._base(i),
            translation=m.Vector3(x=float(p[0]), y=float(p[1]), z=0.0),
            rotation=_quat(float(p[2]))) for i, p in enumerate(frame.poses)]
        lidar = scene.lidar
        if lidar is not None:
            transforms.append(m.FrameTransform(
                timestamp=ts, parent_frame_id=self._base(0), child_frame_id="laser",
                translation=m.Vector3(x=float(lidar.mount[0]), y=float(lidar.mount[1]), z=0.0),
                rotation=_quat(float(lidar.mount[2]))))
        self._log("/tf", m.FrameTransforms(transforms=transforms), ns)
        if lidar is not None and frame.scan.size:
            angles = lidar.angles()
            self._log("/scan", m.LaserScan(
                timestamp=ts, frame_id="laser", pose=_identity(m),
                start_angle=float(angles[0]), end_angle=float(angles[-1]),
                ranges=np.nan_to_num(frame.scan, posinf=lidar.range_max).tolist()), ns)
        self._log("/people", m.SceneUpdate(entities=[self._people(frame, ts)]), ns)
        self._log("/plan", self._poses(frame.plan, ts), ns)
        self._log("/local_plan", self._poses(frame.local_path, ts), ns)
        if frame.goal is not None:
            g = frame.goal
            self._log("/goal", m.PoseInFrame(timestamp=ts, frame_id="map", pose=m.Pose(
                position=m.Vector3(x=float(g[0]), y=float(g[1]), z=0.0),
                orientation=_quat(float(g[2])))), ns)

    # -- messages ---------------------------------------------------------------------------------
    def _people(self, frame: LiveFrame, ts: Any) -> Any:
        m, p = self._m, frame.people
        cylinders, arrows = [], []
        for k in range(len(p)):
            x, y = float(p.positions[k, 0]), float(p.positions[k, 1])
            r, h = float(p.radii[k]), float(p.headings[k])
            cr, cg, cb = agent_state_color(int(p.states[k]))
            colour = m.Color(r=cr, g=cg, b=cb, a=0.9)
            cylinders.append(m.CylinderPrimitive(
                pose=m.Pose(position=m.Vector3(x=x, y=y, z=PERSON_HEIGHT / 2),
                            orientation=_quat(0.0)),
                size=m.Vector3(x=2 * r, y=2 * r, z=PERSON_HEIGHT),
                bottom_scale=1.0, top_scale=1.0, color=colour))
            arrows.append(m.ArrowPrimitive(
                pose=m.Pose(position=m.Vector3(x=x, y=y, z=PERSON_HEIGHT),
                            orientation=_quat(h)),
                shaft_length=0.4, shaft_diameter=0.05, head_length=0.15, head_diameter=0.12,
                color=colour))
        links = []
        for gid in np.unique(frame.groups[frame.groups >= 0]):
            members = p.positions[frame.groups == gid]
            if len(members) > 1:
                pts = np.column_stack([members, np.full(len(members), PERSON_HEIGHT)])
                links.append(self._line(pts, (0.3, 0.3, 0.3, 0.8), loop=len(members) > 2))
        return m.SceneEntity(timestamp=ts, frame_id="map", id="people", cylinders=cylinders,
                             arrows=arrows, lines=links,
                             metadata=[m.KeyValuePair(key="count", value=str(len(p)))])

    def _poses(self, path: np.ndarray, ts: Any) -> Any:
        m = self._m
        heading = np.zeros(len(path))
        if len(path) > 1:
            d = np.diff(path, axis=0)
            heading[:-1] = np.arctan2(d[:, 1], d[:, 0])
            heading[-1] = heading[-2]
        return m.PosesInFrame(timestamp=ts, frame_id="map", poses=[
            m.Pose(position=m.Vector3(x=float(x), y=float(y), z=0.0), orientation=_quat(float(a)))
            for (x, y), a in zip(path, heading, strict=True)])

    def _line(self, points: np.ndarray, rgba: tuple[float, float, float, float], *,
              loop: bool) -> Any:
        m = self._m
        kind = m.LinePrimitiveLineType.LineLoop if loop else m.LinePrimitiveLineType.LineStrip
        return m.LinePrimitive(
            type=kind, pose=_identity(m), thickness=0.05, scale_invariant=False,
            points=[m.Point3(x=float(a), y=float(b), z=float(c)) for a, b, c in points],
            color=m.Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3]))

    def _base(self, i: int) -> str:
        assert self._scene is not None
        return "base_link" if i == 0 else f"{self._scene.robot_names[i]}/base_link"

    def _ns(self, t: float) -> int:
        return self._start + round(t * 1e9)

    def _stamp(self, t: float) -> Any:
        ns = self._ns(t)
        return self._m.Timestamp(ns // 1_000_000_000, ns % 1_000_000_000)

    def _log(self, topic: str, message: Any, ns: int) -> None:
        self.channels[topic].log(message, log_time=ns)
        self.messages += 1


def _quat(yaw: float) -> Any:
    import foxglove.messages as m

    return m.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def _identity(m: Any) -> Any:
    return m.Pose(position=m.Vector3(x=0.0, y=0.0, z=0.0), orientation=_quat(0.0))
