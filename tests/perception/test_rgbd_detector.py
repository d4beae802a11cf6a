"""The RGB-D people detector: its geometry, the shipped weights on the golden frame, the data."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.config import load_config
from arena.core.errors import ConfigError
from arena.perception.rgbd_data import CAMERA, STRIDE, labelled_frames, shrink, to_base
from arena.perception.rgbd_detector import BLOB_FEATURES, RgbdPeopleDetector, base_points
from arena.sensors.spec3d import RgbdSpec
from tests.perception.rgbd_golden import GOLDEN, render


def golden():
    with np.load(GOLDEN) as g:
        return (g["depth"], g["rgb"].astype(np.float32) / 255, g["pose"], g["people"])


def test_a_pixel_on_the_optical_axis_lands_where_the_tilted_camera_looks_at_the_floor():
    # 85 x 61 px: the shrunk grid samples the principal point (42, 30) exactly
    h, pitch = 0.8, 0.3
    spec = RgbdSpec(width=85, height=61, fovy=50.0, mount=(0.2, 0.1, h, 0.0, pitch))
    depth = np.zeros((61 // STRIDE, 85 // STRIDE), dtype=np.float32)
    r, c = (30 - STRIDE // 2) // STRIDE, (42 - STRIDE // 2) // STRIDE
    depth[r, c] = h / math.sin(pitch)  # along the optical axis to the floor
    pts = base_points(depth, spec)
    np.testing.assert_allclose(pts[r, c], [0.2 + h / math.tan(pitch), 0.1, 0.0], atol=1e-6)
    np.testing.assert_allclose(pts[0, 0], [0.2, 0.1, h])  # no return: the camera itself


def test_the_shipped_detector_finds_the_people_of_the_golden_frame_and_not_the_box():
    depth, _, pose, people = golden()
    det = RgbdPeopleDetector()
    xy, score = det.people(depth, det.pixel_scores(depth, CAMERA), CAMERA)
    truth = to_base(people, pose)
    sure = xy[score >= 0.6]
    assert len(sure) == len(truth)
    for p in truth:
        assert np.min(np.hypot(*(sure - p).T)) < 0.3, p


def test_candidates_carry_their_features():
    depth, _, _, _ = golden()
    det = RgbdPeopleDetector()
    xy, feats = det.candidates(depth, det.pixel_scores(depth, CAMERA), CAMERA)
    assert feats.shape == (len(xy), len(BLOB_FEATURES))
    f = dict(zip(BLOB_FEATURES, feats[np.argmin(np.hypot(*(xy - [3.0, 0.0]).T))], strict=True))
    # the person 3 m ahead: pixels from the floor to their head, about their body's width
    assert f["bottom"] < 0.3 and 1.4 < f["top"] < 2.0
    assert 0.2 < f["area"] < 1.2 and 2.5 < f["range"] < 3.2 and f["spread"] < 0.3


def test_a_wrong_weights_file_is_a_one_line_error(tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, w1=np.zeros(3))
    with pytest.raises(ConfigError, match=r"bad\.npz: not an RGB-D people detector"):
        RgbdPeopleDetector(bad)


def test_the_golden_frame_is_what_the_camera_renders_today():
    from tests.mujoco_kit import require_mujoco

    require_mujoco(module=False)
    depth, rgb = shrink(render())
    g_depth, g_rgb, _, _ = golden()
    assert np.mean(np.abs(depth - g_depth) < 0.02) > 0.99
    assert np.mean(np.abs(rgb - g_rgb) < 0.05) > 0.98


def test_labelled_frames_mark_the_people_the_camera_shows():
    from tests.mujoco_kit import require_mujoco

    require_mujoco(module=False)
    cfg = load_config(None, ["map={type: empty, width: 8, height: 8}", "task.obstacles.static=0",
                             "task.obstacles.dynamic=6", "sim.backend.type=mujoco", "seed=4",
                             "task.robots.min_goal_distance=3"])
    samples = list(labelled_frames(cfg, episodes=1, steps=30, every=4))
    assert len(samples) == 7
    s = samples[-1]
    assert s.depth.shape == (60, 80) and s.rgb.shape == (60, 80, 3) and s.mask.shape == (60, 80)
    assert s.people.shape == (6, 2) and s.visible.shape == (6,)
    seen = [x for x in samples if x.visible.any()]
    assert seen and all(x.mask.any() for x in seen)  # a visible person shows in the mask
    # a visible person lies in the camera's field of view (73 degrees across)
    for x in seen:
        p = x.people[x.visible]
        assert np.all(np.abs(np.arctan2(p[:, 1], p[:, 0] - x.spec.mount[0])) < math.radians(40))
    again = list(labelled_frames(cfg, episodes=1, steps=30, every=4))
    assert all(np.array_equal(a.depth, b.depth) for a, b in zip(samples, again, strict=True))
