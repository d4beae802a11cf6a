"""Ego-centric pedestrian feature maps (the ``semantic`` observation part), numpy only.

One implementation for the environments (:class:`arena.learn.observations.ObservationBuilder`)
and the planners that rebuild the observation at run time (``trail``); it imports no
Gymnasium, so the planners run without the ``learn`` extra.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from arena.crowd.semantic import decode_animation, encode_social_state, pedestrian_type_codes
from arena.learn.config import SemanticObsConfig

FloatArray = NDArray[np.float64]
MAX_SPEED = 20.0
"""m/s; velocity features are clipped to ±this (keeps the space bounded)."""


def to_robot_frame(vectors: FloatArray, headings: FloatArray) -> FloatArray:
    """Rotate ``(N, M, 2)`` world-frame vectors by ``−ψ`` of each world's robot ``(N,)``."""
    c, s = np.cos(headings)[:, None], np.sin(headings)[:, None]
    x, y = vectors[..., 0], vectors[..., 1]
    return np.stack([c * x + s * y, -s * x + c * y], axis=-1)


def semantic_maps(
    sc: SemanticObsConfig,
    rel: FloatArray,
    vel: FloatArray,
    kind: NDArray[np.int64],
    state: NDArray[np.int64],
    mask: NDArray[np.bool_],
) -> NDArray[np.float32]:
    """The ``semantic`` part: ego-centric pedestrian feature maps of ``N`` worlds.

    Args:
        sc: the maps' configuration (size, ROI, channels).
        rel: ``(N, M, 2)`` people's positions in the robot frame (m; x ahead, y left).
        vel: ``(N, M, 2)`` their velocities in the robot frame (m/s).
        kind: ``(N, M)`` type codes (0 adult, 1 elder, 2 child).
        state: ``(N, M)`` social-state codes.
        mask: ``(N, M)`` the slot holds a person.

    Returns:
        ``(N, channels, size, size)`` float32; the cell of a person (column along x, row along
        y, the robot at ``size // 2``) holds its channel values, others 0.
    """
    n = rel.shape[0]
    size = sc.size
    grid = np.zeros((n, len(sc.channels), size, size), np.float32)
    if rel.shape[1] == 0:
        return grid
    col = np.floor(rel[..., 0] / sc.roi * size).astype(np.int64) + size // 2
    row = np.floor(rel[..., 1] / sc.roi * size).astype(np.int64) + size // 2
    inside = mask & (col >= 0) & (col < size) & (row >= 0) & (row < size)
    w, p = np.nonzero(inside)
    if w.size == 0:
        return grid
    v = vel[w, p]
    values = {
        "pedestrian_location": np.ones(w.size),
        "pedestrian_type": pedestrian_type_codes(kind[w, p]),
        "pedestrian_vel_x": np.clip(v[:, 0], -MAX_SPEED, MAX_SPEED),
        "pedestrian_vel_y": np.clip(v[:, 1], -MAX_SPEED, MAX_SPEED),
        "pedestrian_social_state": decode_animation(encode_social_state(state[w, p])),
    }
    vals = np.column_stack([values[c] for c in sc.channels]).astype(np.float32)
    chan = np.arange(len(sc.channels))
    grid[w[:, None], chan[None, :], row[w, p][:, None], col[w, p][:, None]] = vals
    return grid
