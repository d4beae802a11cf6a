"""An episode's scene and frames as ROS message field values, without any ROS library.

Each message is a plain nested ``dict`` keyed by the ROS 2 field names (``header.stamp.sec``,
``header.stamp.nanosec``); numeric arrays are numpy arrays of the field's type (``ranges``
float32, ``data`` int8 / uint8, covariances float64). A bag writer fills rosbags' classes from
them (:mod:`arena.ros.bag`); a live rclpy bridge fills its own with
``rosidl_runtime_py.set_message_fields``; a rospy bridge the same way, reading ``stamp.sec`` /
``nanosec`` as ROS 1's ``secs`` / ``nsecs`` and leaving ``header.seq`` to rospy. Fields a message
type has in one ROS version only (ROS 1's ``seq``, ROS 2 Marker's textures) are left out and
take their zero value.

:class:`RosMessages` follows one episode: :meth:`~RosMessages.scene` gives the latched messages
at time 0, :meth:`~RosMessages.frame` each step's, on the topics of
:func:`arena.ros.topics.topic_table`.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from arena.core.types import Pose2D
from arena.live.frame import LiveFrame, LiveScene
from arena.render.style import agent_state_color
from arena.ros.topics import MAP_FRAME, RobotNames, Topic, robot_names, topic_table
from arena.sensors.spec import LidarSpec

Fields = dict[str, Any]
#: One message to send: its topic, its time (ns of simulated time) and its field values.
Message = tuple[Topic, int, Fields]

#: Height (m) of a person's cylinder marker.
PERSON_HEIGHT = 1.7
#: Marker actions and types (the same numbers in ROS 1 and ROS 2).
MARKER_ARROW, MARKER_CYLINDER, MARKER_LINE_LIST = 0, 3, 5
MARKER_ADD, MARKER_DELETEALL = 0, 3
#: sensor_msgs/PointField datatypes.
POINT_INT32, POINT_FLOAT32 = 5, 7
#: ``/people/states`` point layout: little-endian float32 then int32 fields, 44 bytes a point.
PEOPLE_DTYPE = np.dtype([
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("vx", "<f4"), ("vy", "<f4"),
    ("heading", "<f4"), ("radius", "<f4"),
    ("id", "<i4"), ("kind", "<i4"), ("state", "<i4"), ("group", "<i4"),
])


# -- building blocks --------------------------------------------------------------------------
def sim_ns(t: float) -> int:
    """Simulated time ``t`` (s) in integer ns, as the bags' record times."""
    return round(t * 1e9)


def stamp(ns: int) -> Fields:
    """``builtin_interfaces/Time`` of ``ns`` nanoseconds."""
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def header(ns: int, frame_id: str) -> Fields:
    """``std_msgs/Header``."""
    return {"stamp": stamp(ns), "frame_id": frame_id}


def vector(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Fields:
    """``geometry_msgs/Vector3`` (or ``Point``)."""
    return {"x": float(x), "y": float(y), "z": float(z)}


def yaw_quaternion(yaw: float) -> Fields:
    """``geometry_msgs/Quaternion`` of a rotation by ``yaw`` rad about z."""
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}


def quaternion_yaw(q: Any) -> float:
    """Yaw (rad) of a received ``geometry_msgs/Quaternion`` (any object with x, y, z, w)."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def received_pose(msg: Any) -> Pose2D:
    """The planar pose of a received ``geometry_msgs/Pose``."""
    p = msg.position
    return Pose2D(float(p.x), float(p.y), quaternion_yaw(msg.orientation))


def pose(x: float, y: float, yaw: float, z: float = 0.0) -> Fields:
    """``geometry_msgs/Pose`` of a planar pose."""
    return {"position": vector(x, y, z), "orientation": yaw_quaternion(float(yaw))}


def transform(ns: int, parent: str, child: str, x: float, y: float, yaw: float) -> Fields:
    """``geometry_msgs/TransformStamped``: ``child``'s planar pose in ``parent``."""
    return {"header": header(ns, parent), "child_frame_id": child,
            "transform": {"translation": vector(x, y), "rotation": yaw_quaternion(float(yaw))}}


def path(ns: int, points: np.ndarray) -> Fields:
    """``nav_msgs/Path`` in ``map`` through ``points`` ``(k, 2)`` m, each facing the next."""
    heading = np.zeros(len(points))
    if len(points) > 1:
        d = np.diff(points, axis=0)
        heading[:-1] = np.arctan2(d[:, 1], d[:, 0])
        heading[-1] = heading[-2]
    return {"header": header(ns, MAP_FRAME), "poses": [
        {"header": header(ns, MAP_FRAME), "pose": pose(x, y, a)}
        for (x, y), a in zip(points.tolist(), heading.tolist(), strict=True)]}


def occupancy_grid(scene: LiveScene, ns: int) -> Fields:
    """``nav_msgs/OccupancyGrid`` of the scene's map (row 0 at the origin, as in Arena)."""
    g = scene.grid
    return {"header": header(ns, MAP_FRAME), "info": {
        "map_load_time": stamp(ns), "resolution": float(g.resolution),
        "width": int(g.width), "height": int(g.height),
        "origin": pose(g.origin[0], g.origin[1], 0.0)},
        "data": np.ascontiguousarray(g.data, dtype=np.int8).ravel()}


def laser_scan(spec: LidarSpec, ranges: np.ndarray, ns: int, frame_id: str) -> Fields:
    """``sensor_msgs/LaserScan`` of ``ranges`` ``(beams,)`` m in the sensor's frame.

    ``angle_max`` is the last beam's angle (a full-circle scan does not repeat its first beam,
    so it stops one increment short of ``angle_min + 2π``).
    """
    inc = spec.angle_increment
    return {"header": header(ns, frame_id), "angle_min": spec.angle_min,
            "angle_max": spec.angle_min + inc * (spec.num_beams - 1), "angle_increment": inc,
            "time_increment": 0.0, "scan_time": 1.0 / spec.update_rate,
            "range_min": spec.range_min, "range_max": spec.range_max,
            "ranges": np.asarray(ranges, dtype=np.float32),
            "intensities": np.zeros(0, dtype=np.float32)}


def odometry(frame: LiveFrame, i: int, names: RobotNames, ns: int) -> Fields:
    """``nav_msgs/Odometry`` of robot ``i``: pose in ``odom`` (= map), body twist.

    The covariances are zero: the simulator's pose and twist are exact.
    """
    p, v = frame.poses[i], frame.twists[i]
    return {"header": header(ns, names.odom), "child_frame_id": names.base,
            "pose": {"pose": pose(p[0], p[1], p[2]), "covariance": np.zeros(36)},
            "twist": {"twist": {"linear": vector(v[0], v[1]), "angular": vector(z=v[2])},
                      "covariance": np.zeros(36)}}


def people_markers(frame: LiveFrame, ns: int) -> Fields:
    """``visualization_msgs/MarkerArray`` of the people.

    A delete-all first, then per person a cylinder coloured by social state (ns ``people``,
    id = the person's id) and a heading arrow (``people/heading``), and the links within each
    group (``people/groups``).
    """
    p = frame.people
    h = header(ns, MAP_FRAME)
    markers: list[Fields] = [{"header": h, "ns": "people", "id": 0, "action": MARKER_DELETEALL}]
    for k in range(len(p)):
        x, y = float(p.positions[k, 0]), float(p.positions[k, 1])
        r, pid = float(p.radii[k]), int(p.ids[k])
        cr, cg, cb = agent_state_color(int(p.states[k]))
        colour = {"r": cr, "g": cg, "b": cb, "a": 0.9}
        markers.append({"header": h, "ns": "people", "id": pid, "type": MARKER_CYLINDER,
                        "action": MARKER_ADD, "pose": pose(x, y, 0.0, PERSON_HEIGHT / 2),
                        "scale": vector(2 * r, 2 * r, PERSON_HEIGHT), "color": colour})
        markers.append({"header": h, "ns": "people/heading", "id": pid, "type": MARKER_ARROW,
                        "action": MARKER_ADD,
                        "pose": pose(x, y, float(p.headings[k]), PERSON_HEIGHT),
                        "scale": vector(0.5, 0.08, 0.08), "color": colour})
    links = []
    for gid in np.unique(frame.groups[frame.groups >= 0]).tolist():
        members = p.positions[frame.groups == gid]
        for a, b in itertools.pairwise(members):
            links += [vector(a[0], a[1], PERSON_HEIGHT), vector(b[0], b[1], PERSON_HEIGHT)]
    if links:
        markers.append({"header": h, "ns": "people/groups", "id": 0, "type": MARKER_LINE_LIST,
                        "action": MARKER_ADD, "pose": pose(0.0, 0.0, 0.0),
                        "scale": vector(0.05), "color": {"r": 0.3, "g": 0.3, "b": 0.3, "a": 0.8},
                        "points": links})
    return {"markers": markers}


def people_states(frame: LiveFrame, ns: int) -> Fields:
    """``sensor_msgs/PointCloud2`` of the people, one point of :data:`PEOPLE_DTYPE` each."""
    p = frame.people
    pts = np.zeros(len(p), dtype=PEOPLE_DTYPE)
    pts["x"], pts["y"] = p.positions[:, 0], p.positions[:, 1]
    pts["vx"], pts["vy"] = p.velocities[:, 0], p.velocities[:, 1]
    pts["heading"], pts["radius"] = p.headings, p.radii
    pts["id"], pts["kind"], pts["state"], pts["group"] = p.ids, p.kinds, p.states, frame.groups
    names = PEOPLE_DTYPE.names or ()
    fields = [{"name": n, "offset": PEOPLE_DTYPE.fields[n][1],  # type: ignore[index]
               "datatype": POINT_FLOAT32 if PEOPLE_DTYPE[n].kind == "f" else POINT_INT32,
               "count": 1} for n in names]
    return {"header": header(ns, MAP_FRAME), "height": 1, "width": len(p), "fields": fields,
            "is_bigendian": False, "point_step": PEOPLE_DTYPE.itemsize,
            "row_step": PEOPLE_DTYPE.itemsize * len(p),
            "data": np.frombuffer(pts.tobytes(), dtype=np.uint8), "is_dense": True}


def twist(command: np.ndarray) -> Fields:
    """``geometry_msgs/Twist`` of a command ``[vx m/s, vy m/s, omega rad/s]``."""
    return {"linear": vector(command[0], command[1]), "angular": vector(z=command[2])}


# -- one episode ------------------------------------------------------------------------------
class RosMessages:
    """Turns one episode's scene and frames into the messages of its topic table.

    Args:
        clock: publish ``/clock`` with every step.

    A lidar's scan is sent when the sensor takes a new reading: at reset, then whenever
    ``1 / update_rate`` s have passed since its last one (the simulator's own rule), so a 10 Hz
    lidar in a 20 Hz simulation sends every other step.
    """

    def __init__(self, *, clock: bool = True) -> None:
        self.clock = clock
        self.table: list[Topic] = []
        self._scene: LiveScene | None = None
        self._names: list[RobotNames] = []
        self._last_step = -1
        self._last_scan: dict[str, float] = {}

    def scene(self, scene: LiveScene) -> list[Message]:
        """Start an episode: its topic table, and the latched ``/tf_static`` and ``/map``."""
        self._scene, self._last_step, self._last_scan = scene, -1, {}
        self.table = topic_table(scene, clock=self.clock)
        self._names = [robot_names(scene, i) for i in range(len(scene.robot_names))]
        by_kind = {t.kind: t for t in self.table if t.robot is None}
        static = []
        for i, names in enumerate(self._names):
            static.append(transform(0, MAP_FRAME, names.odom, 0.0, 0.0, 0.0))
            lidars = scene.lidars[i] if i < len(scene.lidars) else {}
            for sensor, frame_id in names.sensors.items():
                mx, my, myaw = lidars[sensor].mount
                static.append(transform(0, names.base, frame_id, mx, my, myaw))
        return [(by_kind["tf_static"], 0, {"transforms": static}),
                (by_kind["map"], 0, occupancy_grid(scene, 0))]

    def frame(self, frame: LiveFrame, *, only: set[str] | None = None,
              repeat: bool = False) -> list[Message]:
        """The messages of one step (none for a repeat of the last step's frame).

        Args:
            frame: the step.
            only: build only the topics of these names (``None``: all).
            repeat: build a repeat of the last step too (a live bridge sends it again to a
                node that subscribed late).
        """
        scene = self._scene
        if scene is None or (frame.step == self._last_step and not repeat):
            return []  # the episode's last frame repeats its last step (with the outcome)
        if repeat and frame.step == self._last_step:
            self._last_scan = {k: t for k, t in self._last_scan.items() if t < frame.time}
        self._last_step = frame.step
        ns = sim_ns(frame.time)
        out: list[Message] = []
        for topic in self.table:
            if only is not None and topic.name not in only:
                continue
            fields = self._message(topic, scene, frame, ns)
            if fields is not None:
                out.append((topic, ns, fields))
        return out

    def _message(self, topic: Topic, scene: LiveScene, frame: LiveFrame,
                 ns: int) -> Fields | None:
        """``topic``'s message of ``frame``, or ``None`` when it has none this step."""
        kind, i = topic.kind, topic.robot or 0  # world topics: i unused
        names = self._names[i]
        if kind == "clock":
            return {"clock": stamp(ns)}
        if kind == "tf":
            return {"transforms": [transform(ns, n.odom, n.base, *frame.poses[k])
                                   for k, n in enumerate(self._names)]}
        if kind == "people_markers":
            return people_markers(frame, ns)
        if kind == "people_states":
            return people_states(frame, ns)
        if kind == "odom":
            return odometry(frame, i, names, ns)
        if kind == "scan":
            return self._scan(scene, frame, i, topic.sensor or "", names, ns)
        if kind in ("plan", "local_plan"):
            return path(ns, frame.plan if kind == "plan" else frame.local_path)
        if kind == "goal" and frame.goal is not None:
            g = frame.goal
            return {"header": header(ns, MAP_FRAME), "pose": pose(g[0], g[1], g[2])}
        if kind == "cmd_vel" and frame.commands is not None:
            return twist(frame.commands[i])
        return None

    def _scan(self, scene: LiveScene, frame: LiveFrame, i: int, sensor: str,
              names: RobotNames, ns: int) -> Fields | None:
        spec = scene.lidars[i][sensor]
        readings = frame.lidar_scans[i] if i < len(frame.lidar_scans) else {}
        if sensor not in readings:
            return None
        key = f"{i}/{sensor}"
        last = self._last_scan.get(key)
        if last is not None and frame.time - last < 1.0 / spec.update_rate - 1e-9:
            return None  # the sensor holds its last reading: no new scan yet
        self._last_scan[key] = frame.time
        return laser_scan(spec, readings[sensor], ns, names.sensors[sensor])
