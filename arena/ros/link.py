"""A live ROS connection of one robot: the episode's topics out, velocity commands in.

:class:`RosLink` is the ROS-agnostic part of the ROS 1 and ROS 2 bridges. It is a
:class:`~arena.live.hook.LiveSink`: each scene and frame of the running episode becomes the
messages of :func:`arena.ros.topics.topic_table` (:class:`~arena.ros.messages.RosMessages`,
the same messages the bag export writes, but ``cmd_vel``, which the node sends), sent
through a :class:`Transport` (rclpy in :mod:`arena.ros.ros2`, rospy in :mod:`arena.ros.ros1`).
Incoming traffic, from any thread, comes back through :meth:`RosLink.on_command`,
:meth:`RosLink.on_goal` and :meth:`RosLink.on_reset`.

Two clock modes:

``lockstep``
    :meth:`RosLink.command` waits for a ``cmd_vel`` received after the latest frame was sent:
    the simulation advances one control period per command, however fast or slow the node is,
    so a benchmark is reproducible. Each frame's ``odom`` goes out last, so a node that answers
    every ``odom`` has the frame's other messages by then. A node that does not answer within
    ``timeout`` s (``startup_timeout`` for the first command of an episode, while the node
    discovers the topics) raises :class:`NodeTimeout`, which ends the episode as ``error``.
``realtime``
    :meth:`RosLink.command` takes the latest command without waiting (the run is paced to
    wall-clock time); a command older than ``command_timeout`` s of wall time counts as a stop,
    as robot base drivers do.

A topic nobody subscribes to is not built (``/people/markers`` with 50 people costs more than
the step), except the latched ones (``/map``, ``/tf_static``), which late subscribers get.
``goal_pose`` is sent when the goal changes (a navigator such as Nav2's restarts on each goal
it receives) and kept for late subscribers; goals other nodes send on it are the user's (the
link's own, echoed back, are not).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ArenaError, ConfigError
from arena.core.types import Pose2D
from arena.live.frame import LiveFrame, LiveScene
from arena.ros.messages import Fields, RosMessages, sim_ns
from arena.ros.topics import Topic

Mode = Literal["lockstep", "realtime"]
#: s between repeats of an unanswered episode's latest frame (a node still discovering).
RESEND_S = 0.25
#: s of silence after which the latest frame goes again to every subscribed topic.
RESEND_ALL_S = 1.0
FloatArray = NDArray[np.float64]


class NodeTimeout(ArenaError):
    """The external node sent no command within the timeout (its episode ends as ``error``)."""


class Transport(Protocol):
    """One ROS client library's connection, owned by a :class:`RosLink`."""

    def publish(self, topic: Topic, name: str, fields: Fields) -> None:
        """Send ``fields`` on topic ``name`` (``topic.name`` in the link's namespace).

        The publisher is created on first use (see :meth:`advertise`).
        """
        ...

    def advertise(self, topic: Topic, name: str) -> None:
        """Create the publisher of topic ``name`` (once; later calls do nothing).

        Its type is ``topic.msgtype``; latched (ROS 1) / transient local (ROS 2) when
        ``topic.latched`` or for the goal (sent when it changes).
        """
        ...

    def subscribers(self, name: str) -> int:
        """How many subscribers topic ``name`` has now (0 for one not advertised)."""
        ...

    def poll(self, timeout: float) -> None:
        """Handle incoming messages for up to ``timeout`` s; may return once one arrived."""
        ...

    def close(self) -> None:
        """Remove this link's publishers, subscriptions and services."""
        ...


@dataclass(frozen=True)
class LinkOptions:
    """How a link talks to the external node.

    Attributes:
        mode: ``lockstep`` or ``realtime`` (see the module doc).
        namespace: prefix of every topic and service (``""`` or ``/name``).
        timeout: s of wall time to wait for each lock-step command.
        startup_timeout: s to wait for the first command of an episode.
        command_timeout: s (wall) after which a real-time command counts as a stop.
        cmd_vel_stamped: ``cmd_vel`` is ``geometry_msgs/TwistStamped`` (Nav2's
            ``enable_stamped_cmd_vel``) instead of ``Twist``.
        clock: publish ``/clock`` (simulated time, for nodes with ``use_sim_time``).
        remap: ``(default name, name)`` pairs: a topic (or ``/arena/reset``) of the table under
            another absolute name (``("/scan", "/front/scan")``); the namespace does not apply.
    """

    mode: Mode = "lockstep"
    namespace: str = ""
    timeout: float = 5.0
    startup_timeout: float = 30.0
    command_timeout: float = 0.5
    cmd_vel_stamped: bool = False
    clock: bool = True
    remap: tuple[tuple[str, str], ...] = ()

    def name(self, topic: str) -> str:
        """``topic`` in the link's namespace, or where :attr:`remap` sends it."""
        for source, target in self.remap:
            if source == topic:
                return target
        return f"{self.namespace}{topic}"


@dataclass
class _Inbox:
    """What arrived from the node (guarded by the link's condition)."""

    command: FloatArray | None = None
    command_frame: int = -1  # frames sent before the command arrived
    stamped: bool = False  # the command had a stamp (TwistStamped): matched by time
    answers: int = 0  # unstamped commands received over the link's life
    command_wall: float = -np.inf
    goals: list[Pose2D] = field(default_factory=list)
    resets: int = 0


class RosLink:
    """Sends an episode's topics and takes the node's commands (see the module doc).

    Args:
        transport: builds the link's transport (called once, with the link).
        options: mode, namespace and timeouts.
    """

    def __init__(self, transport: Callable[[RosLink], Transport],
                 options: LinkOptions | None = None) -> None:
        self.options = options or LinkOptions()
        self.messages = RosMessages(clock=self.options.clock)
        self._cond = threading.Condition()
        self._inbox = _Inbox()
        self._frames = 0  # frames sent in this episode
        self._frame_ns = 0  # the latest frame's simulated time (ns)
        self._odoms = 0  # odom messages sent over the link's life (each gets one answer)
        self._answered = False  # a command came in this episode
        self._last_frame: LiveFrame | None = None
        self._goal_sent: tuple[float, ...] | None = None
        self._goal_topics: set[str] = set()
        self._reached: dict[str, int] = {}  # subscribers each topic had at its last send
        self.transport = transport(self)

    # -- outgoing (the episode's thread) --------------------------------------------------------
    def scene(self, scene: LiveScene) -> None:
        """Start an episode: send the latched ``/tf_static`` and ``/map``."""
        self._goal_sent = None
        with self._cond:
            self._frames, self._frame_ns, self._answered = 0, 0, False
            self._inbox.command, self._inbox.command_frame = None, -1
        latched = self.messages.scene(scene)
        # the command topic is the node's: the link subscribes it and never publishes on it
        self.messages.table = [t for t in self.messages.table if t.kind != "cmd_vel"]
        self._goal_topics = {t.name for t in self.messages.table if t.kind == "goal"}
        self._reached = {}
        for topic in self.messages.table:  # subscribers can be counted from now on
            self.transport.advertise(topic, self.options.name(topic.name))
        for topic, _, fields in latched:
            self.transport.publish(topic, self.options.name(topic.name), fields)

    def wants_frame(self, time: float) -> bool:
        """Every step is sent (the node may act on any of them)."""
        return True

    def frame(self, frame: LiveFrame, *, last: bool = False) -> None:
        """Send one step's messages on the topics someone subscribes to."""
        self._send(frame, repeat=False)

    def _send(self, frame: LiveFrame, *, repeat: bool, everything: bool = False) -> None:
        """Send ``frame`` on the subscribed topics.

        A new frame counts as sent just before its last message (``odom``) goes out: an
        answer can only follow that one, and a client library that runs callbacks on its own
        threads (rospy) may deliver it before ``publish`` returns. A repeat goes only to topics
        that gained a subscriber since (a node answering each ``odom`` must get each frame
        once), or to every subscribed topic with ``everything`` (a node still silent after
        :data:`RESEND_ALL_S`: its first answer may have gone out before it was connected).
        """
        self._last_frame = frame
        transport, opts = self.transport, self.options
        counts = {t.name: transport.subscribers(opts.name(t.name)) for t in self.messages.table}
        if repeat:
            wanted = {n for n, c in counts.items()
                      if c > (0 if everything else self._reached.get(n, 0))}
            if not wanted:
                return
        else:
            wanted = {n for n, c in counts.items() if c > 0}
            # the goal goes out when it changes (a navigator restarts on every goal it gets)
            goal = None if frame.goal is None else tuple(np.round(frame.goal, 9).tolist())
            if goal is not None and goal != self._goal_sent:
                wanted |= self._goal_topics
                self._goal_sent = goal
            else:
                wanted -= self._goal_topics
        self._reached.update(counts)
        messages = self.messages.frame(frame, only=wanted, repeat=repeat)
        # odom last: a node that answers each odom has the frame's scan, plan and goal by then
        messages.sort(key=lambda m: m[0].kind == "odom")
        for k, (topic, _, fields) in enumerate(messages):
            if not repeat and k == len(messages) - 1:
                self._count_frame(frame)
            if topic.kind == "odom":
                with self._cond:
                    self._odoms += 1
            transport.publish(topic, opts.name(topic.name), fields)
        if not repeat and not messages:
            self._count_frame(frame)

    def _count_frame(self, frame: LiveFrame) -> None:
        with self._cond:
            self._frames += 1
            self._frame_ns = sim_ns(frame.time)

    # -- incoming (any thread) ------------------------------------------------------------------
    def on_command(self, command: FloatArray, stamp_ns: int | None = None) -> None:
        """A ``cmd_vel`` ``[vx m/s, vy m/s, omega rad/s]`` arrived.

        ``stamp_ns`` (TwistStamped's header, ns; ``None`` or 0: unstamped): a command stamped
        before the latest frame's time answers an earlier frame, so lock-step does not take it
        for the latest one.
        """
        cmd = np.asarray(command, dtype=np.float64).reshape(3)
        with self._cond:
            inbox = self._inbox
            inbox.stamped = stamp_ns is not None and stamp_ns > 0
            stale = inbox.stamped and stamp_ns < self._frame_ns  # type: ignore[operator]
            inbox.answers += not inbox.stamped
            inbox.command = cmd
            inbox.command_frame = self._frames - 1 if stale else self._frames
            self._inbox.command_wall = time.monotonic()
            self._cond.notify_all()

    def on_goal(self, pose: Pose2D) -> None:
        """A goal arrived on ``goal_pose`` (taken by :meth:`take_goals`).

        The link's own goal, which it publishes on the same topic, is not one.
        """
        sent = self._goal_sent
        if sent is not None and np.allclose(pose.as_array(), sent, atol=1e-6):
            return
        with self._cond:
            self._inbox.goals.append(pose)
            self._cond.notify_all()

    def on_reset(self) -> tuple[bool, str]:
        """The reset service was called: the running episode ends, the next one starts."""
        with self._cond:
            self._inbox.resets += 1
            self._cond.notify_all()
        return True, "the running episode ends; the next one starts"

    def take_goals(self) -> list[Pose2D]:
        """Goals received since the last call."""
        with self._cond:
            goals, self._inbox.goals = self._inbox.goals, []
        return goals

    def take_resets(self) -> int:
        """Reset requests received since the last call."""
        with self._cond:
            n, self._inbox.resets = self._inbox.resets, 0
        return n

    # -- commands -------------------------------------------------------------------------------
    def command(self) -> FloatArray:
        """The node's command for the current step ``(3,)`` (see the module doc).

        Raises:
            NodeTimeout: lock-step, and no command within the timeout.
        """
        opts = self.options
        if opts.mode == "realtime":
            self.transport.poll(0.0)
            with self._cond:
                inbox = self._inbox
                fresh = time.monotonic() - inbox.command_wall <= opts.command_timeout
                return (inbox.command.copy() if inbox.command is not None and fresh
                        else np.zeros(3))
        wait = opts.timeout if self._answered else opts.startup_timeout
        deadline = time.monotonic() + wait
        resend = time.monotonic() + RESEND_S
        resend_all = time.monotonic() + RESEND_ALL_S
        while True:
            with self._cond:
                if self._answers_latest():
                    self._answered = True
                    return self._inbox.command.copy()  # type: ignore[union-attr]
                frames = self._frames
            now = time.monotonic()
            left = deadline - now
            if not self._answered and self._last_frame is not None and now >= resend:
                # a node that subscribed after the frame went out gets it now
                everything = now >= resend_all
                self._send(self._last_frame, repeat=True, everything=everything)
                resend = now + RESEND_S
                if everything:
                    resend_all = now + RESEND_ALL_S
                    with self._cond:  # answers lost before the node was connected: resync
                        if self._odoms:  # expect one answer to the odom just sent again
                            self._inbox.answers = min(self._inbox.answers, self._odoms - 1)
            if left <= 0:
                raise NodeTimeout(
                    f"no {opts.name('/cmd_vel')} command within {wait:g} s (lock-step, after "
                    f"frame {frames}): the planner node does not answer")
            self.transport.poll(min(left, 0.1))

    def _answers_latest(self) -> bool:
        """The inbox's command answers the latest frame (called under the condition).

        A stamped command answers the frames up to its stamp. Unstamped ones are counted: a
        node answers each ``odom`` once, so the latest frame is answered when there are as
        many answers as odoms were sent. Counting over the link's life, not just since the
        frame went out, keeps an answer that arrives late (to an episode's last frame, which
        no tick consumes) from being taken for the next frame's, which would make every
        later command one frame late. Without odom subscribers, any command that came after
        the frame went out answers it.
        """
        inbox = self._inbox
        if inbox.command is None:
            return False
        if inbox.stamped or not self._odoms:
            return inbox.command_frame >= self._frames
        return inbox.answers >= self._odoms

    def close(self) -> None:
        """Close the transport."""
        self.transport.close()


def check_topic(name: str, *, field_name: str = "remap") -> str:
    """An absolute ROS name ``/a/b`` (letters, digits, underscores; no part starts with a digit).

    Raises:
        ConfigError: anything else.
    """
    try:
        ok = name.startswith("/") and not name.endswith("/") and check_namespace(name) == name
    except ConfigError:
        ok = False
    if not ok:
        raise ConfigError(f"{field_name}: {name!r} is not an absolute ROS name (expected "
                          "'/name' or '/a/b')")
    return name


def check_namespace(namespace: str, *, field_name: str = "namespace") -> str:
    """A ROS namespace: ``""`` or ``/a/b`` of letters, digits and underscores.

    Raises:
        ConfigError: anything else.
    """
    ns = namespace.rstrip("/")
    if ns and (not ns.startswith("/") or not all(
            p and (p[0].isalpha() or p[0] == "_") and p.replace("_", "").isalnum()
            for p in ns[1:].split("/"))):
        raise ConfigError(f"{field_name}: {namespace!r} is not a ROS namespace (expected '' or "
                          "'/name', letters, digits and underscores, not starting with a digit)")
    return ns
