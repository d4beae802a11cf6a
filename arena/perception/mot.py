"""Tracking metrics against the ground truth: CLEAR MOT (MOTA, MOTP, id switches) and IDF1.

:class:`MotAccumulator` takes one frame at a time: the ground-truth people (ids, positions) and
the tracker's hypotheses (track ids, positions). A hypothesis matches a person when they are at
most ``threshold`` m apart.

CLEAR MOT (Bernardin and Stiefelhagen, 2008), per frame: a person's match from the previous
frame is kept while it stays within the threshold; the other people and hypotheses are paired
by ``scipy.optimize.linear_sum_assignment`` on distance. A person matched to another hypothesis
than at their last match is an **id switch**. Unmatched people are **misses** (FN), unmatched
hypotheses **false positives** (FP). ``MOTA = 1 − (FN + FP + IDSW) / GT`` over all frames (GT:
ground-truth detections; MOTA may be negative), ``MOTP`` the mean distance of the matches (m,
lower is better).

IDF1 (Ristani et al., 2016): every ground-truth id is matched to at most one track id for the
whole sequence, maximising the frames where the two are within the threshold (IDTP);
``IDF1 = 2 IDTP / (2 IDTP + IDFP + IDFN)`` with IDFN, IDFP the ground-truth and hypothesis
detections left over.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linear_sum_assignment


@dataclass(frozen=True)
class MotScores:
    """The metrics of a sequence (see the module docstring).

    Attributes:
        mota: multiple object tracking accuracy (1 is perfect; NaN without ground truth).
        motp: mean distance of the matches (m; NaN without matches).
        idf1: identity F1 score in [0, 1] (NaN without any detection).
        id_switches: IDSW.
        false_positives: FP.
        misses: FN.
        matches: matched (person, hypothesis) pairs over all frames.
        ground_truth: ground-truth detections over all frames.
        hypotheses: hypothesis detections over all frames.
    """

    mota: float
    motp: float
    idf1: float
    id_switches: int
    false_positives: int
    misses: int
    matches: int
    ground_truth: int
    hypotheses: int


class MotAccumulator:
    """Collects frames of ground truth and hypotheses; :meth:`scores` gives the metrics.

    Args:
        threshold: largest distance (m) at which a hypothesis matches a person.
    """

    def __init__(self, threshold: float = 0.5) -> None:
        if not threshold > 0:
            raise ValueError(f"threshold must be > 0 m, got {threshold}")
        self.threshold = float(threshold)
        self._current: dict[int, int] = {}  # person -> hypothesis matched in the last frame
        self._last: dict[int, int] = {}  # person -> hypothesis at their last match
        self._pairs: dict[tuple[int, int], int] = {}  # (person, hypothesis) -> frames close
        self._gt_count: dict[int, int] = {}
        self._hyp_count: dict[int, int] = {}
        self.matches = self.misses = self.false_positives = self.id_switches = 0
        self._dist_sum = 0.0

    def add_frame(
        self, gt_ids: ArrayLike, gt_pos: ArrayLike, hyp_ids: ArrayLike, hyp_pos: ArrayLike
    ) -> None:
        """One frame: ``(n,)`` person ids, ``(n, 2)`` positions; ``(m,)`` track ids, ``(m, 2)``."""
        gi = np.asarray(gt_ids, dtype=np.int64).reshape(-1)
        gp = np.asarray(gt_pos, dtype=np.float64).reshape(-1, 2)
        hi = np.asarray(hyp_ids, dtype=np.int64).reshape(-1)
        hp = np.asarray(hyp_pos, dtype=np.float64).reshape(-1, 2)
        if gi.shape[0] != gp.shape[0] or hi.shape[0] != hp.shape[0]:
            raise ValueError("ids and positions must have the same length")
        t = self.threshold
        dist = np.hypot(*(gp[:, None, :] - hp[None, :, :]).transpose(2, 0, 1)) if (
            gi.size and hi.size) else np.zeros((gi.size, hi.size))
        close = dist <= t
        for a, b in zip(*np.nonzero(close), strict=True):  # for IDF1
            key = (int(gi[a]), int(hi[b]))
            self._pairs[key] = self._pairs.get(key, 0) + 1
        for g in gi.tolist():
            self._gt_count[g] = self._gt_count.get(g, 0) + 1
        for h in hi.tolist():
            self._hyp_count[h] = self._hyp_count.get(h, 0) + 1
        row_of = {int(g): k for k, g in enumerate(gi)}
        col_of = {int(h): k for k, h in enumerate(hi)}
        matched: dict[int, int] = {}
        for g, h in self._current.items():  # keep last frame's matches still within reach
            if g in row_of and h in col_of and close[row_of[g], col_of[h]]:
                matched[g] = h
        free_r = [k for k, g in enumerate(gi.tolist()) if g not in matched]
        used = set(matched.values())
        free_c = [k for k, h in enumerate(hi.tolist()) if h not in used]
        if free_r and free_c:
            sub = dist[np.ix_(free_r, free_c)]
            cost = np.where(sub <= t, sub, 1e9)
            rows, cols = linear_sum_assignment(cost)
            for r, c in zip(rows.tolist(), cols.tolist(), strict=True):
                if cost[r, c] < 1e9:
                    g, h = int(gi[free_r[r]]), int(hi[free_c[c]])
                    if g in self._last and self._last[g] != h:
                        self.id_switches += 1
                    matched[g] = h
        for g, h in matched.items():
            self._dist_sum += float(dist[row_of[g], col_of[h]])
            self._last[g] = h
        self._current = matched
        self.matches += len(matched)
        self.misses += gi.size - len(matched)
        self.false_positives += hi.size - len(matched)

    def scores(self) -> MotScores:
        """The metrics of the frames added so far."""
        gt = sum(self._gt_count.values())
        hyp = sum(self._hyp_count.values())
        errors = self.misses + self.false_positives + self.id_switches
        mota = 1.0 - errors / gt if gt else math.nan
        motp = self._dist_sum / self.matches if self.matches else math.nan
        idtp = 0
        if self._pairs:
            people = sorted(self._gt_count)
            tracks = sorted(self._hyp_count)
            pi = {g: k for k, g in enumerate(people)}
            ti = {h: k for k, h in enumerate(tracks)}
            counts = np.zeros((len(people), len(tracks)))
            for (g, h), c in self._pairs.items():
                counts[pi[g], ti[h]] = c
            rows, cols = linear_sum_assignment(-counts)
            idtp = int(counts[rows, cols].sum())
        idf1 = 2 * idtp / (gt + hyp) if gt + hyp else math.nan
        return MotScores(mota, motp, idf1, self.id_switches, self.false_positives, self.misses,
                         self.matches, gt, hyp)
