"""The people tracker: crossings without id switches, velocities, birth, coasting and death."""

from __future__ import annotations

import numpy as np
import pytest

from arena.perception.mot import MotAccumulator
from arena.perception.tracker import Tracker, TrackerParams

DT = 0.1


def passing(rng: np.random.Generator, gap: float, speed: float, noise: float, steps: int = 80):
    """Two people walking towards each other on lines ``gap`` m apart: (time, ids, truth, det)."""
    for k in range(steps):
        t = k * DT
        truth = np.array([[-4.0 + speed * t, 0.0], [4.0 - speed * t, gap]])
        yield t, np.array([0, 1]), truth, truth + rng.normal(0.0, noise, truth.shape)


@pytest.mark.parametrize("seed", range(5))
def test_two_people_passing_1m_apart_keep_their_ids(seed):
    tracker = Tracker()
    acc = MotAccumulator(0.5)
    for t, ids, truth, det in passing(np.random.default_rng(seed), 1.0, 1.0, 0.05):
        tracks = tracker.update(t, det)
        acc.add_frame(ids, truth, tracks.ids, tracks.positions)
    s = acc.scores()
    assert s.id_switches == 0
    assert s.idf1 > 0.97 and s.mota > 0.97  # only the first frame (a track needs 2 hits) misses
    assert s.motp < 0.08


def test_velocity_is_estimated_and_the_covariance_shrinks():
    tracker = Tracker(TrackerParams(meas_std=0.05))
    rng = np.random.default_rng(1)
    first = None
    for k in range(30):
        t = k * DT
        tracks = tracker.update(t, [np.array([1.2 * t, -0.5 * t]) + rng.normal(0, 0.05, 2)])
        if len(tracks) and first is None:
            first = tracks.covariances[0].copy()
    assert tracks.ids.tolist() == [0]
    assert np.allclose(tracks.velocities[0], [1.2, -0.5], atol=0.12)
    assert np.allclose(tracks.positions[0], [1.2 * 2.9, -0.5 * 2.9], atol=0.1)
    assert tracks.covariances[0][2, 2] < 0.2 * first[2, 2]


def test_birth_needs_two_hits_and_a_lone_false_detection_never_becomes_a_track():
    tracker = Tracker()
    assert len(tracker.update(0.0, [[1.0, 1.0]])) == 0  # tentative
    assert tracker.update(0.1, [[1.0, 1.0]]).ids.tolist() == [0]
    tracks = tracker.update(0.2, [[1.0, 1.0], [5.0, 5.0]])  # a spurious one far away
    assert tracks.ids.tolist() == [0]
    tracks = tracker.update(0.3, [[1.0, 1.0]])  # ... gone again: never reported
    assert tracks.ids.tolist() == [0]
    assert tracker.update(0.4, [[1.0, 1.0], [5.0, 5.0]]).ids.tolist() == [0]
    # id 1 was the dropped tentative track: ids are never reused
    assert tracker.update(0.5, [[1.0, 1.0], [5.0, 5.0]]).ids.tolist() == [0, 2]


def test_a_hidden_person_coasts_and_a_vanished_one_dies():
    tracker = Tracker(TrackerParams(max_coast=1.0))
    t = 0.0
    for _ in range(10):  # walking at 1 m/s along x
        tracks = tracker.update(t, [[t, 0.0]])
        t += DT
    for _ in range(5):  # hidden for 0.5 s: coasting on its prediction
        tracks = tracker.update(t, [])
        assert tracks.ids.tolist() == [0] and not tracks.detected[0]
        t += DT
    assert tracks.positions[0, 0] == pytest.approx(t - DT, abs=0.1)
    tracks = tracker.update(t, [[t, 0.0]])  # seen again where it should be: the same id
    assert tracks.ids.tolist() == [0] and tracks.detected[0]
    for _ in range(11):
        t += DT
        tracks = tracker.update(t, [])
    assert len(tracks) == 0  # more than max_coast unseen


def test_bad_input():
    tracker = Tracker()
    tracker.update(1.0, [])
    with pytest.raises(ValueError, match="time went back"):
        tracker.update(0.5, [])
    with pytest.raises(ValueError, match="finite"):
        tracker.update(2.0, [[np.nan, 0.0]])
    with pytest.raises(ValueError, match="gate"):
        TrackerParams(gate=0)
