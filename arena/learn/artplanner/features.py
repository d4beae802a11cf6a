"""The motion-cost network's input: a height patch along an edge, in the edge's frame.

For an edge ``a→b`` of length ``L ≤ max_length`` the patch is ``n_along × n_across`` ground
heights: ``n_along`` stations evenly from ``margin`` behind ``a`` to ``margin`` past ``b`` (the
body overhangs both ends), ``n_across`` lateral offsets evenly over ``width`` centred on the
edge (left first). Heights are taken relative to the ground at ``a`` and divided by
``height_scale``; the last input is ``L / max_length``. So the input is the same for an edge
anywhere on the map, turned any way: what the network learns is how the terrain *along the
edge* costs, as ArtPlanner's network sees a height patch around the robot.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

HeightFn = Callable[[NDArray[np.float64]], NDArray[np.float64]]
"""Ground height (m) at world points ``(..., 2)`` → ``(...)``."""


class EdgeFeatureParams(BaseModel):
    """How an edge's height patch is sampled (m)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    n_along: int = Field(21, ge=2, le=64, description="stations along the edge")
    n_across: int = Field(5, ge=1, le=32, description="lateral samples per station")
    width: float = Field(0.5, gt=0, description="m, lateral span of the patch")
    margin: float = Field(0.2, ge=0, description="m sampled behind the start and past the end")
    max_length: float = Field(1.0, gt=0, description="m, longest edge the network rates")
    height_scale: float = Field(0.3, gt=0, description="m per unit of the height inputs")

    @property
    def size(self) -> int:
        """Input size: ``n_along · n_across + 1``."""
        return self.n_along * self.n_across + 1


def patch_points(a: NDArray[np.float64], b: NDArray[np.float64], p: EdgeFeatureParams
                 ) -> NDArray[np.float64]:
    """World points ``(n, n_along, n_across, 2)`` of the patches of edges ``a→b`` (``(n, 2)``)."""
    d = b - a
    length = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
    u = d / length[:, None]
    nrm = np.stack([-u[:, 1], u[:, 0]], axis=-1)
    t = np.linspace(0.0, 1.0, p.n_along)[None, :]
    s = -p.margin + t * (length[:, None] + 2 * p.margin)  # (n, A)
    lat = np.linspace(p.width / 2, -p.width / 2, p.n_across) if p.n_across > 1 \
        else np.zeros(1)
    return (a[:, None, None, :] + s[:, :, None, None] * u[:, None, None, :]
            + lat[None, None, :, None] * nrm[:, None, None, :])


def edge_features(height: HeightFn, a: NDArray[np.float64], b: NDArray[np.float64],
                  p: EdgeFeatureParams) -> NDArray[np.float32]:
    """Network inputs ``(n, p.size)`` float32 of edges ``a→b`` on the ground ``height``.

    Args:
        height: ground height at world points (a :meth:`HeightMap.at
            <arena.maps.terrain.HeightMap.at>`, or a training patch sampler).
        a: ``(n, 2)`` edge starts (m).
        b: ``(n, 2)`` edge ends (m); ``|b - a| ≤ p.max_length`` (longer edges are split by the
            caller).
        p: the sampling layout.
    """
    a = np.asarray(a, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 2)
    z = height(patch_points(a, b, p))  # (n, A, C)
    z0 = height(a)  # (n,)
    rel = (z - z0[:, None, None]) / p.height_scale
    length = np.hypot(*(b - a).T) / p.max_length
    return np.concatenate([rel.reshape(len(a), -1), length[:, None]], axis=1).astype(np.float32)
