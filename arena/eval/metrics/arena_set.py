"""Arena-Rosnav's 13 metrics (arena-evaluation ``metrics.py``), with their intended definitions.

Differences from Arena's code (see the specs §4.2 and §10), all deliberate:

* success checks that the goal was actually reached (Arena: "< 3 collisions");
* pairs and triples are consecutive, never wrapping around to the last samples;
* path length, curvature and roughness use the 2-D position only (Arena includes the yaw);
* path lengths leave teleport jumps out (the driven path);
* normalized curvature and roughness use the path resampled every 0.1 s (``shape_sample_dt``),
  not the recorded rows, so they do not change with the simulation step;
* velocity is ``‖(vx, vy)‖`` of the measured twist (Arena takes the norm of the *position*);
* acceleration and jerk are divided by Δt (Arena: plain differences);
* roughness uses ``L = |p0 − p2|`` (Arena: wrong axes);
* time sums use ``Δt_0 = 0`` (Arena: the first sample's absolute time);
* "seen by pedestrians" uses the bearing pedestrian→robot = bearing robot→pedestrian + π
  (Arena: π − bearing);
* the private zone is a body gap below the paper's 0.5 m (Arena's code: centre distance
  ≤ 1.0 m), a parameter.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from arena.core import geometry
from arena.eval.metrics.base import (
    BoolArray,
    FloatArray,
    MetricParams,
    angle_diff,
    any_per_step,
    driven_segments,
    masked_time,
    metric,
    ped_offsets,
    safe_mean,
    step_dt,
    world_velocity,
)
from arena.eval.record import EpisodeRecord


def goal_distance(record: EpisodeRecord) -> FloatArray:
    """``(T,)`` m, 2-D distance robot→goal at every row."""
    d = record.pose[:, :2] - record.meta.goal[None, :2]
    return np.hypot(d[:, 0], d[:, 1])


def reached_goal(record: EpisodeRecord, params: MetricParams) -> bool:
    """Outcome is "success" and the final 2-D goal distance ≤ goal radius (+ float slack)."""
    if record.steps == 0 or record.meta.outcome != "success":
        return False
    return bool(goal_distance(record)[-1] <= record.meta.goal_radius + params.goal_tolerance)


def segment_lengths(record: EpisodeRecord) -> FloatArray:
    """``(T−1,)`` m, 2-D lengths of consecutive position pairs (teleport jumps included)."""
    return geometry.segment_lengths(record.pose)


def _triples(record: EpisodeRecord) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Consecutive 2-D triples of the recorded rows (see :func:`_point_triples`)."""
    return _point_triples(record.pose[:, :2])


def _point_triples(p: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Consecutive triples of the ``(N, 2)`` m points ``p``.

    Twice the triangle area and the sides a=|p0p1|, b=|p1p2|,
    c=|p0p2| (each ``(N−2,)``, m² and m; empty for N < 3).
    """
    p0, p1, p2 = p[:-2], p[1:-1], p[2:]
    u, v = p1 - p0, p2 - p0
    area2 = np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
    a = np.hypot(*(p1 - p0).T)
    b = np.hypot(*(p2 - p1).T)
    c = np.hypot(*(p2 - p0).T)
    return area2, a, b, c


def menger_curvature(record: EpisodeRecord) -> FloatArray:
    """``(T−2,)`` 1/m, ``k = 4·Area / (a·b·c)`` per consecutive triple (0 if a side is 0)."""
    return _menger(*_triples(record))


def path_length_value(record: EpisodeRecord) -> float:
    """m, sum of the driven 2-D segment lengths.

    Teleport jumps are left out (see :func:`~arena.eval.metrics.base.driven_segments`): they
    count 0 m, kept in place so that the sum rounds as over every segment. The one definition
    of an episode's path length (``EpisodeResult.path_length`` is this of its record).
    """
    return float(np.sum(np.where(driven_segments(record), segment_lengths(record), 0.0)))


def _driven_pieces(record: EpisodeRecord) -> list[slice]:
    """Row slices of the driven stretches between teleport jumps (each ≥ 1 row)."""
    cuts = np.flatnonzero(~driven_segments(record)) + 1
    bounds = [0, *cuts.tolist(), record.steps]
    return [slice(a, b) for a, b in itertools.pairwise(bounds) if b > a]


def resampled_triples(
    record: EpisodeRecord, spacing: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Consecutive triples of the path resampled every ``spacing`` s.

    Each driven stretch (rows between teleport jumps) is resampled at ``t_0 + k·spacing``,
    ``k = 0, 1, …`` up to its last row (a shorter tail is left out), by linear interpolation of
    the recorded 2-D positions in time; triples never span a jump. Returns twice the triangle
    areas (m²) and the sides a=|p0p1|, b=|p1p2|, c=|p0p2| (m), each ``(M,)``.
    """
    parts: list[tuple[FloatArray, FloatArray, FloatArray, FloatArray]] = []
    t_all = np.asarray(record.time, dtype=np.float64)
    for rows in _driven_pieces(record):
        t, p = t_all[rows], record.pose[rows, :2]
        n = math.floor((t[-1] - t[0]) / spacing + 1e-9) + 1
        grid = t[0] + np.arange(n) * spacing
        q = np.stack([np.interp(grid, t, p[:, 0]), np.interp(grid, t, p[:, 1])], axis=1)
        parts.append(_point_triples(q))
    if not parts:
        return np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0)
    area2, a, b, c = (np.concatenate(x) for x in zip(*parts, strict=True))
    return area2, a, b, c


def _menger(area2: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
    """1/m, ``k = 4·Area / (a·b·c)`` per triple (0 if a side is 0)."""
    den = a * b * c
    ok = den > 0
    return np.where(ok, 2.0 * area2 / np.where(ok, den, 1.0), 0.0)


def count_contacts(contact: BoolArray) -> int:
    """Rising edges of a ``(T,)`` contact flag; the state before row 0 counts as no contact."""
    c = contact.astype(np.int8)
    return int(np.count_nonzero(np.diff(c, prepend=np.int8(0)) > 0))


def succeeded(record: EpisodeRecord, params: MetricParams) -> bool:
    """Success under ``params.success_rule``.

    "goal": :func:`reached_goal`; "arena": that and fewer than 2 collisions (the paper's rule).
    """
    if not reached_goal(record, params):
        return False
    return params.success_rule == "goal" or count_contacts(record.collision) < 2


@metric("success", unit="1", description="1 if the episode succeeded and ended inside the goal")
def success(record: EpisodeRecord, params: MetricParams) -> float:
    """1 if the episode succeeded and ended inside the goal.

    1.0 iff ``outcome == "success"`` and ``‖p_T − goal‖ ≤ goal_radius`` (2-D), and, with
    ``success_rule="arena"`` (the Arena 3.0 paper's rule), fewer than 2 collisions (see
    ``collisions``); else 0.0. The default rule "goal" ignores collisions.
    """
    return 1.0 if succeeded(record, params) else 0.0


@metric("collisions", unit="-", description="number of collisions (rising edges of contact)")
def collisions(record: EpisodeRecord, params: MetricParams) -> float:
    """Number of collisions (rising edges of contact).

    Count of rows where ``record.collision`` (contact of any kind) turns on; the state before
    row 0 counts as "no contact", so a contact at row 0 is one collision (Arena does not count
    it).
    """
    return float(count_contacts(record.collision))


@metric("collisions_static", unit="-", description="collisions with walls and obstacles")
def collisions_static(record: EpisodeRecord, params: MetricParams) -> float:
    """Collisions with walls and obstacles.

    Rising edges (as ``collisions``) of ``collision_wall | collision_obstacle``: a contact that
    moves from a wall onto an adjoining obstacle is one collision.
    """
    return float(count_contacts(record.collision_wall | record.collision_obstacle))


@metric("collisions_pedestrian", unit="-", description="collisions with pedestrians")
def collisions_pedestrian(record: EpisodeRecord, params: MetricParams) -> float:
    """Rising edges (as ``collisions``) of ``collision_pedestrian`` (any pedestrian)."""
    return float(count_contacts(record.collision_pedestrian))


@metric("collisions_robot", unit="-", description="collisions with other robots")
def collisions_robot(record: EpisodeRecord, params: MetricParams) -> float:
    """Rising edges (as ``collisions``) of ``collision_robot`` (any other robot)."""
    return float(count_contacts(record.collision_robot))


@metric("time_to_goal", unit="s", description="time from reset to reaching the goal")
def time_to_goal(record: EpisodeRecord, params: MetricParams) -> float:
    """s, ``t_T − t_0`` for a successful episode (see ``success``); NaN otherwise."""
    if not reached_goal(record, params):
        return math.nan
    return float(record.time[-1] - record.time[0])


@metric("path_length", unit="m", description="2-D length of the driven path")
def path_length(record: EpisodeRecord, params: MetricParams) -> float:
    """m, ``Σ_j ‖p_{j+1} − p_j‖`` over the driven 2-D segments.

    Teleport jumps are left out; 0 for fewer than 2 rows.
    """
    return path_length_value(record)


@metric("velocity", unit="m/s", description="mean translational speed ‖(vx, vy)‖")
def velocity(record: EpisodeRecord, params: MetricParams) -> float:
    """m/s, mean over rows of ``‖(vx, vy)‖`` of the measured twist; NaN without rows."""
    return safe_mean(np.hypot(record.velocity[:, 0], record.velocity[:, 1]))


def acceleration_values(record: EpisodeRecord) -> FloatArray:
    """Acceleration magnitudes per consecutive pair.

    ``(T−1,)`` m/s², ``‖v_{j+1} − v_j‖ / Δt`` with world-frame velocity vectors; pairs with
    Δt = 0 are dropped.
    """
    dv = np.diff(world_velocity(record), axis=0)
    dt = np.diff(record.time)
    ok = dt > 0
    return np.asarray(np.hypot(dv[ok, 0], dv[ok, 1]) / dt[ok], dtype=np.float64)


def jerk_values(record: EpisodeRecord) -> FloatArray:
    """Jerk magnitudes per consecutive triple.

    ``(T−2,)`` m/s³, ``‖a_{j+1} − a_j‖ / ((Δt_j + Δt_{j+1}) / 2)`` with
    ``a_j = (v_{j+1} − v_j)/Δt_j`` (world-frame vectors); uniform Δt gives ``‖Δ²v‖/Δt²``.
    """
    if record.steps < 3:
        return np.zeros(0)
    keep = np.concatenate([[True], np.diff(record.time) > 0])  # drop repeated time stamps
    v, dt = world_velocity(record)[keep], np.diff(record.time[keep])
    if dt.shape[0] < 2:
        return np.zeros(0)
    a = np.diff(v, axis=0) / dt[:, None]
    da = np.diff(a, axis=0) / (0.5 * (dt[:-1] + dt[1:]))[:, None]
    return np.asarray(np.hypot(da[:, 0], da[:, 1]), dtype=np.float64)


@metric("acceleration", unit="m/s^2", description="mean acceleration magnitude")
def acceleration(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean acceleration magnitude.

    m/s², mean of ``‖Δv‖/Δt`` over consecutive pairs (world-frame velocity vectors, so turning
    at constant speed counts); NaN with fewer than 2 rows. Arena: plain speed differences.
    """
    return safe_mean(acceleration_values(record))


@metric("jerk", unit="m/s^3", description="mean jerk magnitude (derivative of acceleration)")
def jerk(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean jerk magnitude (derivative of acceleration).

    m/s³, mean of the second finite difference of velocity over Δt² (see
    :func:`jerk_values`); NaN with fewer than 3 rows.
    """
    return safe_mean(jerk_values(record))


@metric("curvature", unit="1/m", description="mean Menger curvature of consecutive triples")
def curvature(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean Menger curvature of consecutive triples.

    1/m, mean over consecutive 2-D triples of ``4·Area/(|p0p1|·|p1p2|·|p0p2|)`` (0 for a
    degenerate triple, as Arena); NaN with fewer than 3 rows. (Arena's plots label it "m".)
    """
    return safe_mean(menger_curvature(record))


@metric("curvature_max", unit="1/m", description="largest Menger curvature of the path")
def curvature_max(record: EpisodeRecord, params: MetricParams) -> float:
    """1/m, maximum over consecutive triples of the Menger curvature; NaN with < 3 rows."""
    k = menger_curvature(record)
    return float(np.max(k)) if k.size else math.nan


@metric("normalized_curvature", unit="1", description="mean curvature times local arc length")
def normalized_curvature(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean curvature times local arc length.

    Dimensionless, on the path resampled every ``shape_sample_dt`` s (default 0.1 s, see
    :func:`resampled_triples`), so the value does not depend on the simulation step: mean over
    the resampled triples of ``k · (|p0p1| + |p1p2|)`` with the Menger curvature ``k`` (1/m;
    ≈ the turning angle in rad over 2·``shape_sample_dt``); NaN with fewer than 3 samples.
    """
    area2, a, b, c = resampled_triples(record, params.shape_sample_dt)
    return safe_mean(_menger(area2, a, b, c) * (a + b))


@metric("roughness", unit="1", description="mean 2·Area/L² of consecutive triples")
def roughness(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean 2·Area/L² of consecutive triples.

    Dimensionless, on the path resampled every ``shape_sample_dt`` s (default 0.1 s, see
    :func:`resampled_triples`), so the value does not depend on the simulation step: mean over
    the resampled triples of ``2·Area / |p0 − p2|²`` (Area in m², 0 where ``p0 = p2``); NaN
    with fewer than 3 samples.
    """
    area2, _, _, c = resampled_triples(record, params.shape_sample_dt)
    ok = c > 0
    return safe_mean(np.where(ok, area2 / np.where(ok, c * c, 1.0), 0.0))


@metric("angle_over_length", unit="rad/m", description="total heading change per metre")
def angle_over_length(record: EpisodeRecord, params: MetricParams) -> float:
    """Total heading change per metre of the driven path.

    rad/m, ``Σ_j angle_diff(ψ_{j+1}, ψ_j) / path_length`` over the driven segments (teleport
    jumps left out of both sums); NaN if the path length is 0.
    """
    length = path_length_value(record)
    return heading_change_value(record) / length if length > 0 else math.nan


def heading_change_value(record: EpisodeRecord) -> float:
    """rad, ``Σ_j angle_diff(ψ_{j+1}, ψ_j)`` over the driven segments (teleport jumps left out)."""
    turn = angle_diff(record.pose[1:, 2], record.pose[:-1, 2])
    return float(np.sum(turn[driven_segments(record)]))


@metric("time_in_private_zone", unit="s", description="time a pedestrian was in the private zone")
def time_in_private_zone(record: EpisodeRecord, params: MetricParams) -> float:
    """Time a pedestrian was in the private zone.

    s, ``Σ Δt_j`` (Δt_0 = 0) over rows where the body gap to some pedestrian,
    ``‖p_ped − p_robot‖ − r_ped − r_robot`` (m, the robot's bounding circle ``meta.robot_radius``
    and the pedestrian's ``ped_radius``), is below ``private_zone_radius`` (default 0.5 m,
    paper). A centre distance of 0.5 m would count only collisions: a jackal (0.267 m) and a
    person (0.3 m) touch at 0.567 m.
    """
    _, dist = ped_offsets(record)
    gap = dist - record.ped_radius - record.meta.robot_radius
    return masked_time(record, any_per_step(record, gap < params.private_zone_radius))


def _bearing_robot_to_ped(record: EpisodeRecord) -> FloatArray:
    rel, _ = ped_offsets(record)
    return np.arctan2(rel[:, 1], rel[:, 0])


@metric("time_looking_at_pedestrians", unit="s", description="time the robot faced a pedestrian")
def time_looking_at_pedestrians(record: EpisodeRecord, params: MetricParams) -> float:
    """Time the robot faced a pedestrian.

    s, ``Σ Δt_j`` over rows where some pedestrian's bearing from the robot is within
    ``robot_gaze_half_angle`` (5°) of the robot's yaw: ``|angle_diff(ψ, atan2(dy, dx))| ≤ α``.
    """
    yaw = record.pose[record.ped_row, 2]
    flags = angle_diff(yaw, _bearing_robot_to_ped(record)) <= params.robot_gaze_half_angle
    return masked_time(record, any_per_step(record, flags))


@metric("time_seen_by_pedestrians", unit="s", description="time a pedestrian faced the robot")
def time_seen_by_pedestrians(record: EpisodeRecord, params: MetricParams) -> float:
    """Time a pedestrian faced the robot.

    s, ``Σ Δt_j`` over rows where some pedestrian's heading is within
    ``pedestrian_gaze_half_angle`` (5°) of its bearing to the robot (robot→ped bearing + π).
    """
    to_robot = _bearing_robot_to_ped(record) + np.pi
    flags = angle_diff(record.ped_heading, to_robot) <= params.pedestrian_gaze_half_angle
    return masked_time(record, any_per_step(record, flags))


__all__ = [
    "acceleration_values",
    "count_contacts",
    "goal_distance",
    "heading_change_value",
    "jerk_values",
    "menger_curvature",
    "path_length_value",
    "reached_goal",
    "resampled_triples",
    "segment_lengths",
    "step_dt",
    "succeeded",
]
