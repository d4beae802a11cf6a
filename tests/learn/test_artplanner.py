"""ArtPlanner's motion cost: the stepping model's labels, the data set, training, the file."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.learn.artplanner.dataset import make_dataset, random_patches
from arena.learn.artplanner.features import EdgeFeatureParams, edge_features
from arena.learn.artplanner.model import ARTPLANNER_WEIGHTS, MotionCostModel
from arena.learn.artplanner.stepping import SteppingParams, stepping_labels, track_points

P = SteppingParams()


def _label(height, length=0.8, heading=0.0):
    a = np.array([[-length / 2 * math.cos(heading), -length / 2 * math.sin(heading)]])
    b = -a
    ok, t = stepping_labels(height(track_points(a, b, P)), np.array([length]), P)
    return bool(ok[0]), float(t[0])


def test_stepping_model_limits():
    assert _label(lambda q: np.zeros(q.shape[:-1])) == (True, pytest.approx(1 / P.v_max))
    for rise, ok in ((0.1, True), (0.2, False)):  # a step across the edge at x = 0
        assert _label(lambda q, r=rise: r * (q[..., 0] > 0))[0] is ok
    for deg, ok in ((20, True), (30, False)):
        slope = math.tan(math.radians(deg))
        assert _label(lambda q, s=slope: s * q[..., 0])[0] is ok  # up the slope
        assert _label(lambda q, s=slope: s * q[..., 1])[0] is (deg < 20.1)  # across: roll
    up = _label(lambda q: 0.2 * q[..., 0])[1]
    down = _label(lambda q: -0.2 * q[..., 0])[1]
    assert up > down > 1 / P.v_max
    bumps = _label(lambda q: 0.15 * (np.sin(40 * q[..., 0]) > 0.9))  # 15 cm bumps, rough
    assert not bumps[0]


def test_features_are_relative_and_rotation_free():
    p = EdgeFeatureParams()
    plane = lambda q: 1.0 + 0.3 * q[..., 0]  # noqa: E731
    a, b = np.array([[0.0, 0.0]]), np.array([[0.6, 0.0]])
    x = edge_features(plane, a, b, p)
    assert x.shape == (1, p.size) and x[0, -1] == pytest.approx(0.6 / p.max_length)
    # the same edge moved and turned on the same (turned) ground gives the same input
    c, s = math.cos(1.0), math.sin(1.0)
    turned = lambda q: 1.0 + 0.3 * (c * (q[..., 0] - 5) + s * (q[..., 1] + 2))  # noqa: E731
    a2 = np.array([[5.0, -2.0]])
    b2 = a2 + 0.6 * np.array([[c, s]])
    np.testing.assert_allclose(edge_features(turned, a2, b2, p), x, atol=1e-5)


def test_dataset_is_deterministic_and_mixed():
    p, s = EdgeFeatureParams(), SteppingParams()
    x1, f1, t1 = make_dataset(3000, p, s, seed=4)
    x2, f2, t2 = make_dataset(3000, p, s, seed=4)
    np.testing.assert_array_equal(x1, x2)
    np.testing.assert_array_equal(f1, f2)
    np.testing.assert_array_equal(t1, t2)
    assert 0.2 < f1.mean() < 0.8  # both classes well represented
    assert np.all(t1 >= 1 / s.v_max - 1e-6)
    z = random_patches(5, 0.1, np.random.default_rng(0))
    assert z.shape == (5, 24, 24) and z.min() == 0.0


def test_shipped_model_loads_and_agrees_with_its_labels_on_fresh_data():
    model = MotionCostModel.load(ARTPLANNER_WEIGHTS)
    x, f, t = make_dataset(4000, model.features, model.stepping, seed=12345)
    p, time = model.predict(x)
    assert np.mean((p >= 0.5) == (f > 0.5)) > 0.93
    ok = f > 0.5
    assert np.median(np.abs(time[ok] - t[ok]) / t[ok]) < 0.1


def test_bad_model_files(tmp_path):
    with pytest.raises(ConfigError, match="no ArtPlanner motion-cost policy file"):
        MotionCostModel.load(tmp_path / "missing.npz")
    other = tmp_path / "lflh.npz"
    other.write_bytes((ARTPLANNER_WEIGHTS.parent / "lflh.npz").read_bytes())
    with pytest.raises(ConfigError, match="policy 'lflh'"):
        MotionCostModel.load(other)


def test_training_is_seeded_and_writes_a_loadable_model(tmp_path):
    pytest.importorskip("torch")
    from arena.learn.artplanner.train import main

    for run in ("a", "b"):
        assert main(["-o", str(tmp_path / run), "--samples", "600", "--epochs", "2",
                     "--hidden", "8", "--seed", "3"]) == 0
    a = MotionCostModel.load(tmp_path / "a" / "model.npz")
    b = MotionCostModel.load(tmp_path / "b" / "model.npz")
    for wa, wb in zip(a.weights, b.weights, strict=True):
        np.testing.assert_array_equal(wa, wb)
    assert a.meta["training"]["samples"] == 600
