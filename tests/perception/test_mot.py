"""CLEAR MOT and IDF1 on hand-made sequences with known answers."""

from __future__ import annotations

import math

import pytest

from arena.perception.mot import MotAccumulator

A, B = (0.0, 0.0), (5.0, 0.0)


def test_perfect_tracks_score_one():
    acc = MotAccumulator(0.5)
    for t in range(10):
        acc.add_frame([1, 2], [(t, 0.0), (t, 3.0)], [7, 8], [(t + 0.1, 0.0), (t, 3.2)])
    s = acc.scores()
    assert (s.mota, s.idf1, s.id_switches, s.misses, s.false_positives) == (1.0, 1.0, 0, 0, 0)
    assert s.matches == 20 and s.motp == pytest.approx(0.15)


def test_an_id_switch_misses_and_false_positives_are_counted():
    acc = MotAccumulator(0.5)
    for _ in range(4):  # person 1 tracked as 7
        acc.add_frame([1], [A], [7], [A])
    for _ in range(4):  # then as 9: one switch
        acc.add_frame([1], [A], [9], [A])
    acc.add_frame([1], [A], [], [])  # a miss
    acc.add_frame([1], [A], [9, 3], [A, B])  # a false positive far away
    s = acc.scores()
    assert s.id_switches == 1 and s.misses == 1 and s.false_positives == 1
    assert s.ground_truth == 10 and s.matches == 9
    assert s.mota == pytest.approx(1 - 3 / 10)
    # IDF1: person 1 <-> track 9 (5 frames) beats track 7 (4): IDTP 5 of 10 gt, 10 hyp
    assert s.idf1 == pytest.approx(2 * 5 / 20)


def test_a_kept_match_is_not_stolen_by_a_closer_newcomer():
    acc = MotAccumulator(1.0)
    acc.add_frame([1], [A], [7], [(0.8, 0.0)])
    acc.add_frame([1], [A], [7, 8], [(0.8, 0.0), (0.1, 0.0)])  # 7 still in reach: kept
    s = acc.scores()
    assert s.id_switches == 0 and s.false_positives == 1


def test_empty_sequences_and_bad_input():
    s = MotAccumulator().scores()
    assert math.isnan(s.mota) and math.isnan(s.motp) and math.isnan(s.idf1)
    with pytest.raises(ValueError, match="threshold must be > 0"):
        MotAccumulator(0.0)
    with pytest.raises(ValueError, match="same length"):
        MotAccumulator().add_frame([1, 2], [A], [], [])
