"""The episode hook that feeds live viewers: scene at reset, frames as they are wanted.

:class:`LiveHook` is one more :class:`~arena.episode.runner.EpisodeHooks` of an episode. It asks
each :class:`LiveSink` whether it wants a frame before building one (building costs a little;
a sink with no viewer wants none), so an unwatched run pays nothing but the question. With a
:class:`~arena.live.control.LiveControl` it also holds each tick while a viewer pauses and
paces the run to the viewer's speed.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.live.control import LiveControl
from arena.live.frame import LiveFrame, LiveScene, frame_of, scene_of


class LiveSink(Protocol):
    """Where live scenes and frames go (the live server, a Foxglove server, an MCAP file)."""

    def wants_frame(self, time: float) -> bool:
        """Whether a frame at simulated ``time`` (s) is wanted now."""
        ...

    def scene(self, scene: LiveScene) -> None:
        """A new episode began."""
        ...

    def frame(self, frame: LiveFrame, *, last: bool = False) -> None:
        """One moment; ``last``: the episode's final frame (its ``outcome`` is set)."""
        ...


class LiveHook(EpisodeHooks):
    """Sends an episode's scene and frames to ``sinks``; holds ticks for ``control``.

    Args:
        sinks: the viewers' channels.
        control: pause, steps and pace (``None``: the run goes as fast as it goes).
    """

    def __init__(self, sinks: Sequence[LiveSink], control: LiveControl | None = None) -> None:
        self.sinks = list(sinks)
        self.control = control
        self.scene: LiveScene | None = None
        self.frames = 0
        """Frames built in this episode (for benchmarks and tests)."""

    def initialize_episode(self, runner: EpisodeRunner) -> None:
        """Send the new scene and the first frame."""
        self.scene = scene_of(runner)
        self.frames = 0
        for sink in self.sinks:
            sink.scene(self.scene)
        self._publish(runner, force=True)

    def before_step(self, runner: EpisodeRunner) -> None:
        """Wait while paused; keep the pace."""
        if self.control is not None:
            assert runner.state is not None
            self.control.wait(runner.state.time)

    def after_step(self, runner: EpisodeRunner) -> None:
        """Send a frame to the sinks that want one."""
        self._publish(runner)

    def episode_end(self, runner: EpisodeRunner) -> None:
        """Send the last frame (with the outcome) to every sink."""
        self._publish(runner, force=True, last=True)

    def _publish(self, runner: EpisodeRunner, *, force: bool = False, last: bool = False) -> None:
        assert runner.state is not None
        t = runner.state.time
        wanting = [s for s in self.sinks if force or s.wants_frame(t)]
        if not wanting or self.scene is None:
            return
        frame = frame_of(runner, self.scene)
        self.frames += 1
        for sink in wanting:
            sink.frame(frame, last=last)
