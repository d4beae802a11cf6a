"""Average precision of detections against the visible people."""

from __future__ import annotations

import numpy as np
import pytest

from arena.perception.scoring import average_precision


def test_average_precision_on_hand_made_detections():
    people = [np.array([[0.0, 0.0], [5.0, 0.0]]), np.array([[1.0, 1.0]])]
    visible = [np.array([True, True]), np.array([False])]
    # frame 0: a sure hit, a wrong one, then the second person late; frame 1: a hidden person
    dets = [(np.array([[0.1, 0.0], [9.0, 9.0], [5.2, 0.0]]), np.array([0.9, 0.8, 0.3])),
            (np.array([[1.0, 1.1]]), np.array([0.95]))]
    ap, recall, precision = average_precision(dets, people, visible, 0.5)
    # ranked: hidden (ignored), hit (P 1, R .5), miss (P .5), hit (P 2/3, R 1)
    assert recall.tolist() == [0.5, 0.5, 1.0]
    assert precision.tolist() == pytest.approx([1.0, 0.5, 2 / 3])
    assert ap == pytest.approx(0.5 * 1.0 + 0.5 * 2 / 3)
    assert average_precision(dets, people, visible, 0.05)[0] == 0.0
