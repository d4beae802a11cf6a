"""An in-memory ROS transport: a link's partner node without any ROS library or network.

:class:`LoopbackTransport` keeps what a :class:`~arena.ros.link.RosLink` sends (per topic name,
the field dicts) and answers every poll with a command from ``reply`` (a function of the
messages sent so far), as an external node would. The conformance test of the ROS planners
(whose real partner is another process) and the link's unit tests use it.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from typing import Any

import numpy as np

from arena.ros.link import LinkOptions, RosLink
from arena.ros.messages import Fields
from arena.ros.topics import Topic

#: A node's rule: the messages sent so far (topic name -> field dicts) -> ``[vx, vy, omega]``,
#: or ``None`` to stay silent.
Reply = Callable[[dict[str, list[Fields]]], Any]


class LoopbackTransport:
    """Records published messages; each :meth:`poll` answers with ``reply(sent)``.

    Args:
        link: the link it serves.
        reply: the node's rule (default: a command far outside any robot's limits, which the
            planner must clip).
        subscribed: topic names the node subscribes to (default: every topic).
        eager: answer inside each ``odom`` publish instead of in :meth:`poll`, as a client
            library whose callbacks run on their own threads may deliver the answer before
            ``publish`` returns.
    """

    def __init__(self, link: RosLink, reply: Reply | None = None,
                 subscribed: set[str] | None = None, *, eager: bool = False) -> None:
        self.link = link
        self.eager = eager
        self.reply = reply or (lambda sent: np.array([10.0, 5.0, 10.0]))
        self.subscribed = subscribed
        self.sent: dict[str, list[Fields]] = defaultdict(list)
        self.advertised: dict[str, Topic] = {}

    def advertise(self, topic: Topic, name: str) -> None:
        """Note the topic."""
        self.advertised.setdefault(name, topic)

    def publish(self, topic: Topic, name: str, fields: Fields) -> None:
        """Keep the message."""
        self.advertise(topic, name)
        self.sent[name].append(fields)
        if self.eager and topic.kind == "odom":
            self._answer()  # a node whose answer arrives before publish returns (rospy)

    def subscribers(self, name: str) -> int:
        """1 for an advertised topic the node subscribes to, else 0."""
        if name not in self.advertised:
            return 0
        return int(self.subscribed is None or name in self.subscribed)

    def poll(self, timeout: float) -> None:
        """Answer with the node's rule (silent when it returns ``None``; eager: only at odom)."""
        if not self.eager:
            self._answer()

    def _answer(self) -> None:
        cmd = self.reply(self.sent)
        if cmd is not None:
            self.link.on_command(np.asarray(cmd, dtype=np.float64))

    def close(self) -> None:
        """Nothing to release."""


def loopback_link(options: LinkOptions | None = None, **kwargs: Any) -> RosLink:
    """A :class:`RosLink` on a :class:`LoopbackTransport` (``kwargs`` go to the transport)."""
    return RosLink(lambda link: LoopbackTransport(link, **kwargs), options)


def attach_loopback(planner: Any, **kwargs: Any) -> Any:
    """Give a ROS planner a loopback link (no node, no network); returns the planner."""
    planner.link = loopback_link(planner.params.link_options(), **kwargs)
    return planner
