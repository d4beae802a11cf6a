"""Tests of PNG, MP4 and GIF output (written to tmp_path and read back)."""

from __future__ import annotations

from pathlib import Path

import imageio.v2 as iio2
import imageio.v3 as iio3
import numpy as np
import pytest

from arena.core.errors import ArenaError, ConfigError
from arena.core.geometry import rectangle
from arena.maps.grid import OccupancyGrid
from arena.render import Overlay, RenderError, VideoWriter, render_episode, save_png
from arena.scene.state import AgentStates, Collisions, Obstacle, RobotStates, SimState, StaticWorld


def _frames(n: int, h: int = 48, w: int = 64) -> list[np.ndarray]:
    """``n`` distinct frames: a white square moving over a gradient."""
    out = []
    base = np.zeros((h, w, 3), dtype=np.uint8)
    base[..., 0] = np.linspace(0, 200, w, dtype=np.uint8)[None, :]
    base[..., 2] = 90
    for k in range(n):
        f = base.copy()
        f[10:20, 2 + 4 * k : 12 + 4 * k] = 255
        out.append(f)
    return out


def _mp4_frames(path: Path) -> list[np.ndarray]:
    with iio2.get_reader(path) as reader:
        return [np.asarray(f) for f in reader]


def test_save_png_round_trip(tmp_path: Path) -> None:
    frame = _frames(1)[0]
    path = save_png(frame, tmp_path / "sub" / "still.png")
    assert path.exists()
    back = iio3.imread(path)
    assert np.array_equal(back[..., :3], frame)


def test_save_png_rejects_bad_frames(tmp_path: Path) -> None:
    with pytest.raises(RenderError):
        save_png(np.zeros((4, 4), dtype=np.uint8), tmp_path / "a.png")
    with pytest.raises(RenderError):
        save_png(np.zeros((4, 4, 3), dtype=np.float32), tmp_path / "b.png")


def test_mp4_twelve_frames(tmp_path: Path) -> None:
    frames = _frames(12)
    with VideoWriter(tmp_path / "clip.mp4", fps=10) as vw:
        for f in frames:
            vw.append(f)
    assert vw.n_frames == 12
    back = _mp4_frames(tmp_path / "clip.mp4")
    assert len(back) == 12
    assert back[0].shape == (48, 64, 3)
    # Lossy, but close: the moving square is where it should be.
    assert np.abs(back[5].astype(int) - frames[5].astype(int)).mean() < 6
    with iio2.get_reader(tmp_path / "clip.mp4") as reader:
        meta = reader.get_meta_data()
    assert meta["codec"] == "h264"
    assert meta["pix_fmt"].startswith("yuv420p")
    assert meta["fps"] == pytest.approx(10.0)


def test_mp4_pads_odd_sizes(tmp_path: Path) -> None:
    frames = _frames(3, h=33, w=51)
    vw = VideoWriter(tmp_path / "odd.MP4", fps=5)
    for f in frames:
        vw.append(f)
    assert vw.close() == tmp_path / "odd.MP4"
    back = _mp4_frames(tmp_path / "odd.MP4")
    assert len(back) == 3
    assert back[0].shape == (34, 52, 3)


def test_gif_twelve_frames(tmp_path: Path) -> None:
    frames = _frames(12)
    with VideoWriter(tmp_path / "clip.gif", fps=10) as vw:
        for f in frames:
            vw.append(f)
    back = iio3.imread(tmp_path / "clip.gif", index=None)
    assert back.shape[:3] == (12, 48, 64)
    assert np.abs(back[3][..., :3].astype(int) - frames[3].astype(int)).mean() < 6
    assert iio3.immeta(tmp_path / "clip.gif")["duration"] == 100


def test_unsupported_extension(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"\.avi"):
        VideoWriter(tmp_path / "clip.avi")
    with pytest.raises(ArenaError):
        VideoWriter(tmp_path / "clip")
    with pytest.raises(ConfigError):
        VideoWriter(tmp_path / "clip.mp4", fps=0)


def test_writer_misuse(tmp_path: Path) -> None:
    vw = VideoWriter(tmp_path / "x.gif")
    vw.append(_frames(1)[0])
    with pytest.raises(RenderError, match="first"):
        vw.append(_frames(1, h=20, w=20)[0])
    vw.close()
    assert vw.close() == tmp_path / "x.gif"  # closing twice is fine
    with pytest.raises(RenderError, match="closed"):
        vw.append(_frames(1)[0])
    with pytest.raises(RenderError, match="no frames"):
        VideoWriter(tmp_path / "empty.mp4").close()
    assert not (tmp_path / "empty.mp4").exists()


def test_error_inside_with_block_is_not_masked(tmp_path: Path) -> None:
    with pytest.raises(KeyError), VideoWriter(tmp_path / "y.mp4"):
        raise KeyError("boom")


def _episode(n: int) -> tuple[list[SimState], StaticWorld]:
    grid = OccupancyGrid.empty(6.0, 4.0, 0.1)
    world = StaticWorld.build(
        grid, (Obstacle("b", "cuboid", np.array([4.5, 2.0, 0.0]), rectangle(0.6, 0.6)),)
    )
    states = []
    for k in range(n):
        robots = RobotStates(("r",), ("burger",), np.array([[1.0 + 0.2 * k, 1.0, 0.0]]),
                             np.zeros((1, 3)), np.zeros((1, 3)), np.array([0.25]), (None,),
                             (np.zeros(0),))
        states.append(SimState(0.1 * k, k, robots, AgentStates.empty(), Collisions.none(1)))
    return states, world


def test_render_episode(tmp_path: Path) -> None:
    states, world = _episode(12)
    out = render_episode(states, world, tmp_path / "ep.mp4", fps=10, width_px=120,
                         overlays=lambda i, s: Overlay(text=f"frame {i}"), legend=False)
    frames = _mp4_frames(out)
    assert len(frames) == 12
    assert frames[0].shape == (80, 120, 3)
    # every=5 draws states 0, 5, 10 and always the last one (11).
    gif = render_episode(states, world, tmp_path / "ep.gif", every=5, width_px=120, legend=False)
    assert iio3.imread(gif, index=None).shape[0] == 4


def test_videos_are_readable_by_default(tmp_path: Path) -> None:
    """At least 720 px wide, even sizes, H.264, with a legend of what the video shows."""
    states, world = _episode(4)
    calls: list[int] = []

    def overlay(i: int, s: SimState) -> Overlay:
        calls.append(i)
        return Overlay(goals=np.array([[5.0, 3.0, 0.0]]), text=f"frame {i}")

    out = render_episode(states, world, tmp_path / "ep.mp4", overlays=overlay)
    assert calls == [0, 1, 2, 3]  # each overlay asked for once
    meta = iio3.immeta(out, extension=".mp4")
    assert meta["codec"] == "h264"
    w, h = meta["size"]
    assert w >= 720 and w % 2 == 0 and h % 2 == 0
    frames = _mp4_frames(out)
    assert frames[0].shape == (h, w, 3)
    # the goal ring is in the legend (right of the map): the robot colour appears there
    plain = render_episode(states, world, tmp_path / "plain.mp4", legend=False)
    assert _mp4_frames(plain)[0].shape[1] == w
    right = frames[-1][:, int(0.85 * w):].astype(int)
    blue = np.array([31, 119, 180])
    assert np.any(np.abs(right - blue).max(axis=-1) < 30)
    assert not np.any(np.abs(_mp4_frames(plain)[-1][:, int(0.85 * w):].astype(int) - blue)
                      .max(axis=-1) < 30)


def test_render_episode_errors(tmp_path: Path) -> None:
    states, world = _episode(3)
    with pytest.raises(ConfigError):
        render_episode(states, world, tmp_path / "e.webm")
    with pytest.raises(ConfigError):
        render_episode(states, world, tmp_path / "e.gif", every=0)
    with pytest.raises(ConfigError):
        render_episode(states, world, tmp_path / "e.gif", overlays=[None])
    with pytest.raises(RenderError):
        render_episode([], world, tmp_path / "e.gif")
