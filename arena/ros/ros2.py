"""The ROS 2 transport of a :class:`~arena.ros.link.RosLink`: rclpy publishers and subscriptions.

One rclpy context and one node (``arena``) per process, made on first use and shared by every
link the process opens (a benchmark worker runs many episodes); each link has its own
publishers, subscriptions and service, removed when it closes. Callbacks run only inside
:meth:`Ros2Transport.poll` (``spin_once`` on this thread), so the simulation never races them.

QoS: latched topics (``/map``, ``/tf_static``) and ``goal_pose`` (sent when it changes) are
reliable + transient local (depth 1), as Nav2's map server and tf2's static broadcaster; the
others reliable, volatile, depth 10.
Needs the ``arena[ros2]`` extra and ``tf2_msgs`` (``arena ros2 setup``, see
:mod:`arena.ros.ros2_env`).
"""

from __future__ import annotations

import array
import atexit
import importlib
from functools import cache
from typing import Any

import numpy as np

from arena.ros.link import RosLink
from arena.ros.messages import Fields, received_pose
from arena.ros.ros2_env import import_rclpy
from arena.ros.topics import Topic

#: array.array type codes of ROS 2 primitive sequences (filled from numpy bytes, no checks
#: per element).
_ARRAY_CODES = {"float": "f", "double": "d", "int8": "b", "uint8": "B", "octet": "B",
                "int16": "h", "uint16": "H", "int32": "i", "uint32": "I", "int64": "q",
                "uint64": "Q"}
_NUMPY = {"float": np.float32, "double": np.float64, "int8": np.int8, "uint8": np.uint8,
          "octet": np.uint8, "int16": np.int16, "uint16": np.uint16, "int32": np.int32,
          "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64}


@cache
def message_class(msgtype: str) -> Any:
    """The rclpy class of ``pkg/msg/Name`` (or ``pkg/Name``)."""
    parts = msgtype.split("/")
    pkg, name = parts[0], parts[-1]
    return getattr(importlib.import_module(f"{pkg}.msg"), name)


#: Field name -> ROS 2 type string, per message class.
_TYPES: dict[Any, dict[str, str]] = {}


def fill(msg: Any, fields: Fields) -> Any:
    """Set ``msg``'s fields from a :mod:`arena.ros.messages` dict; returns ``msg``.

    The dict holds nested dicts, lists of dicts and numpy arrays; fields it leaves out keep
    their zero value.
    """
    types = _TYPES.get(type(msg)) or _TYPES.setdefault(
        type(msg), dict(msg.get_fields_and_field_types()))
    for name, value in fields.items():
        kind = types[name]
        if isinstance(value, dict):
            fill(getattr(msg, name), value)
        elif kind.startswith("sequence<"):
            inner = kind[9:-1].split(",")[0]
            if inner in _ARRAY_CODES:
                data = np.ascontiguousarray(value, dtype=_NUMPY[inner])
                setattr(msg, name, array.array(_ARRAY_CODES[inner], data.tobytes()))
            elif "/" in inner:
                cls = message_class(inner)
                setattr(msg, name, [fill(cls(), v) for v in value])
            else:
                setattr(msg, name, list(value))
        elif kind.endswith("]"):  # a fixed array: numpy of its type
            base = kind[:kind.index("[")]
            setattr(msg, name, np.asarray(value, dtype=_NUMPY.get(base, np.float64)))
        elif kind in ("float", "double"):
            setattr(msg, name, float(value))
        elif kind == "boolean":
            setattr(msg, name, bool(value))
        elif kind in _NUMPY:
            setattr(msg, name, int(value))
        else:
            setattr(msg, name, value)
    return msg


class _Process:
    """The process's rclpy context, node and executor (made once, shut down at exit)."""

    node: Any = None
    executor: Any = None

    @classmethod
    def get(cls) -> tuple[Any, Any]:
        if cls.node is None:
            rclpy = import_rclpy()
            from rclpy.executors import SingleThreadedExecutor

            if not rclpy.ok():
                rclpy.init()
            cls.node = rclpy.create_node("arena")
            cls.executor = SingleThreadedExecutor()
            cls.executor.add_node(cls.node)
            atexit.register(cls.shutdown)
        return cls.node, cls.executor

    @classmethod
    def shutdown(cls) -> None:
        if cls.node is None:
            return
        import rclpy

        cls.executor.shutdown()
        cls.node.destroy_node()
        cls.node = cls.executor = None
        if rclpy.ok():
            rclpy.shutdown()



class Ros2Transport:
    """rclpy side of one :class:`~arena.ros.link.RosLink` (see the module doc).

    Subscribes ``<ns>/cmd_vel`` (``Twist``, or ``TwistStamped`` with ``cmd_vel_stamped``) and
    ``<ns>/goal_pose`` (``PoseStamped``); serves ``<ns>/arena/reset`` (``std_srvs/Trigger``).
    """

    def __init__(self, link: RosLink) -> None:
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from std_srvs.srv import Trigger

        self.node, self.executor = _Process.get()
        self.link = link
        self._latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                                   durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self._volatile = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._publishers: dict[str, Any] = {}
        opts = link.options
        stamped = opts.cmd_vel_stamped
        cmd_type = message_class("geometry_msgs/msg/TwistStamped" if stamped
                                 else "geometry_msgs/msg/Twist")
        self._subscriptions = [
            self.node.create_subscription(cmd_type, opts.name("/cmd_vel"),
                                          self._on_stamped if stamped else self._on_twist, 10),
            self.node.create_subscription(message_class("geometry_msgs/msg/PoseStamped"),
                                          opts.name("/goal_pose"), self._on_goal, 10),
        ]
        self._service = self.node.create_service(Trigger, opts.name("/arena/reset"),
                                                 self._on_reset)

    # -- Transport ------------------------------------------------------------------------------
    def advertise(self, topic: Topic, name: str) -> None:
        """Create the topic's publisher (once)."""
        if name not in self._publishers:
            keep = topic.latched or topic.kind == "goal"  # the goal: sent when it changes
            self._publishers[name] = self.node.create_publisher(
                message_class(topic.msgtype), name, self._latched if keep else self._volatile)

    def publish(self, topic: Topic, name: str, fields: Fields) -> None:
        """Fill and publish one message (the publisher made on first use)."""
        self.advertise(topic, name)
        self._publishers[name].publish(fill(message_class(topic.msgtype)(), fields))

    def subscribers(self, name: str) -> int:
        """The topic's subscription count (0 before it is advertised)."""
        pub = self._publishers.get(name)
        return 0 if pub is None else int(pub.get_subscription_count())

    def poll(self, timeout: float) -> None:
        """Run the callbacks ready within ``timeout`` s (one ``spin_once``)."""
        self.executor.spin_once(timeout_sec=max(0.0, timeout))

    def close(self) -> None:
        """Destroy this link's publishers, subscriptions and service."""
        if self.node is None:
            return
        for pub in self._publishers.values():
            self.node.destroy_publisher(pub)
        for sub in self._subscriptions:
            self.node.destroy_subscription(sub)
        self.node.destroy_service(self._service)
        self._publishers, self._subscriptions = {}, []
        self.node = None

    # -- callbacks ------------------------------------------------------------------------------
    def _on_twist(self, msg: Any) -> None:
        self.link.on_command(np.array([msg.linear.x, msg.linear.y, msg.angular.z]))

    def _on_stamped(self, msg: Any) -> None:
        t = msg.twist
        stamp = msg.header.stamp
        self.link.on_command(np.array([t.linear.x, t.linear.y, t.angular.z]),
                             stamp.sec * 1_000_000_000 + stamp.nanosec)

    def _on_goal(self, msg: Any) -> None:
        self.link.on_goal(received_pose(msg.pose))

    def _on_reset(self, request: Any, response: Any) -> Any:
        response.success, response.message = self.link.on_reset()
        return response
