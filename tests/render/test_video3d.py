"""3-D videos of episodes: cameras, social-state colours, determinism, config and the run."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from arena.config import load_config
from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.crowd.state import SocialState
from arena.render import style
from arena.render.video3d import Video3D
from arena.sim.native2d import Native2DBackend
from tests.mujoco_kit import require_mujoco
from tests.sim.mujoco.scenes import episode, people

require_mujoco()


def states(n: int = 6, turn: float = 0.0):
    """A jackal driving from (1, 1.2) into the room with three people standing, n states."""
    ep = episode(agents=people([(3.5, 3.5), (5.0, 4.0), (2.5, 4.5)]))
    b = Native2DBackend()
    out = [b.reset(ep, None, derive_rng(0, "video3d"))]
    for _ in range(n - 1):
        out.append(b.step(np.array([[0.5, 0.0, turn]]), 0.2))
    return ep, out


def near(frame: np.ndarray, rgb: tuple[float, float, float], tol: float = 0.12) -> np.ndarray:
    """Pixels whose chromaticity is that of ``rgb`` (lighting scales brightness, not hue)."""
    f = frame.astype(np.float64) + 1.0
    want = np.array(rgb) + 1.0 / 255
    return np.all(np.abs(f / f.sum(-1, keepdims=True) - want / want.sum()) < tol / 3, axis=-1) & (
        f.sum(-1) > 60
    )


def test_chase_camera_keeps_the_robot_in_the_lower_middle_of_the_view():
    ep, ss = states(8, turn=0.4)
    video = Video3D(ep, ss[0], "chase", width=320, height=240)
    robot = style.robot_color(0)
    for s in ss:
        frame = video.frame(s, f"t = {s.time:.1f} s")
        assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
        rows, cols = np.nonzero(near(frame, robot))
        assert len(rows) > 50, f"robot not in view at step {s.step}"
        assert 0.3 * 320 < cols.mean() < 0.7 * 320
        assert rows.mean() > 0.45 * 240  # below the image centre
    video.close()


def test_torsos_wear_the_social_state_colour():
    ep, ss = states(2)
    video = Video3D(ep, ss[0], "overview", width=320, height=240)
    s = ss[-1]
    running = np.full(len(s.agents), int(SocialState.RUNNING))
    phone = np.full(len(s.agents), int(SocialState.PHONE))
    for codes, colour, other in ((running, SocialState.RUNNING, SocialState.PHONE),
                                 (phone, SocialState.PHONE, SocialState.RUNNING)):
        agents = dataclasses.replace(s.agents, states=codes)
        frame = video.frame(dataclasses.replace(s, agents=agents))
        assert near(frame, style.AGENT_STATE_COLORS[colour]).sum() > 60
        assert near(frame, style.AGENT_STATE_COLORS[other]).sum() < 5
    video.close()


def test_the_same_states_give_the_same_frames():
    ep, ss = states(4, turn=0.3)
    runs = []
    for _ in range(2):
        video = Video3D(ep, ss[0], "chase", width=160, height=120)
        runs.append([video.frame(s, "x").tobytes() for s in ss])
        video.close()
    assert runs[0] == runs[1]
    assert len(set(runs[0])) == len(ss)  # the view moves with the robot


def test_video_3d_config():
    out = load_config(None, []).output
    assert out.camera_3d("native2d") is None and out.camera_3d("mujoco") == "chase"
    over = load_config(None, ["output.video_3d=overview"]).output
    assert over.camera_3d("native2d") == "overview"
    assert load_config(None, ["output.video=false"]).output.camera_3d("mujoco") is None
    with pytest.raises(ConfigError, match=r"output\.video_3d_size: .*even sizes in 64\.\.1920"):
        load_config(None, ["output.video_3d_size=[641, 480]"])
    with pytest.raises(ConfigError, match=r"output\.video_3d"):
        load_config(None, ["output.video_3d=top"])


def test_a_mujoco_run_writes_the_3d_video_and_the_report_shows_it(tmp_path):
    from arena.eval.replay import render_episode_video
    from arena.experiment import run_experiment

    cfg = load_config(None, [
        "sim.backend.type=mujoco", "map.type=empty", "map.width=8", "map.height=6",
        "task.obstacles.static=1", "task.obstacles.dynamic=2", "task.timeout=6", "episodes=1",
        "task.robots.min_goal_distance=3",
        "output.video_3d_size=[160, 120]", "output.width_px=300",
    ])
    _, results = run_experiment(cfg, tmp_path / "run")
    files = results[0].files
    assert files["video_3d"].endswith("video_3d.mp4")
    import imageio.v3 as iio

    frames = iio.imread(files["video_3d"], index=None, extension=".mp4")
    assert frames.shape[1:] == (120, 160, 3) and len(frames) >= 2
    assert (tmp_path / "run" / "episode_000" / "final_3d.png").is_file()
    again = render_episode_video(files["record"], tmp_path / "replay")
    assert again.matches_record and again.path_3d is not None and again.path_3d.is_file()
