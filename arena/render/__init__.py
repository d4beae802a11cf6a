"""Top-down frames, PNG stills and MP4/GIF videos of simulation states.

This is the only package that imports matplotlib; it reads states and never changes them.

Example:
    >>> renderer = FrameRenderer(world, lidar_specs=[spec])  # doctest: +SKIP
    >>> with VideoWriter("episode.mp4", fps=10) as video:  # doctest: +SKIP
    ...     for state in states:
    ...         video.append(renderer.render(state, Overlay(text="running")))
"""

from arena.render.frames import DEFAULT_WIDTH_PX, FrameRenderer, Overlay, render_world
from arena.render.legend import legend_items
from arena.render.video import RenderError, VideoWriter, render_episode, save_png

__all__ = [
    "DEFAULT_WIDTH_PX",
    "FrameRenderer",
    "Overlay",
    "RenderError",
    "VideoWriter",
    "legend_items",
    "render_episode",
    "render_world",
    "save_png",
]
