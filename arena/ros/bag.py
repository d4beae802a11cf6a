"""ROS bags of an episode, written with the pure-Python ``rosbags`` library (Apache-2.0).

``rosbags`` writes both formats Arena exports, so one code path serves them: ROS 1 bags
(format 2.0, what ``rosbag play`` and ``rosbag`` read) and ROS 2 bags with MCAP storage (a
folder with ``<name>.mcap`` and ``metadata.yaml``, version 8: ROS 2 Jazzy and later). Messages
are serialized by rosbags' own serializers (ROS 1 and CDR) from its bundled message definitions
(Noetic and Jazzy), so no ROS install is needed.

:class:`RosbagSink` is a :class:`~arena.live.hook.LiveSink`: it turns scenes and frames into
messages with :class:`~arena.ros.messages.RosMessages` and writes them with
:class:`BagWriter`. Needs the ``rosbags`` package (``pip install 'arena[rosbag]'``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal

import numpy as np

from arena.core.errors import ConfigError
from arena.live.frame import LiveFrame, LiveScene
from arena.ros.messages import Fields, RosMessages
from arena.ros.topics import Topic

Flavour = Literal["ros1", "ros2"]
#: ROS 2 bag metadata version written (8: readable by ROS 2 Jazzy and later).
ROSBAG2_VERSION: Literal[8] = 8
#: The caller id a ROS 1 bag names as each topic's publisher.
CALLER_ID = "/arena"
#: ROS 1's tf2_msgs/TFMessage, which rosbags' Noetic store does not bundle.
TF_MESSAGE_ROS1 = "geometry_msgs/TransformStamped[] transforms\n"

_NUMPY = {"bool": np.bool_, "byte": np.uint8, "char": np.uint8, "octet": np.uint8,
          "int8": np.int8, "uint8": np.uint8, "int16": np.int16, "uint16": np.uint16,
          "int32": np.int32, "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64,
          "float32": np.float32, "float64": np.float64}


def rosbags_module() -> Any:
    """The ``rosbags`` package, or a one-line error naming the extra to install."""
    try:
        import rosbags
        import rosbags.rosbag1
        import rosbags.rosbag2
        import rosbags.typesys
    except ImportError:
        raise ConfigError(
            "ROS bag output needs the rosbags package: pip install 'arena[rosbag]'") from None
    return rosbags


def typestore(flavour: Flavour) -> Any:
    """The rosbags message store for ``flavour`` (Noetic + tf2_msgs/TFMessage, or Jazzy)."""
    rosbags_module()
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    if flavour == "ros2":
        return get_typestore(Stores.ROS2_JAZZY)
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(TF_MESSAGE_ROS1, "tf2_msgs/msg/TFMessage"))
    return store


def build_message(store: Any, msgtype: str, fields: Mapping[str, Any]) -> Any:
    """An instance of rosbags' class for ``msgtype`` filled from ``fields`` (nested dicts).

    Fields missing from ``fields`` take their zero value (ROS 1's ``header.seq``, ROS 2-only
    Marker fields); an unknown field raises ``KeyError`` naming it (a typo, never skipped).
    """
    defs = store.fielddefs[msgtype][1]
    known = {name for name, _ in defs}
    unknown = [k for k in fields if k not in known]
    if unknown:
        raise KeyError(f"{msgtype} has no field {unknown[0]!r}")
    return store.types[msgtype](**{name: _value(store, node, fields.get(name))
                                   for name, node in defs})


#: rosbags' field node kinds (rosbags.interfaces.Nodetype): a base type, a message, an array
#: of fixed length, a sequence.
_BASE, _NAME, _ARRAY = 1, 2, 3
_SCALAR = {"string": str, "bool": bool, "float32": float, "float64": float}


def _value(store: Any, node: tuple[Any, Any], value: Any) -> Any:
    kind, detail = node
    if kind == _NAME:
        return build_message(store, detail, value or {})
    if kind == _BASE:
        cast = _SCALAR.get(detail[0], int)  # every other base type is an integer
        return cast() if value is None else cast(value)
    elem, size = detail  # ARRAY: size is its length; SEQUENCE: its bound (0: none)
    if elem[0] == _BASE and elem[1][0] != "string":
        dtype = _NUMPY[elem[1][0]]
        if value is None:
            return np.zeros(size if kind == _ARRAY else 0, dtype=dtype)
        return np.asarray(value, dtype=dtype)
    return [_value(store, elem, v) for v in (value or ())]


class BagWriter:
    """One bag of ``flavour`` at ``path`` (a ``.bag`` file, or a ROS 2 bag folder).

    Args:
        path: where to write; must not exist (rosbags never overwrites).
        flavour: ``"ros1"`` or ``"ros2"``.
        custom_data: ROS 2 only: key → value strings kept in ``metadata.yaml``.
    """

    def __init__(self, path: Path, flavour: Flavour,
                 custom_data: Mapping[str, str] | None = None) -> None:
        rosbags_module()
        self.flavour = flavour
        self.store = typestore(flavour)
        self.path = path
        if flavour == "ros2":
            from rosbags.rosbag2 import StoragePlugin, Writer

            self._writer: Any = Writer(path, version=ROSBAG2_VERSION,
                                       storage_plugin=StoragePlugin.MCAP)
            for key, value in (custom_data or {}).items():
                self._writer.set_custom_data(key, value)
        else:
            from rosbags.rosbag1 import Writer as Writer1

            self._writer = Writer1(path)
        self._writer.open()
        self._connections: dict[str, Any] = {}
        self.messages = 0
        """Messages written."""

    def custom_data(self, key: str, value: str) -> None:
        """ROS 2: keep ``key: value`` in ``metadata.yaml``'s ``custom_data`` (before closing).

        Raises:
            ConfigError: a ROS 1 bag (it has no such place).
        """
        if self.flavour != "ros2":
            raise ConfigError("a ROS 1 bag has no custom metadata")
        self._writer.set_custom_data(key, value)

    def add(self, topic: Topic) -> None:
        """Declare ``topic`` (latched ones: latching / transient-local QoS)."""
        if topic.name in self._connections:
            return
        if self.flavour == "ros2":
            qos = [_latched_qos()] if topic.latched else []
            conn = self._writer.add_connection(topic.name, topic.msgtype, typestore=self.store,
                                               offered_qos_profiles=qos)
        else:
            conn = self._writer.add_connection(
                topic.name, topic.msgtype, typestore=self.store,
                callerid=CALLER_ID, latching=1 if topic.latched else 0)
        self._connections[topic.name] = conn

    def write(self, topic: Topic, ns: int, fields: Fields) -> None:
        """Write one message at ``ns`` (record time, ns)."""
        try:
            msg = build_message(self.store, topic.msgtype, fields)
        except KeyError as e:  # name the topic: the field is a typo in arena.ros.messages
            raise KeyError(f"{topic.name}: {e.args[0]}") from None
        if self.flavour == "ros2":
            data = self.store.serialize_cdr(msg, topic.msgtype)
        else:
            data = self.store.serialize_ros1(msg, topic.msgtype)
        self._writer.write(self._connections[topic.name], ns, data)
        self.messages += 1

    def close(self) -> None:
        """Finish the bag (index, metadata)."""
        self._writer.close()

    def abort(self) -> None:
        """Stop writing after an error, leaving an unfinished bag (to be removed)."""
        self._writer.abort()


def _latched_qos() -> Any:
    """ROS 2's transient-local, reliable, keep-last-1 profile (latched ``/map``, ``/tf_static``)."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    zero = QosTime(0, 0)
    return Qos(QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL,
               zero, zero, QosLiveliness.AUTOMATIC, zero, avoid_ros_namespace_conventions=False)


class RosbagSink:
    """A :class:`~arena.live.hook.LiveSink` writing every frame of an episode into ``bag``.

    Args:
        bag: the open bag.
        clock: also write ``/clock`` (players such as ``ros2 bag play --clock`` make their own).
    """

    def __init__(self, bag: BagWriter, *, clock: bool = False) -> None:
        self.bag = bag
        self.convert = RosMessages(clock=clock)

    def wants_frame(self, time: float) -> bool:
        """Every frame: a bag keeps every step."""
        return True

    def scene(self, scene: LiveScene) -> None:
        """Declare the episode's topics and write its latched messages."""
        messages = self.convert.scene(scene)
        for topic in self.convert.table:
            self.bag.add(topic)
        for topic, ns, fields in messages:
            self.bag.write(topic, ns, fields)

    def frame(self, frame: LiveFrame, *, last: bool = False) -> None:
        """Write the step's messages."""
        for topic, ns, fields in self.convert.frame(frame):
            self.bag.write(topic, ns, fields)
