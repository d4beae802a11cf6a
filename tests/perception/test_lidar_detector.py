"""The lidar people detector: the shipped weights on known scans, AP, training, the data."""

from __future__ import annotations

import numpy as np
import pytest

from arena.config import load_config
from arena.core.errors import ConfigError
from arena.maps.grid import OccupancyGrid
from arena.perception.lidar_data import labelled_frames
from arena.perception.lidar_detector import LidarPeopleDetector, train
from arena.perception.scoring import average_precision
from arena.sensors.lidar2d import Lidar2D
from arena.sensors.spec import LidarSpec

SPEC = LidarSpec(angle_min=-np.pi, angle_max=np.pi, num_beams=720, range_max=12.0)


def room_scan(circles: list[tuple[float, float, float]]) -> np.ndarray:
    """A 10 x 10 m room (walls around, a desk-sized box), the sensor at (5, 5) facing +x."""
    occ = np.zeros((200, 200), dtype=bool)
    occ[:3, :] = occ[-3:, :] = occ[:, :3] = occ[:, -3:] = True
    occ[30:50, 150:180] = True  # a 1.5 x 1 m box at (7.5-9, 1.5-2.5)
    lidar = Lidar2D(SPEC)
    lidar.bind(OccupancyGrid.from_occupied(occ, 0.05))
    c = np.array(circles, dtype=np.float64).reshape(-1, 3)
    return lidar.scan(np.array([5.0, 5.0, 0.0]), c[:, :2], c[:, 2])


def test_the_shipped_detector_finds_legs_and_bodies_and_not_the_walls():
    # a person as two legs 3 m ahead, one as a body circle 2.5 m to the left, one far right
    people = np.array([[3.0, 0.0], [0.0, 2.5], [1.0, -3.0]])  # sensor frame
    circles = [(8.0, 5.1, 0.07), (8.0, 4.9, 0.07), (5.0, 7.5, 0.25), (6.0, 2.0, 0.25)]
    det = LidarPeopleDetector()
    xy, score = det.detect(room_scan(circles), SPEC.angles(), SPEC.range_max)
    sure = xy[score >= 0.5]
    for p in people:
        assert np.min(np.hypot(*(sure - p).T)) < 0.15, p
    # nothing sure away from the people: walls and the box are not people
    assert all(np.min(np.hypot(*(people - q).T)) < 0.5 for q in sure)
    empty_xy, _ = det.detect(room_scan([]), SPEC.angles(), SPEC.range_max)
    assert len(empty_xy) == 0 or np.all(det.detect(room_scan([]), SPEC.angles(),
                                                   SPEC.range_max)[1] < 0.5)


def test_training_on_simulated_scans_gives_a_working_detector(tmp_path):
    cfg = load_config(None, ["map={type: rosnav_indoor}", "task.obstacles.static=2",
                             "task.obstacles.dynamic=12", "sim.backend.pedestrian_body=legs",
                             "seed=5"])
    frames = list(labelled_frames(cfg, episodes=2, steps=60, every=5))
    again = list(labelled_frames(cfg, episodes=2, steps=60, every=5))
    assert [f.labels.tolist() for f in frames] == [f.labels.tolist() for f in again]
    x = np.concatenate([f.segments.features for f in frames])
    y = np.concatenate([f.labels for f in frames])
    assert 0 < y.sum() < y.size
    train(x, y, tmp_path / "d.npz")
    det = LidarPeopleDetector(tmp_path / "d.npz")
    found = [det.people(f.segments, det.segment_scores(f.segments)) for f in frames]
    ap, _, _ = average_precision(found, [f.people for f in frames],
                                 [f.visible for f in frames], 0.5)
    assert ap > 0.6
    # positive segments lie at people, negative ones mostly not
    for f in frames:
        for c in f.segments.centroids[f.labels == 1]:
            assert np.min(np.hypot(*(f.people - c).T)) < 0.5


def test_a_bad_weights_file_is_a_one_line_error(tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, mean=np.zeros(3))
    with pytest.raises(ConfigError, match=r"bad\.npz: not a lidar people detector"):
        LidarPeopleDetector(bad)
    with pytest.raises(ConfigError, match="not a lidar people detector"):
        LidarPeopleDetector(tmp_path / "missing.npz")
