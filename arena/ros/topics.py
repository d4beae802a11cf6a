"""The ROS topic and frame table of an episode: bags now, live ROS 1 / ROS 2 bridges later.

Names and frames follow REP 105 and Nav2's defaults, so a recorded bag plays into RViz, Foxglove
or a navigation stack without remapping:

==========================  ==============================  =======  ===========================
topic                       type (ROS 2 spelling)           rate     what
==========================  ==============================  =======  ===========================
/clock                      rosgraph_msgs/msg/Clock         step     simulated time (optional in
                                                                     bags: players make their own)
/tf_static                  tf2_msgs/msg/TFMessage          once     map → odom (identity),
                                                                     base_link → each lidar frame
/tf                         tf2_msgs/msg/TFMessage          step     odom → base_link
/map                        nav_msgs/msg/OccupancyGrid      once     the occupancy grid
/people/markers             visualization_msgs/msg/         step     people as cylinders coloured
                            MarkerArray                              by social state, headings,
                                                                     group links
/people/states              sensor_msgs/msg/PointCloud2     step     one point per person: x y z
                                                                     vx vy heading radius (float32)
                                                                     id kind state group (int32)
<ns>/odom                   nav_msgs/msg/Odometry           step     pose and body twist
<ns>/scan                   sensor_msgs/msg/LaserScan       lidar    the stack's (primary) lidar
<ns>/<sensor>/scan          sensor_msgs/msg/LaserScan       lidar    every other named lidar
<ns>/plan                   nav_msgs/msg/Path               step     the global plan (robot 0)
<ns>/local_plan             nav_msgs/msg/Path               step     the local planner's path
<ns>/goal_pose              geometry_msgs/msg/PoseStamped   step     the current goal (robot 0)
<ns>/cmd_vel                geometry_msgs/msg/Twist         step     the command of the step
==========================  ==============================  =======  ===========================

``step``: once per simulation step; ``lidar``: when the sensor takes a new reading (every
``1 / update_rate`` s, as the simulator holds a slower lidar's scan); ``once``: at time 0,
latched (ROS 1) / transient-local (ROS 2).

Frames: ``map`` → ``odom`` → ``base_link`` → ``<sensor>`` (``laser`` for Arena's robots).
Arena's robots know their true pose, so there is no odometry drift: ``odom`` coincides with
``map`` and the map → odom transform is the identity, published once on ``/tf_static``.

With more than one robot each robot has a namespace ``<ns>`` = ``/robot_<i>`` and its frames a
prefix ``robot_<i>/`` (``robot_1/odom``, ``robot_1/base_link``, ``robot_1/laser``) on the shared
``/tf``, ``/tf_static`` and ``map``, so one viewer shows every robot. With one robot ``<ns>`` is
empty and frames carry no prefix. ``/plan``, ``/local_plan`` and ``/goal_pose`` are robot 0's
(the episode's navigation stack drives robot 0).

People have no message in a base ROS install that carries positions with velocities
(``people_msgs`` is an extra package, and ``geometry_msgs/PoseArray`` has no velocity), so
``/people/states`` is a ``sensor_msgs/PointCloud2`` with named fields: one message per step keeps
each person's position, velocity, radius, id and social state together (no matching across
two topics by index), it exists unchanged in ROS 1 and ROS 2, RViz draws it, and
``sensor_msgs_py.point_cloud2.read_points`` (ROS 2) or ``sensor_msgs.point_cloud2`` (ROS 1)
read its fields by name.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from arena.live.frame import LiveScene

#: What a topic carries (the key :class:`~arena.ros.messages.RosMessages` produces it under).
Kind = Literal["clock", "tf_static", "tf", "map", "people_markers", "people_states", "odom",
               "scan", "plan", "local_plan", "goal", "cmd_vel"]

#: ROS 2 message type of each kind (ROS 1: :func:`ros1_type`).
MSG_TYPES: dict[str, str] = {
    "clock": "rosgraph_msgs/msg/Clock",
    "tf_static": "tf2_msgs/msg/TFMessage",
    "tf": "tf2_msgs/msg/TFMessage",
    "map": "nav_msgs/msg/OccupancyGrid",
    "people_markers": "visualization_msgs/msg/MarkerArray",
    "people_states": "sensor_msgs/msg/PointCloud2",
    "odom": "nav_msgs/msg/Odometry",
    "scan": "sensor_msgs/msg/LaserScan",
    "plan": "nav_msgs/msg/Path",
    "local_plan": "nav_msgs/msg/Path",
    "goal": "geometry_msgs/msg/PoseStamped",
    "cmd_vel": "geometry_msgs/msg/Twist",
}
#: Kinds sent once per episode at time 0 and kept for late subscribers.
LATCHED = ("tf_static", "map")
#: The world frame, shared by every robot.
MAP_FRAME = "map"


def ros1_type(msgtype: str) -> str:
    """``pkg/msg/Name`` (ROS 2) → ``pkg/Name`` (ROS 1)."""
    pkg, _, name = msgtype.split("/")
    return f"{pkg}/{name}"


@dataclass(frozen=True)
class RobotNames:
    """A robot's namespace and frame names.

    Attributes:
        namespace: topic prefix, ``""`` (one robot) or ``/robot_<i>``.
        odom, base: frame ids of its odometry frame and body.
        sensors: lidar sensor name → frame id.
        scan_topics: lidar sensor name → topic (the primary lidar's is ``<ns>/scan``).
    """

    namespace: str
    odom: str
    base: str
    sensors: dict[str, str]
    scan_topics: dict[str, str]


@dataclass(frozen=True)
class Topic:
    """One topic of the table.

    Attributes:
        name: the full topic name (``/robot_1/scan``).
        kind: what it carries (:data:`Kind`); its type is ``MSG_TYPES[kind]``.
        robot: the robot it belongs to, ``None`` for world topics.
        sensor: the lidar's sensor name for ``scan`` topics, else ``None``.
    """

    name: str
    kind: str
    robot: int | None = None
    sensor: str | None = None

    @property
    def msgtype(self) -> str:
        """ROS 2 message type (``sensor_msgs/msg/LaserScan``)."""
        return MSG_TYPES[self.kind]

    @property
    def latched(self) -> bool:
        """Sent once at time 0 and kept for late subscribers (transient local)."""
        return self.kind in LATCHED


def robot_names(scene: LiveScene, i: int) -> RobotNames:
    """Namespace, frames and scan topics of robot ``i`` of ``scene``."""
    multi = len(scene.robot_names) > 1
    ns = f"/robot_{i}" if multi else ""
    prefix = f"robot_{i}/" if multi else ""
    lidars = scene.lidars[i] if i < len(scene.lidars) else {}
    primary = scene.primary_lidars[i] if i < len(scene.primary_lidars) else None
    return RobotNames(
        namespace=ns, odom=f"{prefix}odom", base=f"{prefix}base_link",
        sensors={s: f"{prefix}{s}" for s in lidars},
        scan_topics={s: f"{ns}/scan" if s == primary else f"{ns}/{s}/scan" for s in lidars},
    )


def topic_table(scene: LiveScene, *, clock: bool = True) -> list[Topic]:
    """Every topic of ``scene``'s episode, world topics first, then per robot.

    Args:
        scene: the episode's scene (its robots and their lidars).
        clock: include ``/clock`` (a live bridge publishes it; a bag may leave it out).
    """
    table = [Topic("/clock", "clock")] if clock else []
    table += [Topic("/tf_static", "tf_static"), Topic("/tf", "tf"), Topic("/map", "map"),
              Topic("/people/markers", "people_markers"),
              Topic("/people/states", "people_states")]
    for i in range(len(scene.robot_names)):
        names = robot_names(scene, i)
        ns = names.namespace
        table.append(Topic(f"{ns}/odom", "odom", i))
        table += [Topic(t, "scan", i, s) for s, t in names.scan_topics.items()]
        if i == 0:
            table += [Topic(f"{ns}/plan", "plan", 0), Topic(f"{ns}/local_plan", "local_plan", 0),
                      Topic(f"{ns}/goal_pose", "goal", 0)]
        table.append(Topic(f"{ns}/cmd_vel", "cmd_vel", i))
    return table
