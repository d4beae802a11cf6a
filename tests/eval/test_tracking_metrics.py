"""Tracking metrics of runs on perceived people, the perception part of a record and its file."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from arena.eval.io import load_record, save_record
from arena.eval.metrics import compute_metrics
from arena.eval.record import PerceptionRecord
from arena.eval.recorder import with_perception
from arena.perception.stage import Perceived
from arena.perception.tracker import Tracks
from tests.eval._records import straight

T = 10
NAMES = ["tracking_mota", "tracking_motp", "tracking_idf1", "tracking_id_switches"]


def crowd_record():
    """Two people walking side by side (ids 7 and 8, 2 m apart) and one (id 9) far away."""
    peds = []
    for r in range(T):
        x = 0.3 * r
        peds += [(r, 7, x, 2.0, 3, 0, 0, 0.3), (r, 8, x, 4.0, 3, 0, 0, 0.3),
                 (r, 9, 20.0, 20.0, 0, 0, 0, 0.3)]
    return straight(T, peds=peds)


def perception(rec, tracks_of_row, seen_ids=(7, 8)):
    """A PerceptionRecord: ``tracks_of_row(r) -> [(track id, x, y)]``, people seen by id."""
    rows, ids, pos = [], [], []
    for r in range(T):
        for tid, x, y in tracks_of_row(r):
            rows.append(r)
            ids.append(tid)
            pos.append((x, y))
    return PerceptionRecord(
        perceived=np.ones(T, bool), seen=np.isin(rec.ped_id, seen_ids),
        trk_row=np.array(rows, np.int64), trk_id=np.array(ids, np.int64),
        trk_position=np.array(pos, float).reshape(-1, 2),
        det_row=np.zeros(0, np.int64), det_position=np.zeros((0, 2)),
    )


def metrics(rec):
    return compute_metrics(rec, NAMES)


def test_perfect_tracks_score_one_and_ground_truth_runs_score_nan():
    rec = crowd_record()
    assert all(math.isnan(v) for v in metrics(rec).values())  # no perception: ground truth
    good = dataclasses.replace(rec, perception=perception(
        rec, lambda r: [(1, 0.3 * r + 0.1, 2.0), (2, 0.3 * r, 4.0)]))
    m = metrics(good)
    assert m["tracking_mota"] == 1.0 and m["tracking_idf1"] == 1.0
    assert m["tracking_id_switches"] == 0.0
    assert m["tracking_motp"] == pytest.approx(0.05)  # 0.1 m off for one of the two


def test_swapped_ids_misses_and_false_tracks_are_counted():
    rec = crowd_record()

    def swapped(r):  # the two tracks swap people half way
        a, b = (1, 2) if r < T // 2 else (2, 1)
        return [(a, 0.3 * r, 2.0), (b, 0.3 * r, 4.0)]

    m = metrics(dataclasses.replace(rec, perception=perception(rec, swapped)))
    assert m["tracking_id_switches"] == 2.0
    assert m["tracking_mota"] == pytest.approx(1 - 2 / (2 * T))
    assert m["tracking_idf1"] == pytest.approx(0.5)
    # person 8 never tracked and a false track 5 m from anyone: FN = T, FP = T
    m = metrics(dataclasses.replace(rec, perception=perception(
        rec, lambda r: [(1, 0.3 * r, 2.0), (5, 10.0, 10.0)])))
    assert m["tracking_mota"] == pytest.approx(1 - (T + T) / (2 * T))


def test_a_track_on_a_person_the_sensors_did_not_show_is_neither_right_nor_wrong():
    rec = crowd_record()
    both = perception(rec, lambda r: [(1, 0.3 * r, 2.0), (2, 0.3 * r, 4.0), (3, 20.0, 20.0)])
    m = metrics(dataclasses.replace(rec, perception=both))
    assert m["tracking_mota"] == 1.0  # person 9 unseen: their track is left out
    assert metrics(dataclasses.replace(rec, perception=dataclasses.replace(
        both, seen=np.ones_like(both.seen))))["tracking_mota"] == 1.0  # seen: a match


def test_perceived_ticks_land_on_the_rows_of_their_time_and_survive_the_file(tmp_path):
    rec = crowd_record()

    def tick(r):
        ids = np.array([1, 2])
        tracks = Tracks(ids, np.array([[0.3 * r, 2.0], [0.3 * r, 4.0]]), np.zeros((2, 2)),
                        np.zeros((2, 4, 4)), np.ones(2, bool))
        return (rec.time[r], Perceived(np.array([[0.3 * r, 2.1]]), tracks,
                                       np.array([True, True, False])))

    log = [tick(r) for r in range(2, T - 1)]
    out = with_perception(rec, log)
    assert with_perception(rec, []) is rec
    p = out.perception
    assert p.perceived.tolist() == [False, False] + [True] * (T - 3) + [False]
    assert p.seen.tolist() == [False] * 6 + [True, True, False] * (T - 3) + [False] * 3
    assert np.bincount(p.trk_row, minlength=T).tolist() == [0, 0] + [2] * (T - 3) + [0]
    assert p.det_position[0].tolist() == [0.6, 2.1]
    assert metrics(out)["tracking_mota"] == 1.0
    back = load_record(save_record(out, tmp_path / "e.parquet")).perception
    for f in dataclasses.fields(PerceptionRecord):
        a, b = getattr(p, f.name), getattr(back, f.name)
        assert a.dtype == b.dtype and np.array_equal(a, b), f.name
    with pytest.raises(ValueError, match="trk_row must index the robot rows"):
        dataclasses.replace(rec, perception=dataclasses.replace(p, trk_row=p.trk_row + T))
