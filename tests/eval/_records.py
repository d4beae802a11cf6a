"""Hand-built EpisodeRecords for metric tests."""

from __future__ import annotations

import numpy as np

from arena.eval.record import EpisodeMeta, EpisodeRecord


def make_record(
    pose, velocity=None, dt=0.1, collision=None, peds=None, outcome="success",
    start=None, goal=None, goal_radius=0.3, robot_radius=0.2, min_range=None,
):
    """peds: list of (row, id, x, y, vx, vy, heading, radius)."""
    pose = np.asarray(pose, float)
    t = pose.shape[0]
    vel = np.zeros((t, 3)) if velocity is None else np.asarray(velocity, float)
    peds = np.asarray(peds if peds else np.zeros((0, 8)), float).reshape(-1, 8)
    meta = EpisodeMeta(
        episode=0, seed=0, stage="", map_name="m", robot="r", robot_radius=robot_radius,
        start=pose[0].copy() if start is None else np.asarray(start, float),
        goal=pose[-1].copy() if goal is None else np.asarray(goal, float),
        goal_radius=goal_radius, goal_tolerance_angle=None, time_limit=100.0, dt=dt,
        outcome=outcome,
    )
    coll = np.zeros(t, bool) if collision is None else np.asarray(collision, bool)
    return EpisodeRecord(
        meta=meta, time=np.arange(t) * dt, pose=pose, velocity=vel, command=np.zeros((t, 3)),
        min_range=np.full(t, np.inf) if min_range is None else np.asarray(min_range, float),
        collision_wall=coll, collision_obstacle=np.zeros(t, bool),
        collision_pedestrian=np.zeros(t, bool), collision_robot=np.zeros(t, bool),
        ped_row=peds[:, 0].astype(np.int64), ped_id=peds[:, 1].astype(np.int64),
        ped_kind=np.zeros(len(peds), np.int64), ped_state=np.zeros(len(peds), np.int64),
        ped_position=peds[:, 2:4].copy(), ped_velocity=peds[:, 4:6].copy(),
        ped_heading=peds[:, 6].copy(), ped_radius=peds[:, 7].copy(),
    )


def straight(n=11, v=1.0, dt=0.1, **kw):
    """Along +x at constant speed v."""
    x = np.arange(n) * v * dt
    pose = np.stack([x, np.zeros(n), np.zeros(n)], 1)
    vel = np.tile([v, 0.0, 0.0], (n, 1))
    return make_record(pose, vel, dt=dt, **kw)
