"""Social-navigation metrics after Francis et al. (2023), Guzzi et al. (2013) and Helbing (1995).

Personal space 1.2 m and intimate space 0.45 m (Hall 1966, close phases; Francis et al. 2023 use
0.5 m for personal space) are body gaps, the centre distance less both radii; groups link
pedestrians whose centres are closer than 1.5 m. All are
:class:`~arena.eval.metrics.base.MetricParams` fields.
"""

from __future__ import annotations

import math

import numpy as np

from arena.eval.metrics.arena_set import (
    acceleration_values,
    goal_distance,
    heading_change_value,
    jerk_values,
    menger_curvature,
    path_length_value,
    succeeded,
)
from arena.eval.metrics.base import (
    FloatArray,
    MetricParams,
    angle_diff,
    any_per_step,
    masked_time,
    metric,
    ped_offsets,
    safe_mean,
    world_velocity,
)
from arena.eval.record import EpisodeRecord


def shortest_length(record: EpisodeRecord, params: MetricParams) -> float:
    """m, ``params.shortest_path`` or the straight-line 2-D distance start→goal (lower bound)."""
    if params.shortest_path is not None:
        return float(params.shortest_path)
    return float(np.hypot(*(record.meta.goal[:2] - record.meta.start[:2])))


def _speed(record: EpisodeRecord) -> FloatArray:
    return np.asarray(np.hypot(record.velocity[:, 0], record.velocity[:, 1]), dtype=np.float64)


@metric("timeout", unit="1", description="1 if the episode ran out of time")
def timeout(record: EpisodeRecord, params: MetricParams) -> float:
    """1.0 iff ``outcome == "timeout"``, else 0.0."""
    return 1.0 if record.meta.outcome == "timeout" else 0.0


@metric("failure_to_progress", unit="1", description="1 if the goal distance stalled for a window")
def failure_to_progress(record: EpisodeRecord, params: MetricParams) -> float:
    """1 if the goal distance stalled for a window.

    1.0 iff the outcome is "stuck", or at some row ``j`` outside the goal with
    ``t_j − t_0 ≥ progress_window`` the goal distance decreased by less than ``progress_min`` over
    the last ``progress_window`` s: ``d(t_j − W) − d(t_j) < progress_min``. Else 0.0.
    """
    if record.meta.outcome == "stuck":
        return 1.0
    if record.steps < 2:
        return 0.0
    t, d = record.time, goal_distance(record)
    i = np.searchsorted(t, t - params.progress_window, side="right") - 1
    valid = (t - t[0] >= params.progress_window) & (i >= 0) & (d > record.meta.goal_radius)
    i = np.clip(i, 0, None)
    return 1.0 if bool(np.any(valid & (d[i] - d < params.progress_min))) else 0.0


@metric("stalled_time", unit="s", description="time spent slower than the stall speed")
def stalled_time(record: EpisodeRecord, params: MetricParams) -> float:
    """s, ``Σ Δt_j`` (Δt_0 = 0) over rows with ``‖(vx, vy)‖ < stall_speed`` outside the goal."""
    mask = (_speed(record) < params.stall_speed) & (goal_distance(record) > record.meta.goal_radius)
    return masked_time(record, mask)


@metric("spl", unit="1", description="success weighted by (shortest / actual) path length")
def spl(record: EpisodeRecord, params: MetricParams) -> float:
    """Success weighted by (shortest / actual) path length.

    Dimensionless, ``S · ℓ / max(p, ℓ)``: S the ``success`` metric (0/1, under
    ``success_rule``), ℓ the shortest path length
    (``shortest_path`` or the straight line start→goal), p the driven 2-D path length; 1.0 for a
    success with ``ℓ = p = 0``.
    """
    if not succeeded(record, params):
        return 0.0
    ell, p = shortest_length(record, params), path_length_value(record)
    return 1.0 if max(ell, p) <= 0 else ell / max(ell, p)


@metric("path_length_ratio", unit="1", description="driven path length / shortest path length")
def path_length_ratio(record: EpisodeRecord, params: MetricParams) -> float:
    """Dimensionless, ``p / ℓ`` (≥ 1 when ℓ is a true lower bound); NaN if ``ℓ = 0``."""
    ell = shortest_length(record, params)
    return path_length_value(record) / ell if ell > 0 else math.nan


@metric("velocity_min", unit="m/s", description="smallest translational speed")
def velocity_min(record: EpisodeRecord, params: MetricParams) -> float:
    """m/s, ``min_j ‖(vx, vy)‖``; NaN without rows."""
    s = _speed(record)
    return float(np.min(s)) if s.size else math.nan


@metric("velocity_max", unit="m/s", description="largest translational speed")
def velocity_max(record: EpisodeRecord, params: MetricParams) -> float:
    """m/s, ``max_j ‖(vx, vy)‖``; NaN without rows."""
    s = _speed(record)
    return float(np.max(s)) if s.size else math.nan


@metric("acceleration_max", unit="m/s^2", description="largest acceleration magnitude")
def acceleration_max(record: EpisodeRecord, params: MetricParams) -> float:
    """m/s², ``max ‖Δv‖/Δt`` over consecutive pairs; NaN with fewer than 2 rows."""
    a = acceleration_values(record)
    return float(np.max(a)) if a.size else math.nan


@metric("jerk_max", unit="m/s^3", description="largest jerk magnitude")
def jerk_max(record: EpisodeRecord, params: MetricParams) -> float:
    """m/s³, maximum of the jerk magnitudes (see ``jerk``); NaN with fewer than 3 rows."""
    j = jerk_values(record)
    return float(np.max(j)) if j.size else math.nan


@metric("acceleration_min", unit="m/s^2", description="smallest acceleration magnitude")
def acceleration_min(record: EpisodeRecord, params: MetricParams) -> float:
    """Smallest acceleration magnitude (Francis et al. 2023, A_min).

    m/s², ``min ‖Δv‖/Δt`` over consecutive pairs of rows (world-frame velocity vectors, the
    values ``acceleration`` and ``acceleration_max`` use); NaN with fewer than 2 rows.
    """
    a = acceleration_values(record)
    return float(np.min(a)) if a.size else math.nan


@metric("jerk_min", unit="m/s^3", description="smallest jerk magnitude")
def jerk_min(record: EpisodeRecord, params: MetricParams) -> float:
    """Smallest jerk magnitude (Francis et al. 2023, J_min).

    m/s³, minimum of the jerk magnitudes per consecutive triple of rows (the values ``jerk``
    and ``jerk_max`` use); NaN with fewer than 3 rows.
    """
    j = jerk_values(record)
    return float(np.min(j)) if j.size else math.nan


@metric("curvature_min", unit="1/m", description="smallest Menger curvature of the path")
def curvature_min(record: EpisodeRecord, params: MetricParams) -> float:
    """Smallest Menger curvature of the path (Arena 3.0 paper).

    1/m, minimum over consecutive 2-D triples of rows of ``4·Area/(|p0p1|·|p1p2|·|p0p2|)``
    (0 for a degenerate triple, as ``curvature`` and ``curvature_max``); NaN with < 3 rows.
    """
    k = menger_curvature(record)
    return float(np.min(k)) if k.size else math.nan


@metric("heading_change", unit="rad", description="cumulative heading change over the path")
def heading_change(record: EpisodeRecord, params: MetricParams) -> float:
    """Cumulative heading change over the driven path (Francis et al. 2023).

    rad, ``Σ_j angle_diff(ψ_{j+1}, ψ_j)`` (each step's yaw change in ``[0, π]``) over the
    driven segments, teleport jumps left out; 0 with fewer than 2 rows.
    """
    return heading_change_value(record)


@metric("min_distance_to_person", unit="m", description="smallest body gap robot-pedestrian")
def min_distance_to_person(record: EpisodeRecord, params: MetricParams) -> float:
    """Smallest body gap robot-pedestrian.

    m, ``min ‖p_ped − p_robot‖ − r_ped − r_robot`` over all pedestrian rows (negative =
    overlap); NaN without pedestrians.
    """
    if record.ped_row.size == 0:
        return math.nan
    _, dist = ped_offsets(record)
    return float(np.min(dist - record.ped_radius - record.meta.robot_radius))


@metric("clearance", unit="m", description="smallest laser range minus the robot radius")
def clearance(record: EpisodeRecord, params: MetricParams) -> float:
    """m, ``min_j min_range_j − r_robot``; NaN if the laser never returned (all ranges inf)."""
    r = record.min_range[np.isfinite(record.min_range)]
    return float(np.min(r) - record.meta.robot_radius) if r.size else math.nan


@metric("time_to_collision", unit="s", description="smallest constant-velocity time to collision")
def time_to_collision(record: EpisodeRecord, params: MetricParams) -> float:
    """Smallest constant-velocity time to collision.

    s, min over pedestrian rows of the time until robot and pedestrian discs touch if both
    keep their current velocity: smallest ``τ ≥ 0`` with ``‖p + v τ‖ = r_ped + r_robot``
    (``p``, ``v`` relative position and velocity); 0 while overlapping. NaN if no pedestrian is
    ever on a collision course (or there are none).
    """
    if record.ped_row.size == 0:
        return math.nan
    p, _ = ped_offsets(record)
    v = record.ped_velocity - world_velocity(record)[record.ped_row]
    rad = record.ped_radius + record.meta.robot_radius
    a = np.einsum("ij,ij->i", v, v)
    b = 2.0 * np.einsum("ij,ij->i", p, v)
    c = np.einsum("ij,ij->i", p, p) - rad * rad
    disc = b * b - 4.0 * a * c
    course = (a > 0) & (b < 0) & (disc >= 0)
    sq = np.sqrt(np.where(course, disc, 0.0))
    tau = np.where(course, (-b - sq) / (2.0 * np.where(course, a, 1.0)), np.inf)
    tau = np.where(c <= 0, 0.0, tau)
    best = float(np.min(tau))
    return best if math.isfinite(best) else math.nan


def _compliance(record: EpisodeRecord, radius: float) -> float:
    if record.steps == 0:
        return math.nan
    _, dist = ped_offsets(record)
    gap = dist - record.ped_radius - record.meta.robot_radius
    return 1.0 - float(np.mean(any_per_step(record, gap < radius)))


@metric("personal_space_compliance", unit="1",
        description="share of steps with no body gap to a person below the personal radius")
def personal_space_compliance(record: EpisodeRecord, params: MetricParams) -> float:
    """Share of steps with no body gap to a person below the personal radius.

    Dimensionless, fraction of rows where every pedestrian's body gap
    ``‖p_ped − p_robot‖ − r_ped − r_robot`` (m, the robot's bounding circle
    ``meta.robot_radius``, the pedestrian's ``ped_radius``) is at least
    ``personal_space_radius`` (default 1.2 m, Hall 1966; Francis et al. 2023: 0.5 m); 1.0
    without pedestrians, NaN without rows.
    """
    return _compliance(record, params.personal_space_radius)


@metric("intimate_space_compliance", unit="1",
        description="share of steps with no body gap to a person below the intimate radius")
def intimate_space_compliance(record: EpisodeRecord, params: MetricParams) -> float:
    """Share of steps with no body gap to a person below the intimate radius.

    Dimensionless, fraction of rows where every pedestrian's body gap
    ``‖p_ped − p_robot‖ − r_ped − r_robot`` (m) is at least ``intimate_space_radius``
    (default 0.45 m, Hall 1966); 1.0 without pedestrians, NaN without rows.
    """
    return _compliance(record, params.intimate_space_radius)


@metric("path_irregularity", unit="rad", description="mean heading deviation from the goal line")
def path_irregularity(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean heading deviation from the goal line.

    rad, mean over rows outside the goal of ``|angle_diff(ψ_j, atan2(goal − p_j))|``
    (Guzzi et al. 2013); NaN if no row is outside the goal.
    """
    rel = record.meta.goal[None, :2] - record.pose[:, :2]
    outside = goal_distance(record) > record.meta.goal_radius
    bearing = np.arctan2(rel[:, 1], rel[:, 0])
    return safe_mean(angle_diff(record.pose[:, 2], bearing)[outside])


@metric("group_space_intrusion", unit="s", description="time inside the space of a group")
def group_space_intrusion(record: EpisodeRecord, params: MetricParams) -> float:
    """Time inside the space of a group.

    s, ``Σ Δt_j`` over rows where the robot centre lies inside a group's circle. Groups are
    connected components (links: centre distance ≤ ``group_distance``) of ≥ ``group_min_size``
    pedestrians; a group's space is the circle about its centroid reaching the farthest member's
    body (centroid distance + its radius). 0 without groups.
    """
    inside = np.zeros(record.steps, dtype=bool)
    rows, counts = np.unique(record.ped_row, return_counts=True)
    for row in rows[counts >= params.group_min_size]:  # components need a per-step graph
        idx = np.flatnonzero(record.ped_row == row)
        pos = record.ped_position[idx]
        adj = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
        reach = adj <= params.group_distance
        while True:  # transitive closure by repeated squaring
            nxt = (reach.astype(np.int64) @ reach.astype(np.int64)) > 0
            if np.array_equal(nxt, reach):
                break
            reach = nxt
        labels = np.argmax(reach, axis=1)  # smallest member index labels each component
        robot = record.pose[row, :2]
        for lab in np.unique(labels):
            members = labels == lab
            if np.count_nonzero(members) < params.group_min_size:
                continue
            centre = pos[members].mean(axis=0)
            extent = np.hypot(*(pos[members] - centre).T) + record.ped_radius[idx][members]
            if np.hypot(*(robot - centre)) <= np.max(extent):
                inside[row] = True
                break
    return masked_time(record, inside)


@metric("induced_force", unit="m/s^2", description="mean social force the robot exerts on people")
def induced_force(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean social force the robot exerts on people.

    m/s² (force per unit mass), mean over rows of ``Σ_i A·exp((r_i − d_i)/B)`` with ``d_i``
    the centre distance, ``r_i = r_ped + r_robot``, A = 2.1 m/s², B = 0.3 m (Helbing & Molnár
    1995 repulsion); 0 without pedestrians, NaN without rows.
    """
    if record.steps == 0:
        return math.nan
    _, dist = ped_offsets(record)
    rad = record.ped_radius + record.meta.robot_radius
    f = params.social_force_a * np.exp((rad - dist) / params.social_force_b)
    per_row = np.bincount(record.ped_row, weights=f, minlength=record.steps)
    return float(np.mean(per_row))
