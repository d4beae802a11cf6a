"""The RGB-D detector's network in numpy: its convolution and the whole net against torch."""

from __future__ import annotations

import numpy as np
import pytest
import torch  # a test extra (make test installs it): this test must run, not skip

from arena.perception.convnet import LAYERS, PixelNet, conv2d, torch_pixelnet


@pytest.mark.parametrize(("stride", "dilation", "k"), [(1, 1, 3), (2, 1, 3), (1, 2, 3),
                                                       (1, 4, 3), (1, 1, 1), (2, 1, 1)])
def test_conv2d_is_torchs_same_padded_convolution(stride, dilation, k):
    rng = np.random.default_rng(0)
    x = rng.normal(size=(5, 13, 18)).astype(np.float32)
    w = rng.normal(size=(7, 5, k, k)).astype(np.float32)
    b = rng.normal(size=7).astype(np.float32)
    ours = conv2d(x, w, b, stride, dilation)
    ref = torch.nn.functional.conv2d(torch.from_numpy(x)[None], torch.from_numpy(w),
                                     torch.from_numpy(b), stride=stride, dilation=dilation,
                                     padding=dilation * (k - 1) // 2)[0].numpy()
    assert ours.shape == ref.shape
    np.testing.assert_allclose(ours, ref, atol=2e-4)


@pytest.mark.parametrize("shape", [(60, 80), (31, 45)])
def test_the_numpy_net_computes_what_the_torch_net_trains(shape):
    torch.manual_seed(3)
    net = torch_pixelnet(6)
    weights = {}
    for n, *_ in LAYERS:
        weights[f"w{n}"] = net.convs[n].weight.detach().numpy()
        weights[f"b{n}"] = net.convs[n].bias.detach().numpy()
    x = np.random.default_rng(1).random((6, *shape)).astype(np.float32)
    with torch.no_grad():
        ref = net(torch.from_numpy(x)[None])[0, 0].numpy()
    ours = PixelNet(weights).logits(x)
    assert ours.shape == shape
    np.testing.assert_allclose(ours, ref, atol=1e-4)
    with pytest.raises(ValueError, match=r"expected a \(6, h, w\) input"):
        PixelNet(weights).logits(x[:3])
