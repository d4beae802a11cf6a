"""Writing frames to disk: PNG stills, MP4 (H.264) and GIF animations.

MP4 goes through the ffmpeg binary bundled with ``imageio-ffmpeg`` (``libx264``, ``yuv420p``,
so every common player opens it); GIF goes through Pillow with one adaptive palette per frame.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Generator, Sequence
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import ArenaError, ConfigError
from arena.render.frames import DEFAULT_WIDTH_PX
from arena.scene.state import SimState, StaticWorld
from arena.sensors.spec import LidarSpec

VIDEO_EXTENSIONS = (".mp4", ".gif")
# x264 constant-rate factor: 20 keeps thin lines and small text sharp at a modest size.
_MP4_CRF = 20


class RenderError(ArenaError):
    """A frame could not be written (wrong shape or dtype, writer already closed, no frames)."""


def _check_frame(frame: ArrayLike) -> NDArray[np.uint8]:
    """Validate an RGB(A) uint8 frame and return it as contiguous ``(H, W, 3)`` RGB."""
    arr = np.asarray(frame)
    if arr.dtype != np.uint8 or arr.ndim != 3 or arr.shape[2] not in (3, 4):
        raise RenderError(
            f"a frame must be an (H, W, 3) or (H, W, 4) uint8 array, got {arr.dtype} {arr.shape}"
        )
    if arr.shape[0] < 1 or arr.shape[1] < 1:
        raise RenderError(f"a frame must not be empty, got shape {arr.shape}")
    return np.ascontiguousarray(arr[:, :, :3])


def save_png(frame: ArrayLike, path: str | Path) -> Path:
    """Write one ``(H, W, 3)`` (or RGBA) uint8 frame as a PNG; parent folders are created.

    Returns:
        The path written.

    Raises:
        RenderError: the frame is not an RGB(A) uint8 image.
    """
    from PIL import Image

    rgb = _check_frame(frame)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(rgb).save(out, format="PNG")
    return out


class VideoWriter:
    """Collects frames into an MP4 or GIF file, chosen by the path's extension.

    Use as a context manager (``with VideoWriter(path) as vw: vw.append(frame)``) or call
    :meth:`close` yourself. All frames must have the size of the first one. MP4 frames with an
    odd width or height are padded by one edge pixel, since ``yuv420p`` needs even sizes.

    Args:
        path: output file, ``.mp4`` or ``.gif`` (case-insensitive); parent folders are created.
        fps: frames per second (> 0).

    Raises:
        ConfigError: unsupported extension or non-positive ``fps``.
    """

    def __init__(self, path: str | Path, fps: float = 10.0) -> None:
        self.path = Path(path)
        self.format = self.path.suffix.lower()
        if self.format not in VIDEO_EXTENSIONS:
            raise ConfigError(
                f"unsupported video extension {self.path.suffix!r} for {self.path}; "
                f"use one of {', '.join(VIDEO_EXTENSIONS)}"
            )
        if not (fps > 0 and np.isfinite(fps)):
            raise ConfigError(f"fps must be a positive number, got {fps!r}")
        self.fps = float(fps)
        self.n_frames = 0
        self._size: tuple[int, int] | None = None  # (H, W) of the first frame
        self._closed = False
        self._ffmpeg: Generator[Any, Any, None] | None = None
        self._gif_frames: list[Any] = []

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self.close()
        else:
            # Do not hide the original error behind a "no frames" complaint.
            with contextlib.suppress(RenderError):
                self.close()

    def append(self, frame: ArrayLike) -> None:
        """Add one ``(H, W, 3)`` uint8 frame.

        Raises:
            RenderError: the writer is closed, or the frame has the wrong dtype or size.
        """
        if self._closed:
            raise RenderError(f"cannot append to {self.path}: the writer is closed")
        rgb = _check_frame(frame)
        size = (int(rgb.shape[0]), int(rgb.shape[1]))
        if self._size is None:
            self._size = size
        elif size != self._size:
            raise RenderError(
                f"frame {self.n_frames} of {self.path} is {size[1]}×{size[0]} px but the first "
                f"was {self._size[1]}×{self._size[0]} px"
            )
        if self.format == ".mp4":
            self._append_mp4(rgb)
        else:
            self._append_gif(rgb)
        self.n_frames += 1

    def close(self) -> Path:
        """Finish the file and return its path (calling it again does nothing more).

        Raises:
            RenderError: no frame was appended (nothing is written then).
        """
        if self._closed:
            return self.path
        self._closed = True
        if self.n_frames == 0:
            raise RenderError(f"no frames were appended; {self.path} was not written")
        if self._ffmpeg is not None:
            self._ffmpeg.close()  # flushes and waits for ffmpeg to finish
            self._ffmpeg = None
        if self._gif_frames:
            first, *rest = self._gif_frames
            first.save(
                self.path, format="GIF", save_all=True, append_images=rest,
                duration=max(round(1000.0 / self.fps), 10), loop=0, disposal=1,
            )
            self._gif_frames = []
        return self.path

    # -- formats ----------------------------------------------------------------------------------
    def _append_mp4(self, rgb: NDArray[np.uint8]) -> None:
        h, w = rgb.shape[:2]
        if h % 2 or w % 2:
            rgb = np.pad(rgb, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
        if self._ffmpeg is None:
            import imageio_ffmpeg

            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._ffmpeg = imageio_ffmpeg.write_frames(
                str(self.path),
                size=(rgb.shape[1], rgb.shape[0]),
                fps=self.fps,
                codec="libx264",
                pix_fmt_in="rgb24",
                pix_fmt_out="yuv420p",
                quality=None,
                output_params=["-crf", str(_MP4_CRF)],
                # Sizes are made even above; a block size of 1 stops imageio-ffmpeg resizing.
                macro_block_size=1,
                ffmpeg_log_level="error",
            )
            self._ffmpeg.send(None)  # start the ffmpeg process
        self._ffmpeg.send(np.ascontiguousarray(rgb).tobytes())

    def _append_gif(self, rgb: NDArray[np.uint8]) -> None:
        from PIL import Image

        if not self._gif_frames:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        # Quantise now: keeps one byte per pixel in memory instead of three.
        img = Image.fromarray(rgb).quantize(
            colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE
        )
        self._gif_frames.append(img)


def render_episode(
    states: Sequence[SimState],
    world: StaticWorld,
    path: str | Path,
    *,
    fps: float = 10.0,
    every: int = 1,
    overlays: Sequence[Any] | Callable[[int, SimState], Any] | None = None,
    lidar_specs: Sequence[LidarSpec | None] = (),
    width_px: int = DEFAULT_WIDTH_PX,
    title: str = "",
    show_lidar: bool = True,
    show_trails: bool = True,
    legend: bool = True,
) -> Path:
    """Render a recorded episode to an MP4 or GIF.

    Every ``every``-th state is drawn, and always the last one (so the final outcome is shown).
    Robot trails are built from all states, not only the drawn ones.

    Args:
        states: the episode's snapshots in order.
        world: the static world they live in.
        path: output ``.mp4`` or ``.gif``.
        fps: frames per second of the output.
        every: draw one state in ``every``.
        overlays: per state an :class:`~arena.render.frames.Overlay` (or ``None``), either as a
            sequence parallel to ``states`` or as a function ``(index, state) -> Overlay | None``.
        lidar_specs: per robot the lidar that produced its scans (see :class:`FrameRenderer`).
        width_px: frame width in pixels.
        title: text at the top of every frame.
        show_lidar: draw lidar hits and rays.
        show_trails: draw robot trails.
        legend: draw a legend of exactly the elements the video shows (see
            :func:`arena.render.legend.legend_items`).

    Returns:
        The written path.

    Raises:
        ConfigError: unsupported extension, ``every < 1``, or ``overlays`` of the wrong length.
        RenderError: ``states`` is empty.
    """
    from dataclasses import replace

    from arena.render.frames import FrameRenderer, Overlay
    from arena.render.legend import legend_items

    if every < 1:
        raise ConfigError(f"every must be >= 1, got {every}")
    if not callable(overlays) and overlays is not None and len(overlays) != len(states):
        raise ConfigError(
            f"overlays has {len(overlays)} entries but there are {len(states)} states"
        )
    writer = VideoWriter(path, fps=fps)
    if not states:
        raise RenderError(f"no states to render into {writer.path}")
    drawn = [k for k in range(len(states)) if k % every == 0 or k == len(states) - 1]
    # Asked once per drawn state, before drawing: the legend must know them all.
    if callable(overlays):
        given = {k: overlays(k, states[k]) for k in drawn}
    else:
        given = {k: overlays[k] if overlays is not None else None for k in drawn}
    items = legend_items(
        [states[k] for k in drawn], given.values(),
        lidar=show_lidar and any(spec is not None for spec in lidar_specs), trails=show_trails,
    ) if legend else ()
    renderer = FrameRenderer(
        world, lidar_specs=lidar_specs, width_px=width_px, title=title,
        show_lidar=show_lidar, show_trails=show_trails, legend=items,
    )
    history: list[NDArray[np.float64]] = []
    with writer:
        for k, state in enumerate(states):
            xy = np.array(state.robots.poses[:, :2], dtype=np.float64)
            if k > 0 and (state.step <= states[k - 1].step or xy.shape != history[-1].shape):
                history = []  # a new episode starts inside the sequence
            history.append(xy)
            if k not in given:
                continue
            ov = given[k] if given[k] is not None else Overlay()
            if show_trails and ov.trails is None:
                hist = np.stack(history)  # (k, r, 2)
                ov = replace(ov, trails=[hist[:, i] for i in range(hist.shape[1])])
            writer.append(renderer.render(state, ov))
    return writer.path
