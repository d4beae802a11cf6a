"""The metric registry, the shared metric parameters and :func:`compute_metrics`.

A metric is a pure function of one :class:`~arena.eval.record.EpisodeRecord` and the explicit
:class:`MetricParams`: ``f(record, params) -> float``. It never mutates the record and returns a
finite float, or NaN where its docstring says the value is undefined (e.g. no pedestrians, too
few steps). Metrics are registered with :func:`metric`, which records the name, the SI unit and a
one-line description::

    @metric("path_length", unit="m", description="2-D length of the driven path")
    def path_length(record: EpisodeRecord, params: MetricParams) -> float: ...

Third-party metrics arrive through the ``arena.metrics`` entry-point group; an entry point must
resolve to a :class:`Metric` (build one with ``Metric(name, fn, unit, description)``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, Field

from arena.core.registry import Registry
from arena.eval.record import EpisodeRecord

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


class MetricParams(BaseModel, frozen=True, extra="forbid"):
    """Every parameter any built-in metric reads (lengths in m, angles in rad, times in s)."""

    private_zone_radius: float = Field(
        0.5,
        gt=0,
        description="m, body gap robot-pedestrian (centre distance less both radii) below "
        "which a pedestrian is 'in the private zone'. The Arena 3.0 paper says 0.5 m; Arena's "
        "code (PERSONAL_SPACE_RADIUS) uses 1.0 m centre to centre.",
    )
    robot_gaze_half_angle: float = Field(
        math.radians(5.0), gt=0, description="rad, half-cone of the robot's gaze (Arena: 5°)"
    )
    pedestrian_gaze_half_angle: float = Field(
        math.radians(5.0), gt=0, description="rad, half-cone of a pedestrian's gaze (Arena: 5°)"
    )
    personal_space_radius: float = Field(
        1.2, gt=0, description="m, body gap robot-pedestrian (centre distance less both radii) "
        "below which a pedestrian is in the personal space: Hall (1966) personal distance, close "
        "phase; Francis et al. (2023) use 0.5 m",
    )
    intimate_space_radius: float = Field(
        0.45, gt=0, description="m, body gap robot-pedestrian below which a pedestrian is in the "
        "intimate space: Hall (1966) intimate distance",
    )
    group_distance: float = Field(
        1.5, gt=0, description="m, pedestrians closer than this are linked into one group"
    )
    group_min_size: int = Field(2, ge=2, description="smallest group that has a group space")
    progress_window: float = Field(
        5.0, gt=0, description="s, window over which progress toward the goal is measured"
    )
    progress_min: float = Field(
        0.1, ge=0, description="m, least decrease of the goal distance over one window"
    )
    stall_speed: float = Field(0.05, ge=0, description="m/s, below this speed the robot stalls")
    shortest_path: float | None = Field(
        None,
        ge=0,
        description="m, shortest feasible path length start→goal for SPL and the path length "
        "ratio; None = the straight-line distance (a lower bound)",
    )
    social_force_a: float = Field(
        2.1, gt=0, description="m/s², Helbing repulsion strength A (Helbing & Molnár 1995)"
    )
    social_force_b: float = Field(0.3, gt=0, description="m, Helbing repulsion range B")
    cf_displacement_threshold: float = Field(
        0.2, gt=0, description="m, a person farther than this from their counterfactual "
        "position (the crowd replayed without the robot) counts as displaced",
    )
    tracking_threshold: float = Field(
        0.5, gt=0, description="m, a track farther than this from a person does not match them "
        "(tracking metrics)",
    )
    success_rule: Literal["goal", "arena"] = Field(
        "goal", description="when an episode succeeds: 'goal' (default) = outcome success and "
        "the final position inside the goal radius, collisions allowed (collisions never end an "
        "episode here); 'arena' = the same and fewer than 2 collisions (the Arena 3.0 paper's "
        "rule, for Arena-compatible tables; Arena's code: fewer than 3)",
    )
    goal_tolerance: float = Field(
        1e-9, ge=0, description="m, float slack added to the goal radius in the success test"
    )
    shape_sample_dt: float = Field(
        0.1, gt=0, description="s, time spacing of the path resampled for normalized_curvature "
        "and roughness (so they do not depend on the simulation step; 0.1 s: Arena's 10 Hz)",
    )


MetricFn = Callable[[EpisodeRecord, MetricParams], float]


@dataclass(frozen=True)
class Metric:
    """A registered metric: a pure function plus its name, SI unit and one-line description.

    Attributes:
        name: stable snake_case name (the results column).
        fn: ``fn(record, params) -> float``.
        unit: SI unit string ("m", "m/s", "s", "rad/m", "1" for dimensionless, "-" for counts).
        description: one line, shown in listings.
    """

    name: str
    fn: MetricFn
    unit: str
    description: str

    def __post_init__(self) -> None:
        # The description is the instance docstring, so registry listings show it as summary.
        object.__setattr__(self, "__doc__", self.description)

    def __call__(self, record: EpisodeRecord, params: MetricParams | None = None) -> float:
        """Evaluate the metric on ``record`` (default parameters if ``params`` is ``None``)."""
        return float(self.fn(record, params if params is not None else MetricParams()))


METRICS: Registry[Metric] = Registry("metric", entry_points="arena.metrics")


def metric(
    name: str, *, unit: str, description: str, tags: tuple[str, ...] = ()
) -> Callable[[MetricFn], MetricFn]:
    """Decorator registering ``fn(record, params) -> float`` in :data:`METRICS` as ``name``."""

    def deco(fn: MetricFn) -> MetricFn:
        METRICS.add(name, Metric(name, fn, unit, description), tags=tags)
        return fn

    return deco


def get_metric(name: str) -> Metric:
    """The registered :class:`Metric` called ``name`` (unknown names raise with a close match)."""
    obj = METRICS.get(name)
    if not isinstance(obj, Metric):
        raise TypeError(f"metric {name!r} is registered as {obj!r}, not a Metric")
    return obj


def compute_metrics(
    record: EpisodeRecord,
    names: Iterable[str] | None = None,
    params: MetricParams | Mapping[str, Any] | None = None,
) -> dict[str, float]:
    """Evaluate metrics on one record.

    Args:
        record: the episode.
        names: metric names, in output order; ``None`` = every registered metric (sorted).
        params: a :class:`MetricParams`, a mapping validated into one, or ``None`` (defaults).

    Returns:
        ``{name: value}``; values are floats (NaN where a metric is undefined for the record).
    """
    if params is None:
        p = MetricParams()
    elif isinstance(params, MetricParams):
        p = params
    else:
        p = MetricParams.model_validate(dict(params))
    selected = list(names) if names is not None else METRICS.names()
    return {n: get_metric(n)(record, p) for n in selected}


# -- shared helpers ---------------------------------------------------------------------------
def angle_diff(a: FloatArray | float, b: FloatArray | float) -> FloatArray:
    """Absolute angular difference in ``[0, π]`` rad: ``π − | |a − b| mod 2π − π |``."""
    d = np.mod(np.abs(np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)),
               2 * np.pi)
    return np.asarray(np.pi - np.abs(d - np.pi), dtype=np.float64)


def step_dt(record: EpisodeRecord) -> FloatArray:
    """``(T,)`` s, time each row closes: ``Δt_j = t_j − t_{j−1}``, ``Δt_0 = 0``."""
    t = np.asarray(record.time, dtype=np.float64)
    return np.concatenate([np.zeros(min(1, t.shape[0])), np.diff(t)])


def world_velocity(record: EpisodeRecord) -> FloatArray:
    """``(T, 2)`` m/s, the body twist ``(vx, vy)`` rotated into the world frame by the yaw."""
    th = record.pose[:, 2]
    vx, vy = record.velocity[:, 0], record.velocity[:, 1]
    c, s = np.cos(th), np.sin(th)
    return np.stack([c * vx - s * vy, s * vx + c * vy], axis=1)


def any_per_step(record: EpisodeRecord, flags: BoolArray) -> BoolArray:
    """``(T,)`` True at robot rows where any pedestrian row (long format) has ``flags`` set."""
    out = np.zeros(record.steps, dtype=bool)
    out[record.ped_row[flags]] = True
    return out


def driven_segments(record: EpisodeRecord) -> BoolArray:
    """``(T−1,)`` False for the segments ``j → j+1`` that a teleport made, True for driven ones.

    A teleport of robot 0 is the record event ``(t, "teleport", "robot 0 …")``
    (:func:`arena.eval.episodes.run_episode` and the recorder write it at the time of the row the
    robot left, before the next step): the segment from the row at time ``t`` to the next row
    is the jump (it also holds that step's drive, at most ``v_max·Δt``, which is dropped too).
    """
    driven = np.ones(max(record.steps - 1, 0), dtype=bool)
    if driven.size == 0:
        return driven
    t = np.asarray(record.time, dtype=np.float64)
    for when, kind, detail in record.events:
        if kind != "teleport" or not (detail == "" or detail.startswith("robot 0")):
            continue
        j = int(np.argmin(np.abs(t - float(when))))
        if j < driven.size:
            driven[j] = False
    return driven


def ped_offsets(record: EpisodeRecord) -> tuple[FloatArray, FloatArray]:
    """Per pedestrian row: offset robot→pedestrian ``(K, 2)`` m and its norm ``(K,)`` m."""
    rel = record.ped_position - record.pose[record.ped_row, :2]
    return rel, np.hypot(rel[:, 0], rel[:, 1])


def masked_time(record: EpisodeRecord, mask: BoolArray) -> float:
    """s, ``Σ Δt_j`` over the rows where ``mask`` is set (``Δt_0 = 0``)."""
    return float(np.sum(step_dt(record)[mask]))


def safe_mean(x: FloatArray) -> float:
    """Mean of ``x``, NaN for an empty array (no warning)."""
    return float(np.mean(x)) if x.size else math.nan
