"""Labelled lidar frames from the simulator, to train and evaluate the lidar people detector.

:func:`labelled_frames` runs ``native2d`` episodes of an experiment config (its map generator,
crowd and robot) with the robot driving slow random arcs, and keeps every ``every``-th scan
with the ground truth in the sensor frame:

* the people's centres and which of them are *visible* (at least ``min_hits`` beams end within
  ``body + 0.05`` m of the body circle, or of a leg circle with ``pedestrian_body: legs``):
  a detector is scored only on people its scan shows;
* the scan's segments (:func:`~arena.perception.segments.segment_scan`) with a label each:
  ``1`` when the segment's centroid lies within ``radius + LABEL_MARGIN`` of a person's body
  circle (or of one of their legs), else ``0``.

Everything is drawn from the config's seed: the same call gives the same frames.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.config.schema import ExperimentConfig
from arena.core.rng import derive_rng
from arena.crowd.driver import build_driver
from arena.perception.segments import Segments, scan_points, segment_scan
from arena.robots.presets import load_robot
from arena.sim.backend import BACKENDS
from arena.sim.engine.scene import legs
from arena.sim.native2d import Native2DBackend
from arena.tasks.generator import TaskGenerator

F64 = NDArray[np.float64]

LABEL_MARGIN = 0.1
"""m a segment's centroid may lie outside a body or leg circle and still be that person's."""


@dataclass(frozen=True, eq=False)
class LidarFrame:
    """One scan with its ground truth, in the sensor frame (x forward, y left; m).

    Attributes:
        ranges: ``(beams,)`` m.
        angles: ``(beams,)`` rad, sensor frame.
        range_max: m.
        people: ``(p, 2)`` the people's centres.
        visible: ``(p,)`` bool, the scan shows them (see the module docstring).
        segments: the scan's segments.
        labels: ``(k,)`` 1 for a segment of a person, else 0.
    """

    ranges: F64
    angles: F64
    range_max: float
    people: F64
    visible: NDArray[np.bool_]
    segments: Segments
    labels: NDArray[np.int64]


def labelled_frames(
    cfg: ExperimentConfig, episodes: int, steps: int, *, every: int = 5, min_hits: int = 3,
    episode_offset: int = 0,
) -> Iterator[LidarFrame]:
    """Frames of ``episodes`` episodes of ``cfg`` (``steps`` simulation steps each)."""
    robot = load_robot(cfg.robot)
    spec = robot.lidar(cfg.navigation.scan_sensor)
    angles = spec.angles() + spec.mount[2]
    gen = TaskGenerator.from_config(cfg, [robot])
    backend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
    if not isinstance(backend, Native2DBackend):
        raise ValueError("labelled lidar frames are drawn on native2d")
    params = backend.params
    for e in range(episode_offset, episode_offset + episodes):
        ep = gen.episode(e)
        rng = derive_rng(cfg.seed, "lidar_data", e)
        state = backend.reset(ep, build_driver(cfg.crowd, cfg.pedestrians), derive_rng(
            cfg.seed, "episode", e, "sim"))
        cmd = np.zeros((1, 3))
        for k in range(steps):
            if k % 20 == 0:  # a new slow arc every 2 s
                cmd = np.array([[rng.uniform(0.0, 0.6), 0.0, rng.uniform(-0.6, 0.6)]])
            state = backend.step(cmd, cfg.sim.dt)
            if k % every:
                continue
            pose = state.robots.poses[0]
            agents = state.agents
            if params.pedestrian_body == "legs":
                leg_xy, leg_r = legs(agents, backend.engine.walked[0], params)
            else:
                leg_xy, leg_r = np.zeros((0, 2)), np.zeros(0)
            yield _frame(state.robots.scans[0], angles, spec.range_max, pose, spec.mount,
                         agents.positions, agents.radii, leg_xy, leg_r, min_hits)


def _to_sensor(xy: F64, pose: F64, mount: tuple[float, float, float]) -> F64:
    """World points ``(n, 2)`` in the frame of a sensor mounted at ``mount`` on ``pose``."""
    c, s = np.cos(pose[2]), np.sin(pose[2])
    origin = pose[:2] + np.array([c * mount[0] - s * mount[1], s * mount[0] + c * mount[1]])
    yaw = pose[2] + mount[2]
    d = np.asarray(xy, dtype=np.float64).reshape(-1, 2) - origin
    cy, sy = np.cos(yaw), np.sin(yaw)
    return np.stack([cy * d[:, 0] + sy * d[:, 1], -sy * d[:, 0] + cy * d[:, 1]], axis=1)


def _frame(
    ranges: F64, angles: F64, range_max: float, pose: F64, mount: tuple[float, float, float],
    people_xy: F64, people_r: F64, leg_xy: F64, leg_r: F64, min_hits: int,
) -> LidarFrame:
    n = people_xy.shape[0]
    people = _to_sensor(people_xy, pose, mount)
    legs_s = _to_sensor(leg_xy, pose, mount)
    pts, valid = scan_points(ranges, angles, range_max)
    hit = pts[valid]
    # circles each person shows: the body, or the two legs (all left legs first, then right)
    if leg_xy.shape[0]:
        circ = legs_s
        rad = leg_r
        owner = np.concatenate([np.arange(n), np.arange(n)])
    else:
        circ, rad, owner = people, np.asarray(people_r, dtype=np.float64), np.arange(n)
    visible = np.zeros(n, dtype=bool)
    if hit.size and circ.size:
        d = np.hypot(*(hit[:, None, :] - circ[None, :, :]).transpose(2, 0, 1))  # (h, c)
        on = d <= rad[None, :] + 0.05
        counts = np.bincount(owner, weights=on.sum(axis=0), minlength=n)
        visible = counts >= min_hits
    segs = segment_scan(pts, valid, range_max=range_max)
    labels = np.zeros(len(segs), dtype=np.int64)
    if len(segs) and circ.size:
        d = np.hypot(*(segs.centroids[:, None, :] - circ[None, :, :]).transpose(2, 0, 1))
        labels = (d <= rad[None, :] + LABEL_MARGIN).any(axis=1).astype(np.int64)
    return LidarFrame(np.asarray(ranges, dtype=np.float64).copy(), angles, float(range_max),
                      people, visible, segs, labels)
