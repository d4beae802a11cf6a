"""policy_conv: the numpy conv layers and scan pooling equal torch's."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.learn.policy_conv import conv1d, conv2d, numpy_extractor, pool_scans


def test_conv1d_matches_torch():
    torch = pytest.importorskip("torch")
    rng = np.random.default_rng(1)
    x = rng.normal(size=(2, 3, 17))
    w = rng.normal(size=(4, 3, 5))
    b = rng.normal(size=4)
    ref = torch.nn.functional.conv1d(torch.as_tensor(x), torch.as_tensor(w), torch.as_tensor(b),
                                     stride=2).numpy()
    np.testing.assert_allclose(conv1d(x, w, b, 2), ref, atol=1e-12)


@pytest.mark.parametrize("stride", [1, 2, 3])
def test_conv2d_matches_torch(stride):
    torch = pytest.importorskip("torch")
    rng = np.random.default_rng(2)
    x = rng.normal(size=(3, 2, 13, 13))
    w = rng.normal(size=(5, 2, 3, 3))
    b = rng.normal(size=5)
    ref = torch.nn.functional.conv2d(torch.as_tensor(x), torch.as_tensor(w), torch.as_tensor(b),
                                     stride=stride).numpy()
    got = conv2d(x, w, b, stride)
    assert got.shape == ref.shape
    np.testing.assert_allclose(got, ref, atol=1e-12)


def test_pool_scans_min_then_mean_per_bin():
    x = np.array([[[1.0, 3.0, 20.0, 5.0], [2.0, 2.0, 0.5, 9.0]]])  # (1, stack 2, 4 beams)
    got = pool_scans(x, clip=10.0, bins=2)
    assert got.shape == (1, 4, 2)
    # min of each scan first (clipped to 10 m, scaled by 1/10), then the means
    np.testing.assert_allclose(got[0], [[0.1, 0.5], [0.2, 0.05], [0.2, 0.75], [0.2, 0.475]])


def test_pool_scans_matches_torch():
    torch = pytest.importorskip("torch")
    from arena.learn.extractors import pool_scans_torch

    x = np.random.default_rng(4).uniform(0, 15, size=(5, 3, 720))
    ref = pool_scans_torch(torch.as_tensor(x), 10.0, 80).numpy()
    np.testing.assert_allclose(pool_scans(x, 10.0, 80), ref, atol=1e-12)


def test_unknown_extractor_is_a_config_error():
    arrays = {"fx/fc/w": np.zeros((2, 2)), "fx/fc/b": np.zeros(2)}
    with pytest.raises(ConfigError, match="unknown feature extractor 'resnet'"):
        numpy_extractor({"type": "resnet", "other_keys": []}, arrays, "p.npz")
