"""Walls of an occupancy grid as few boxes: row runs merged into rectangles across rows."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def _row_runs(row: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """``[(c0, c1), ...]``: the half-open column spans of True cells in ``row``."""
    edges = np.diff(np.concatenate(([0], row.view(np.int8), [0])))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1)
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def merge_boxes(mask: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Cover the True cells of ``mask`` exactly with disjoint rectangles.

    Each row's runs of True cells become spans; a span with the same ``(c0, c1)`` as an open
    rectangle in the row below extends it, any other span opens a new one. Long straight walls
    (rows of one wall share their span) thus give one box each, whatever their length.

    Args:
        mask: ``(rows, cols)`` bool, True = wall.

    Returns:
        ``(k, 4)`` int64 ``[row0, col0, row1, col1]``, half-open cell ranges, ordered by
        ``(row0, col0)``. Their union is the True cells and no two overlap.
    """
    mask = np.ascontiguousarray(mask, dtype=bool)
    done: list[tuple[int, int, int, int]] = []
    open_: dict[tuple[int, int], int] = {}  # (c0, c1) -> first row
    for r in range(mask.shape[0]):
        spans = _row_runs(mask[r]) if mask[r].any() else []
        current: dict[tuple[int, int], int] = {}
        for span in spans:
            current[span] = open_.pop(span, r)
        for (c0, c1), r0 in open_.items():  # spans that ended below this row
            done.append((r0, c0, r, c1))
        open_ = current
    done.extend((r0, c0, mask.shape[0], c1) for (c0, c1), r0 in open_.items())
    out = np.array(sorted(done), dtype=np.int64).reshape(-1, 4)
    return out
