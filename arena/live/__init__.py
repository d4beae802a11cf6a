"""Watching a running episode: its scene and frames, a viewer's control, the live channel.

- :mod:`arena.live.frame`: :class:`LiveScene` (map, obstacles, robot bodies) and
  :class:`LiveFrame` (poses, plan, lidar hits, people with social states and groups) built
  from the episode runner, and their JSON;
- :mod:`arena.live.control`: :class:`LiveControl`, pause, steps, speed, goals and teleports;
- :mod:`arena.live.hook`: :class:`LiveHook`, the episode hook that feeds the viewers;
- :mod:`arena.live.server`: :class:`LiveServer`, a run's loopback channel (JSON lines), and
  :class:`LiveClient` for scripts.

The web app (``arena web``, :mod:`arena.web`) and Foxglove (:mod:`arena.export.foxglove`) are
viewers; none of this needs their extras.
"""

from arena.live.control import LiveControl
from arena.live.frame import LiveFrame, LiveScene, frame_json, frame_of, scene_json, scene_of
from arena.live.hook import LiveHook, LiveSink
from arena.live.server import LIVE_FILE, LiveClient, LiveServer

__all__ = [
    "LIVE_FILE",
    "LiveClient",
    "LiveControl",
    "LiveFrame",
    "LiveHook",
    "LiveScene",
    "LiveServer",
    "LiveSink",
    "frame_json",
    "frame_of",
    "scene_json",
    "scene_of",
]
