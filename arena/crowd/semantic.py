"""Semantic layers: per-pedestrian attributes as located evidence, and their grid rasters.

Arena's crowdsim publishes one ``SemanticData`` message per attribute (arena_specs §5.4): a list
of ``(location, evidence)`` points, one per pedestrian (``pedestrian_moving`` lists only the
moving ones). Costmap layers and the RL observation space (``PEDESTRIAN_*`` feature maps) turn
them into grids. Here :func:`semantic_points` builds the points from a
:class:`~arena.crowd.state.CrowdState` and :func:`rasterize` writes them into an ``(H, W)``
layer, vectorised with ``np.add.at`` / ``np.maximum.at``.

Attributes and encodings (Arena's unless noted):

===================  ==========================================================================
``pedestrian``        1 per pedestrian.
``pedestrian_moving`` 1 per pedestrian whose speed exceeds 0.05 m/s. Arena thresholds the norm
                      of its output *force*; an agent walking steadily at its preferred speed
                      feels almost no force, so we use the velocity by default
                      (``moving_from="acceleration"`` restores Arena's criterion).
``pedestrian_vel_x``  velocity x (m/s, world frame). Arena writes the force's x here; we write
``pedestrian_vel_y``  the real velocity, which is what the name and the RL features promise.
``pedestrian_type``   0 adult, 1 elder, −1 anything else (children included, as in Arena).
``social_state``      ``(animation << 8) | 0x01``: Arena's ``Human.Animation`` enum (IDLE 1,
                      WALKING 2, RUNNING 3, INTERACTING 4, TALKING 5, PHONE 6, from
                      ``enum.auto()``) shifted by 8 bits, with the human type's magic number 1
                      in the low byte. Our :class:`SocialState` codes are the animation value
                      minus 1; PANIC (no animation in Arena, it is left at once for running)
                      encodes as RUNNING. Decode with ``int(evidence) >> 8``.
``stress``            the level in [0, 1].
``energy``            the level in [0, 1].
``social``            the level in [0, 1].
===================  ==========================================================================
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.crowd.state import AgentType, CrowdState, SocialState

FloatArray = NDArray[np.float64]
Float32Array = NDArray[np.float32]

MOVING_THRESHOLD = 0.05
"""Arena's "moving" threshold (m/s here; Arena applies it to the force norm)."""

HUMAN_MAGIC = 0x01
"""Low byte of Arena's social-state evidence for the ``Human`` agent class (and ``Elder``)."""


class SemanticAttribute(enum.StrEnum):
    """Names of the semantic layers (Arena's topic suffixes ``crowdsim_agents/semantic/<name>``)."""

    PEDESTRIAN = "pedestrian"
    PEDESTRIAN_MOVING = "pedestrian_moving"
    PEDESTRIAN_VEL_X = "pedestrian_vel_x"
    PEDESTRIAN_VEL_Y = "pedestrian_vel_y"
    PEDESTRIAN_TYPE = "pedestrian_type"
    SOCIAL_STATE = "social_state"
    STRESS = "stress"
    ENERGY = "energy"
    SOCIAL = "social"


class Animation(enum.IntEnum):
    """Arena's ``Human.Animation`` values (``enum.auto()`` from 1)."""

    IDLE = 1
    WALKING = 2
    RUNNING = 3
    INTERACTING = 4
    TALKING = 5
    PHONE = 6


# Indexed by SocialState code: IDLE 0 … PHONE 5 map to animation code + 1; PANIC 6 → RUNNING.
_ANIMATION_OF_STATE = np.array(
    [
        Animation.IDLE,
        Animation.WALKING,
        Animation.RUNNING,
        Animation.INTERACTING,
        Animation.TALKING,
        Animation.PHONE,
        Animation.RUNNING,
    ],
    dtype=np.int64,
)
assert len(_ANIMATION_OF_STATE) == len(SocialState)


def encode_social_state(codes: ArrayLike) -> Float32Array:
    """``(m,)`` evidence ``(animation << 8) | 0x01`` for :class:`SocialState` codes ``(m,)``.

    Unknown codes (outside 0..6) encode as WALKING.
    """
    c = np.asarray(codes, dtype=np.int64)
    valid = (c >= 0) & (c < len(_ANIMATION_OF_STATE))
    anim = np.where(valid, _ANIMATION_OF_STATE[np.where(valid, c, 0)], int(Animation.WALKING))
    return ((anim << 8) | HUMAN_MAGIC).astype(np.float32)


def decode_animation(evidence: ArrayLike) -> NDArray[np.int64]:
    """Arena's animation codes back from ``social_state`` evidence (``evidence >> 8``)."""
    return np.asarray(evidence).astype(np.int64) >> 8


def pedestrian_type_codes(kinds: ArrayLike) -> Float32Array:
    """Arena's type evidence: 0 adult, 1 elder, −1 anything else."""
    k = np.asarray(kinds, dtype=np.int64)
    out = np.full(k.shape, -1.0, dtype=np.float32)
    out[k == AgentType.ADULT] = 0.0
    out[k == AgentType.ELDER] = 1.0
    return out


@dataclass(frozen=True, eq=False)
class SemanticData:
    """One layer's points (Arena's ``SemanticData`` message without header).

    Attributes:
        locations: ``(m, 2)`` m, world frame.
        evidence: ``(m,)`` float32 values.
    """

    locations: FloatArray
    evidence: Float32Array

    def __len__(self) -> int:
        return int(self.evidence.shape[0])


MovingFrom = Literal["velocity", "acceleration"]


def semantic_points(
    state: CrowdState,
    *,
    accelerations: FloatArray | None = None,
    moving_threshold: float = MOVING_THRESHOLD,
    moving_from: MovingFrom = "velocity",
) -> dict[str, SemanticData]:
    """Every semantic layer of the crowd as points at the pedestrians' positions.

    Args:
        state: the crowd.
        accelerations: ``(n, 2)`` m/s², for ``moving_from="acceleration"``; defaults to the sum
            of ``state.forces`` (zero when there are none).
        moving_threshold: m/s (or m/s² with ``moving_from="acceleration"``), strict.
        moving_from: what "moving" thresholds: the speed (default) or the acceleration norm
            (Arena).

    Returns:
        ``attribute name -> SemanticData`` for every :class:`SemanticAttribute`.
    """
    pos = np.asarray(state.positions, dtype=np.float64).reshape(-1, 2)
    n = pos.shape[0]
    vel = np.asarray(state.velocities, dtype=np.float64).reshape(-1, 2)
    if moving_from == "velocity":
        signal = vel
    elif accelerations is not None:
        signal = np.asarray(accelerations, dtype=np.float64).reshape(-1, 2)
    else:
        signal = sum(state.forces.values(), np.zeros((n, 2)))
    moving = np.hypot(signal[:, 0], signal[:, 1]) > moving_threshold

    def layer(values: ArrayLike, where: NDArray[np.bool_] | None = None) -> SemanticData:
        v = np.asarray(values, dtype=np.float32).reshape(n)
        if where is None:
            return SemanticData(pos.copy(), v.copy())
        return SemanticData(pos[where].copy(), v[where].copy())

    A = SemanticAttribute
    return {
        A.PEDESTRIAN.value: layer(np.ones(n)),
        A.PEDESTRIAN_MOVING.value: layer(np.ones(n), moving),
        A.PEDESTRIAN_VEL_X.value: layer(vel[:, 0]),
        A.PEDESTRIAN_VEL_Y.value: layer(vel[:, 1]),
        A.PEDESTRIAN_TYPE.value: layer(pedestrian_type_codes(state.kinds)),
        A.SOCIAL_STATE.value: layer(encode_social_state(state.social_state)),
        A.STRESS.value: layer(state.stress),
        A.ENERGY.value: layer(state.energy),
        A.SOCIAL.value: layer(state.social),
    }


class SemanticLayers:
    """Configured semantic-layer producer (thin wrapper around :func:`semantic_points`).

    Args:
        params: what counts as moving.
    """

    class Params(BaseModel):
        """Parameters of :class:`SemanticLayers`.

        Attributes:
            moving_threshold: m/s (or m/s²), strict, 0.05 (Arena).
            moving_from: ``"velocity"`` (default) or ``"acceleration"`` (Arena's force norm).
        """

        model_config = ConfigDict(frozen=True, extra="forbid")

        moving_threshold: float = Field(MOVING_THRESHOLD, ge=0.0)
        moving_from: MovingFrom = "velocity"

    attributes: tuple[str, ...] = tuple(a.value for a in SemanticAttribute)

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()

    def points(
        self, state: CrowdState, accelerations: FloatArray | None = None
    ) -> dict[str, SemanticData]:
        """Every layer as points (see :func:`semantic_points`)."""
        return semantic_points(
            state,
            accelerations=accelerations,
            moving_threshold=self.params.moving_threshold,
            moving_from=self.params.moving_from,
        )


class GridLike(Protocol):
    """Anything with a resolution (m/cell) and an origin (m, lower-left corner of cell (0, 0)).

    The shape ``(H, W)`` is read from ``shape``, else ``data.shape``, else ``(height, width)``
    (so an :class:`~arena.maps.grid.OccupancyGrid` or a :class:`GridSpec` both work).
    """

    resolution: float
    origin: Any


@dataclass(frozen=True)
class GridSpec:
    """A bare raster frame (e.g. a robot-centred window).

    Attributes:
        resolution: m per cell.
        origin: ``(x, y)`` m of the lower-left corner of cell ``(0, 0)``; row = y, col = x.
        shape: ``(H, W)`` cells.
    """

    resolution: float
    origin: tuple[float, float]
    shape: tuple[int, int]


def _grid_shape(grid: Any) -> tuple[int, int]:
    shape = getattr(grid, "shape", None)
    if shape is None and hasattr(grid, "data"):
        shape = np.shape(grid.data)
    if shape is None:
        shape = (grid.height, grid.width)
    h, w = (int(s) for s in tuple(shape)[:2])
    return h, w


Reduce = Literal["max", "sum", "mean"]


def rasterize(
    data: SemanticData, grid: GridLike, *, reduce: Reduce = "max", radius: float = 0.0
) -> NDArray[np.float32]:
    """Write a layer's points into an ``(H, W)`` float32 raster.

    Each point covers its own cell (``row = ⌊(y − oy)/res⌋``, ``col = ⌊(x − ox)/res⌋``), and with
    ``radius > 0`` also every cell whose centre lies within ``radius`` of it (each covered cell
    receives the point's full evidence). Points and cells off the grid are dropped. Cells no
    point covers are 0.

    Args:
        data: the points.
        grid: resolution, origin and shape of the raster.
        reduce: how several points in one cell combine: ``max``, ``sum`` or ``mean``.
        radius: m, disc radius (0: one cell per point).

    Returns:
        ``(H, W)`` float32, row 0 at the origin's y.
    """
    if reduce not in ("max", "sum", "mean"):
        raise ValueError(f"reduce must be 'max', 'sum' or 'mean', got {reduce!r}")
    if radius < 0.0 or not math.isfinite(radius):
        raise ValueError(f"radius must be a finite non-negative number of metres, got {radius}")
    h, w = _grid_shape(grid)
    res = float(grid.resolution)
    ox, oy = (float(v) for v in tuple(grid.origin)[:2])
    loc = np.asarray(data.locations, dtype=np.float64).reshape(-1, 2)
    ev = np.asarray(data.evidence, dtype=np.float64).reshape(-1)
    col = np.floor((loc[:, 0] - ox) / res).astype(np.int64)
    row = np.floor((loc[:, 1] - oy) / res).astype(np.int64)
    if radius > 0.0:
        k = math.ceil(radius / res)
        dr, dc = np.mgrid[-k : k + 1, -k : k + 1]
        dr, dc = dr.ravel(), dc.ravel()
        rows = row[:, None] + dr[None, :]
        cols = col[:, None] + dc[None, :]
        cx = ox + (cols + 0.5) * res
        cy = oy + (rows + 0.5) * res
        inside = (cx - loc[:, 0, None]) ** 2 + (cy - loc[:, 1, None]) ** 2 <= radius * radius
        inside |= (dr == 0) & (dc == 0)
        row, col = rows[inside], cols[inside]
        ev = np.broadcast_to(ev[:, None], inside.shape)[inside]
    on = (row >= 0) & (row < h) & (col >= 0) & (col < w)
    flat = row[on] * w + col[on]
    ev = ev[on]
    if reduce == "max":
        out = np.full(h * w, -np.inf)
        np.maximum.at(out, flat, ev)
        out[np.isneginf(out)] = 0.0
    else:
        out = np.zeros(h * w)
        np.add.at(out, flat, ev)
        if reduce == "mean":
            count = np.bincount(flat, minlength=h * w)
            out = np.divide(out, count, out=np.zeros_like(out), where=count > 0)
    return out.reshape(h, w).astype(np.float32)
