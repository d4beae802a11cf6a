"""The ROS 1 transport of a :class:`~arena.ros.link.RosLink`: rospy publishers and subscribers.

One rospy node per process (rospy allows one ``init_node``), named ``arena`` (``arena_<pid>_...``
when a node of that name is already registered, as in a benchmark's parallel workers: the
master would otherwise shut the first one down), made on first use with
``disable_signals=True`` and shared by every link the process opens; each link has its own
publishers and subscribers, unregistered when it closes (the reset service is offered once per
name and answered by the latest open link of that namespace). rospy runs callbacks in its
own threads: goals and resets go to the link from there (thread-safe); commands wait for
:meth:`Ros1Transport.poll`, on the link's thread, as rclpy's callbacks do.

Publishers are latched for ``/map``, ``/tf_static`` and ``goal_pose`` (sent when it changes), as
map_server and tf's static broadcaster do, so a late subscriber gets them. Each ``publish``
serializes and writes to the subscribers' sockets on the calling thread (``queue_size=None``):
in lock-step the next frame waits for the command anyway, and a queue thread per topic only
adds a hand-over to each message's way out (2,100 instead of 2,800 lock-step steps/s on
loopback with one ``/odom`` + ``/plan`` subscriber). The ``cmd_vel`` subscriber asks for
``tcp_nodelay`` (Nagle's algorithm would hold a small Twist up to 40 ms); an external node
should ask for it on ``/scan`` and ``/odom`` too.

Simulated time: ``/clock`` carries each step's time for nodes with ``use_sim_time``; Arena's own
node stamps every message from the simulation, so it never reads ROS time and needs no
``use_sim_time`` itself. Needs Debian's ROS 1 (:mod:`arena.ros.ros1_env`).
"""

from __future__ import annotations

import atexit
import importlib
import threading
import warnings
from functools import cache
from typing import Any, ClassVar

import numpy as np

from arena.ros.link import RosLink
from arena.ros.messages import Fields, received_pose
from arena.ros.ros1_env import check_master, import_rospy, master_has_node
from arena.ros.topics import Topic, ros1_type

#: The process's node name (``arena_<pid>_<ms>`` when taken).
NODE_NAME = "arena"
#: numpy dtypes of genpy's primitive array elements (``uint8[]`` / ``char[]`` go as bytes).
_NUMPY = {"int8": np.int8, "byte": np.int8, "int16": np.int16, "uint16": np.uint16,
          "int32": np.int32, "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64,
          "float32": np.float32, "float64": np.float64, "bool": np.bool_}
_BYTES = ("uint8", "char")
_SCALAR = {"string": str, "bool": bool, "float32": float, "float64": float}


@cache
def message_class(msgtype: str) -> Any:
    """The genpy class of ``pkg/Name`` (or ROS 2's ``pkg/msg/Name``)."""
    parts = msgtype.split("/")
    return getattr(importlib.import_module(f"{parts[0]}.msg"), parts[-1])


@cache
def _slots(cls: Any) -> dict[str, str]:
    """Field name → genpy type (``float32[]``, ``std_msgs/Header``, ``time``) of ``cls``."""
    return dict(zip(cls.__slots__, cls._slot_types, strict=True))


def fill(msg: Any, fields: Fields) -> Any:
    """Set genpy message ``msg``'s fields from a :mod:`arena.ros.messages` dict; returns ``msg``.

    The dicts use ROS 2's field names, which are ROS 1's for every type Arena sends except a
    time's ``sec`` / ``nanosec`` (``rospy.Time(secs, nsecs)``). Fields the dict leaves out
    (``header.seq``, which rospy numbers) keep genpy's zero values. Numeric arrays become
    lists (genpy packs them with ``struct``), ``uint8[]`` bytes.

    Raises:
        KeyError: a field ``msg``'s type does not have (a typo, never skipped).
    """
    types = _slots(msg.__class__)
    for name, value in fields.items():
        kind = types.get(name)
        if kind is None:
            raise KeyError(f"{msg._type} has no field {name!r}")
        setattr(msg, name, _value(getattr(msg, name), kind, value))
    return msg


def _value(current: Any, kind: str, value: Any) -> Any:
    if kind in ("time", "duration"):
        cls = _time_class(kind)
        return cls(int(value["sec"]), int(value["nanosec"]))
    if kind.endswith("]"):
        base = kind[:kind.index("[")]
        if base in _BYTES:
            return np.ascontiguousarray(value, dtype=np.uint8).tobytes()
        if base in _NUMPY:
            return np.asarray(value, dtype=_NUMPY[base]).tolist()
        if base == "string":
            return [str(v) for v in value]
        cls = message_class(base)
        return [fill(cls(), v) for v in value]
    if "/" in kind:
        return fill(current, value)
    return _SCALAR.get(kind, int)(value)


@cache
def _time_class(kind: str) -> Any:
    """The ``Time`` or ``Duration`` class of rospy (genpy's, with rospy's conversions)."""
    rospy = import_rospy()
    return rospy.Time if kind == "time" else rospy.Duration



class _Process:
    """The process's rospy node (made once; rospy shuts it down at exit) and its services.

    rospy lets a node offer a service name once, but a process may hold two links of one
    namespace (two planner configurations, or a benchmark's contestants, in one worker): each
    service is offered once and answered by the latest open link that asked for it.
    """

    rospy: Any = None
    _lock = threading.Lock()
    _services: ClassVar[dict[str, tuple[Any, list[Ros1Transport]]]] = {}

    @classmethod
    def get(cls) -> Any:
        if cls.rospy is None:
            rospy = import_rospy()
            if not rospy.core.is_initialized():
                check_master()
                # a second node of one name makes the master shut the first one down
                taken = master_has_node(f"/{NODE_NAME}")
                rospy.init_node(NODE_NAME, argv=[NODE_NAME], anonymous=taken,
                                disable_signals=True)
                atexit.register(rospy.signal_shutdown, "arena exits")
            cls.rospy = rospy
        return cls.rospy

    @classmethod
    def serve_reset(cls, name: str, transport: Ros1Transport) -> None:
        """Let ``transport`` answer the ``std_srvs/Trigger`` service ``name``."""
        from std_srvs.srv import Trigger

        with cls._lock:
            if name not in cls._services:
                service = cls.rospy.Service(name, Trigger, lambda req: cls._answer(name, req))
                cls._services[name] = (service, [])
            cls._services[name][1].append(transport)

    @classmethod
    def unserve_reset(cls, name: str, transport: Ros1Transport) -> None:
        """``transport`` no longer answers ``name``; the last one gone, the service goes."""
        with cls._lock:
            service, users = cls._services[name]
            users.remove(transport)
            if not users:
                del cls._services[name]
                service.shutdown("link closed")

    @classmethod
    def _answer(cls, name: str, request: Any) -> Any:
        with cls._lock:
            transport = cls._services[name][1][-1]
        return transport._on_reset(request)


class Ros1Transport:
    """rospy side of one :class:`~arena.ros.link.RosLink` (see the module doc).

    Subscribes ``<ns>/cmd_vel`` (``geometry_msgs/Twist``, or ``TwistStamped`` with
    ``cmd_vel_stamped``) and ``<ns>/goal_pose`` (``PoseStamped``); serves
    ``<ns>/arena/reset`` (``std_srvs/Trigger``).

    Raises:
        ConfigError: no ROS 1 installed, or no master at ``ROS_MASTER_URI``.
    """

    def __init__(self, link: RosLink) -> None:
        rospy = _Process.get()
        from std_srvs.srv import TriggerResponse

        self.link = link
        self._node = rospy.get_name()  # before the subscribers: their callbacks read it
        self._response = TriggerResponse
        self._arrived = threading.Event()
        self._lock = threading.Lock()
        self._pending: list[tuple[np.ndarray, int | None]] = []  # commands for the next poll
        self._publishers: dict[str, Any] = {}
        opts = link.options
        stamped = opts.cmd_vel_stamped
        cmd_type = message_class("geometry_msgs/TwistStamped" if stamped
                                 else "geometry_msgs/Twist")
        self._subscribers = [
            rospy.Subscriber(opts.name("/cmd_vel"), cmd_type,
                             self._on_stamped if stamped else self._on_twist,
                             queue_size=10, tcp_nodelay=True),
            rospy.Subscriber(opts.name("/goal_pose"), message_class("geometry_msgs/PoseStamped"),
                             self._on_goal, queue_size=10),
        ]
        self._service = opts.name("/arena/reset")
        _Process.serve_reset(self._service, self)
        self._rospy: Any = rospy

    # -- Transport ------------------------------------------------------------------------------
    def advertise(self, topic: Topic, name: str) -> None:
        """Create the topic's publisher (once)."""
        if name not in self._publishers:
            keep = topic.latched or topic.kind == "goal"  # the goal: sent when it changes
            with warnings.catch_warnings():  # rospy warns of queue_size=None (see module doc)
                warnings.simplefilter("ignore", SyntaxWarning)
                self._publishers[name] = self._rospy.Publisher(
                    name, message_class(ros1_type(topic.msgtype)), latch=keep, queue_size=None)

    def publish(self, topic: Topic, name: str, fields: Fields) -> None:
        """Fill and publish one message (the publisher made on first use)."""
        self.advertise(topic, name)
        self._publishers[name].publish(fill(message_class(ros1_type(topic.msgtype))(), fields))

    def subscribers(self, name: str) -> int:
        """The topic's connected subscribers other than this node (0 before it is advertised).

        rospy connects a node's subscriber to its own publisher of the topic (``cmd_vel``,
        ``goal_pose``): that connection is no external listener.
        """
        pub = self._publishers.get(name)
        if pub is None:
            return 0
        n = int(pub.get_num_connections())
        return n - 1 if n and pub.impl.has_connection(self._node) else n

    def poll(self, timeout: float) -> None:
        """Hand the commands received so far to the link, or wait up to ``timeout`` s for one.

        Without a pending command it waits for a command, goal or reset and hands it over.
        Commands reach the link only here, on the link's thread, as with rclpy: a node may
        answer a frame while the link is still sending it (rospy delivers on its own
        threads), and counting that answer against the frames sent *before* it would make
        the link wait for another one.
        """
        if not self._deliver() and timeout > 0 and self._arrived.wait(timeout):
            self._deliver()

    def _deliver(self) -> bool:
        """Pass the pending commands to the link, oldest first; whether anything arrived."""
        with self._lock:
            pending, self._pending = self._pending, []
            arrived = self._arrived.is_set()
            self._arrived.clear()
        for command, stamp_ns in pending:
            self.link.on_command(command, stamp_ns)
        return arrived

    def close(self) -> None:
        """Unregister this link's publishers, subscribers and service."""
        if self._rospy is None:
            return
        for pub in self._publishers.values():
            pub.unregister()
        for sub in self._subscribers:
            sub.unregister()
        _Process.unserve_reset(self._service, self)
        self._publishers, self._subscribers, self._rospy = {}, [], None

    # -- callbacks (rospy's threads) ----------------------------------------------------------
    def _own(self, msg: Any) -> bool:
        """``msg`` came from this node (the link's echo of its own command or goal)."""
        return bool(getattr(msg, "_connection_header", {}).get("callerid") == self._node)

    def _on_twist(self, msg: Any) -> None:
        if self._own(msg):
            return
        self._command(np.array([msg.linear.x, msg.linear.y, msg.angular.z]), None)

    def _on_stamped(self, msg: Any) -> None:
        if self._own(msg):
            return
        t, stamp = msg.twist, msg.header.stamp
        self._command(np.array([t.linear.x, t.linear.y, t.angular.z]),
                      int(stamp.secs) * 1_000_000_000 + int(stamp.nsecs))

    def _command(self, command: np.ndarray, stamp_ns: int | None) -> None:
        with self._lock:
            self._pending.append((command, stamp_ns))
            self._arrived.set()

    def _on_goal(self, msg: Any) -> None:
        if self._own(msg):
            return
        self.link.on_goal(received_pose(msg.pose))
        self._arrived.set()

    def _on_reset(self, request: Any) -> Any:
        success, message = self.link.on_reset()
        self._arrived.set()
        return self._response(success=success, message=message)
