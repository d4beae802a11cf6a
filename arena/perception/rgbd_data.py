"""Labelled RGB-D frames from the 3-D simulator, to train and evaluate the RGB-D people detector.

:func:`labelled_frames` runs ``mujoco`` episodes of an experiment config (its map generator,
crowd and robot) with an ``rgbd`` camera added to the robot (:func:`with_camera`) and the robot
driving slow random arcs (half of them turning towards a person within 8 m), and keeps every
``every``-th frame, shrunk to the detector's input grid (:func:`shrink`), with the ground
truth the renderer gives for free:

* ``mask``: the person-id pass on the same grid (``True`` where a pixel shows a person);
* the people's centres in the robot base frame (x forward, y left; m) and which of them are
  *visible*: at least ``min_pixels`` full-resolution pixels show them (a detector is scored
  only on people its camera shows).

The camera's mount is drawn per episode (height, pitch) from :data:`MOUNTS`, so the detector
does not learn one robot's view only. Everything is drawn from the config's seed.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.config.schema import ExperimentConfig
from arena.core.rng import derive_rng
from arena.crowd.driver import build_driver
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.sensors.spec3d import RgbdFrame, RgbdSpec
from arena.sim.backend import BACKENDS
from arena.tasks.generator import TaskGenerator

F64 = NDArray[np.float64]

CAMERA = RgbdSpec(width=320, height=240, fovy=58.0, near=0.1, far=10.0, update_rate=10.0,
                  mount=(0.2, 0.0, 0.45, 0.0, 0.1))
"""The training camera: 320 × 240, 58° vertical field of view (73° across), 10 m far plane."""

MOUNTS: tuple[tuple[float, float], ...] = ((0.35, 0.0), (0.45, 0.1), (0.8, 0.15), (1.2, 0.25))
"""``(height m, pitch rad)`` of the camera mounts drawn per episode (a small base to a tall
service robot looking down)."""

STRIDE = 4
"""The detector sees every ``STRIDE``-th pixel row and column (320 × 240 -> 80 × 60)."""


def with_camera(robot: RobotModel, spec: RgbdSpec = CAMERA, name: str = "camera") -> RobotModel:
    """``robot`` with an ``rgbd`` sensor ``name`` of ``spec`` added (or replaced)."""
    data = robot.model_dump()
    data["sensors"][name] = spec.model_dump()
    return RobotModel.model_validate(data)


def shrink_depth(frame: RgbdFrame, stride: int = STRIDE) -> NDArray[np.float32]:
    """The detector's depth image ``(H // stride, W // stride)`` (m) of a frame.

    Depth is sampled at the centre pixel of each ``stride × stride`` block (a mean would invent
    surfaces between a person and the wall behind them).
    """
    h, w = frame.depth.shape[0] // stride, frame.depth.shape[1] // stride
    c = stride // 2
    depth = frame.depth[c : h * stride : stride, c : w * stride : stride]
    return np.ascontiguousarray(depth, dtype=np.float32)


def shrink(
    frame: RgbdFrame, stride: int = STRIDE
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """The frame on the detector's grid: ``(depth (h, w) m, rgb (h, w, 3) in [0, 1])``.

    Depth as :func:`shrink_depth`; colour is each block's mean.
    """
    depth = shrink_depth(frame, stride)
    h, w = depth.shape
    rgb = frame.rgb[: h * stride, : w * stride].reshape(h, stride, w, stride, 3)
    colour = rgb.mean(axis=(1, 3), dtype=np.float32) * np.float32(1.0 / 255.0)
    return depth, colour


@dataclass(frozen=True, eq=False)
class RgbdSample:
    """One shrunk frame with its ground truth (see the module docstring).

    Attributes:
        depth: ``(h, w)`` float32 m (0: no return).
        rgb: ``(h, w, 3)`` float32 colour in [0, 1].
        mask: ``(h, w)`` bool, the pixel shows a person.
        spec: the camera (its mount and intrinsics at full resolution).
        people: ``(p, 2)`` the people's centres in the robot base frame (m).
        visible: ``(p,)`` bool.
    """

    depth: NDArray[np.float32]
    rgb: NDArray[np.float32]
    mask: NDArray[np.bool_]
    spec: RgbdSpec
    people: F64
    visible: NDArray[np.bool_]


def to_base(xy: F64, pose: F64) -> F64:
    """World points ``(n, 2)`` in the base frame of a robot at ``pose`` ``[x, y, θ]``."""
    d = np.asarray(xy, dtype=np.float64).reshape(-1, 2) - pose[:2]
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)


def labelled_frames(
    cfg: ExperimentConfig, episodes: int, steps: int, *, every: int = 4, min_pixels: int = 150,
    episode_offset: int = 0, spec: RgbdSpec = CAMERA,
) -> Iterator[RgbdSample]:
    """Samples of ``episodes`` episodes of ``cfg`` (``steps`` simulation steps each)."""
    for frame, cam, pose, people in camera_frames(cfg, episodes, steps, every=every,
                                                  episode_offset=episode_offset, spec=spec):
        yield sample(frame, cam, pose, people, min_pixels)


def camera_frames(
    cfg: ExperimentConfig, episodes: int, steps: int, *, every: int = 4,
    episode_offset: int = 0, spec: RgbdSpec = CAMERA,
) -> Iterator[tuple[RgbdFrame, RgbdSpec, F64, F64]]:
    """Full frames of episodes of ``cfg`` on the mujoco backend (driven as the module says).

    Yields ``(frame, camera spec, robot pose (3,), people (p, 2) in the world frame)``.
    """
    base = load_robot(cfg.robot)
    if cfg.sim.backend.get("type") != "mujoco":
        raise ValueError("labelled RGB-D frames are drawn on the mujoco backend")
    backend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
    for e in range(episode_offset, episode_offset + episodes):
        rng = derive_rng(cfg.seed, "rgbd_data", e)
        height, pitch = MOUNTS[int(rng.integers(len(MOUNTS)))]
        x, y, _, yaw, _ = spec.mount
        cam = spec.model_copy(update={"mount": (x, y, height, yaw, pitch)})
        robot = with_camera(base, cam)
        ep = TaskGenerator.from_config(cfg, [robot]).episode(e)
        state = backend.reset(ep, build_driver(cfg.crowd, cfg.pedestrians),
                              derive_rng(cfg.seed, "episode", e, "sim"))
        cmd = np.zeros((1, 3))
        for k in range(steps):
            if k % 20 == 0:  # a new slow arc every 2 s, half of them towards someone
                cmd = np.array([[rng.uniform(0.0, 0.6), 0.0, rng.uniform(-0.6, 0.6)]])
                near = to_base(state.agents.positions, state.robots.poses[0])
                near = near[np.hypot(*near.T) < 8.0] if near.size else near
                if len(near) and rng.random() < 0.5:
                    bearing = np.arctan2(*near[int(rng.integers(len(near)))][::-1])
                    cmd[0, 2] = np.clip(bearing, -1.0, 1.0)
            state = backend.step(cmd, cfg.sim.dt)
            if k < 2 or k % every:  # the camera's first frame comes after the first step
                continue
            yield (state.robots.sensors[0]["camera"], cam, state.robots.poses[0],
                   state.agents.positions)


def sample(
    frame: RgbdFrame, spec: RgbdSpec, pose: F64, people_xy: F64, min_pixels: int = 150
) -> RgbdSample:
    """The :class:`RgbdSample` of one frame of a robot at ``pose`` among ``people_xy``."""
    if frame.person is None:
        raise ValueError("labelled frames need the person-id pass (segmentation)")
    counts = frame.person_pixels(int(np.asarray(people_xy).reshape(-1, 2).shape[0]))
    depth, rgb = shrink(frame)
    c = STRIDE // 2
    h, w = depth.shape
    mask = frame.person[c : h * STRIDE : STRIDE, c : w * STRIDE : STRIDE] >= 0
    return RgbdSample(depth, rgb, np.ascontiguousarray(mask), spec,
                      to_base(people_xy, np.asarray(pose, dtype=np.float64)),
                      counts >= min_pixels)
