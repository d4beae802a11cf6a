"""Scoring detectors: average precision of detected positions against the visible people.

Both people detectors (lidar and RGB-D) give per frame ``(positions (k, 2), scores (k,))`` in
a frame of their own; :func:`average_precision` ranks them over all frames and matches each to
the nearest person within an association radius (m) on the floor plane.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def average_precision(
    detections: Sequence[tuple[F64, F64]], people: Sequence[F64],
    visible: Sequence[NDArray[np.bool_]], radius: float,
) -> tuple[float, F64, F64]:
    """AP of per-frame ``(positions, scores)`` against the visible people, within ``radius`` m.

    Detections of all frames are ranked by score; each, in turn, takes the nearest person of
    its frame not yet taken within ``radius``: a visible one makes it a true positive, a hidden
    one (their sensor does not show them) is ignored, none a false positive. AP is the area under
    the precision-recall curve with precision made non-increasing (the VOC/COCO rule).

    Returns:
        ``(AP, recall (d,), precision (d,))`` over the ranked detections (without the ignored).
    """
    ranked = sorted(
        ((float(s), f, k) for f, (_, sc) in enumerate(detections) for k, s in enumerate(sc)),
        key=lambda t: -t[0],
    )
    total = int(sum(int(np.sum(v)) for v in visible))
    taken = [np.zeros(len(p), dtype=bool) for p in people]
    tp: list[float] = []
    for _, f, k in ranked:
        pos = detections[f][0][k]
        free = ~taken[f]
        if not free.any():
            tp.append(0.0)
            continue
        d = np.where(free, np.hypot(*(people[f] - pos).T), np.inf)
        j = int(np.argmin(d))
        if d[j] > radius:
            tp.append(0.0)
            continue
        taken[f][j] = True
        if visible[f][j]:
            tp.append(1.0)
        # a hidden person: neither right nor wrong
    if not tp or total == 0:
        return 0.0, np.zeros(0), np.zeros(0)
    t = np.array(tp)
    ctp = np.cumsum(t)
    precision = ctp / np.arange(1, t.size + 1)
    recall = ctp / total
    p_mono = np.maximum.accumulate(precision[::-1])[::-1]
    r_prev = np.concatenate([[0.0], recall[:-1]])
    ap = float(np.sum((recall - r_prev) * p_mono))
    return ap, recall, precision
