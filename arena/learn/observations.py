"""Observations for ``N`` worlds at once, and their gymnasium spaces (arena_specs §8.2).

Dict keys (each present only when enabled; arrays below are per world, the builder returns
them with a leading ``N`` axis):

================== =================== =======================================================
``lidar``          ``(beams,)``        ranges (m) in ``[0, range_max]``; ``(stack, beams)``,
                                       oldest scan first, when ``laser_stack > 1``
``goal``           ``(2,)``            ``[ρ m, θ rad]``, robot frame, θ = 0 straight ahead,
                                       ρ clipped to ``goal_max_distance``
                                       (Arena offsets θ by π, §10.9; we do not)
``last_action``    ``(3,)``            last command ``[vx m/s, vy m/s, ω rad/s]``
``velocity``       ``(3,)``            measured body twist ``[vx m/s, vy m/s, ω rad/s]`` (what
                                       the simulator executed, after acceleration limits and
                                       contacts; Long et al.'s ``v_t``). Always three
                                       components, the layout of ``last_action``, so that one
                                       policy layout serves every drive: ``vy`` reads 0 for
                                       non-holonomic robots. Clipped to the command box.
``pedestrians``    ``(k, 6)``          k nearest people within ``max_range``, nearest first:
                                       ``[x m, y m, vx m/s, vy m/s, type, social_state]`` with
                                       position and velocity relative to the robot, in its
                                       frame; type 0 adult, 1 elder, −1 other (Arena's codes);
                                       social_state the :class:`~arena.crowd.state.SocialState`
                                       code; empty slots are zero
``pedestrians_mask`` ``(k,)``          1 where a slot holds a person, else 0
``semantic``       ``(C, size, size)`` ego-centric feature maps, ROI ``roi`` m centred on the
                                       robot, row ↔ robot-frame y, column ↔ x; cell
                                       ``floor(x / roi · size) + size / 2`` (Arena truncates
                                       with ``int``, which doubles the centre cells)
``depth``          ``(H, W)``          float32 depth (m along the optical axis, ``0`` where
                                       nothing lies within ``far``) of the ``rgbd`` sensor
                                       ``camera.sensor``, image order (row 0 at the top)
``rgb``            ``(H, W, 3)``       uint8 colour of the same camera
================== =================== =======================================================

Semantic channels: ``pedestrian_location`` 1, ``pedestrian_type`` the type code,
``pedestrian_vel_x``/``_vel_y`` the person's velocity in the robot frame (m/s; Arena writes the
world-frame force), ``pedestrian_social_state`` Arena's animation code (``evidence >> 8``,
1 idle … 6 phone). With ``flatten`` the parts are concatenated in the order above into one
float32 vector (not with camera images: they keep the Dict space, for image encoders).
Camera parts need a backend that renders the ``rgbd`` sensor (``sim.backend.type: mujoco``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.crowd.semantic import pedestrian_type_codes
from arena.learn.config import ObservationConfig
from arena.learn.ped_maps import MAX_SPEED, semantic_maps, to_robot_frame
from arena.robots.model import RobotModel
from arena.sensors.spec3d import RgbdFrame, RgbdSpec

FloatArray = NDArray[np.float64]
Obs = dict[str, NDArray[Any]]

PED_FEATURES = ("x", "y", "vx", "vy", "type", "social_state")
"""Columns of the ``pedestrians`` observation."""
_N_STATES = 7


def lidar_shape(stack: int, beams: int) -> tuple[int, ...]:
    """Shape of one robot's ``lidar`` observation: ``(beams,)``, or ``(stack, beams)`` if stacked.

    One scan is a plain vector, as Gymnasium's frame-stacking convention has it (the stack axis
    appears only when scans are stacked); batched observations add a leading world axis.
    """
    return (int(beams),) if int(stack) == 1 else (int(stack), int(beams))


@dataclass(frozen=True, eq=False)
class ObsInput:
    """World state for ``N`` worlds (``M`` pedestrian slots each).

    Attributes:
        poses: ``(N, 3)`` robot poses ``[x m, y m, ψ rad]``.
        twists: ``(N, 3)`` body-frame velocities ``[vx, vy, ω]``.
        goals: ``(N, 2)`` goal positions (m).
        scans: ``(N, stack, beams)`` most recent laser scans (m), oldest first.
        last_action: ``(N, 3)`` last command.
        ped_pos: ``(N, M, 2)`` m.
        ped_vel: ``(N, M, 2)`` m/s, world frame.
        ped_kind: ``(N, M)`` type codes (0 adult, 1 elder, 2 child).
        ped_state: ``(N, M)`` social-state codes.
        ped_mask: ``(N, M)`` bool, the slot holds a person.
        frames: per world the observed camera's latest frame (``()`` without a camera part).
    """

    poses: FloatArray
    twists: FloatArray
    goals: FloatArray
    scans: FloatArray
    last_action: FloatArray
    ped_pos: FloatArray
    ped_vel: FloatArray
    ped_kind: NDArray[np.int64]
    ped_state: NDArray[np.int64]
    ped_mask: NDArray[np.bool_]
    frames: tuple[RgbdFrame, ...] = ()


def goal_polar(poses: FloatArray, goals: FloatArray) -> FloatArray:
    """``(N, 2)`` ``[ρ, θ]``: distance (m) and bearing (rad, ``[−π, π)``, 0 straight ahead)."""
    rho, theta = _goal_rho_theta(poses, goals)
    out = np.empty((rho.shape[0], 2))
    out[:, 0] = rho
    out[:, 1] = theta
    return out


def _goal_rho_theta(poses: FloatArray, goals: FloatArray) -> tuple[FloatArray, FloatArray]:
    """:func:`goal_polar`'s columns ``(N,)`` each: ρ (m) and θ (rad)."""
    d = goals[:, :2] - poses[:, :2]
    dx, dy = d[:, 0], d[:, 1]
    rho = np.hypot(dx, dy)
    theta = (np.arctan2(dy, dx) - poses[:, 2] + np.pi) % (2 * np.pi) - np.pi
    return rho, theta


def _as_lists(
    bounds: tuple[FloatArray, FloatArray] | None,
) -> tuple[list[float], list[float]]:
    """``(low, high)`` arrays as Python lists (empty when ``None``)."""
    if bounds is None:
        return [], []
    return bounds[0].tolist(), bounds[1].tolist()


def _clipped(
    values: FloatArray, bounds: tuple[FloatArray, FloatArray],
    bounds_l: tuple[list[float], list[float]],
) -> NDArray[np.float32]:
    """``values`` ``(n, 3)`` clipped to ``bounds`` as float32 (one world: :func:`_clip_one`)."""
    if values.shape[0] == 1:
        return _clip_one(values, *bounds_l)
    return values.clip(*bounds).astype(np.float32)


def _clip_one(values: FloatArray, lo: list[float], hi: list[float]) -> NDArray[np.float32]:
    """``values.clip(lo, hi).astype(float32)`` of one row ``(1, d)``, the same bits.

    numpy's float clip is ``min(max(x, lo), hi)`` with ``max(a, b) = a if isnan(a) or a > b
    else b`` and ``min(a, b) = a if isnan(a) or a < b else b`` (so ``clip(−0.0, 0.0, …)`` is
    ``0.0`` and NaN passes), written out here on Python floats: one ``tolist`` and one
    ``np.array`` instead of ``clip``'s Python wrapper, its ufunc and ``astype``.
    """
    out: list[float] = []
    for x, low, high in zip(values.tolist()[0], lo, hi, strict=True):
        v = x if (x != x or x > low) else low
        out.append(v if (v != v or v < high) else high)
    return np.array([out], np.float32)


class ObservationBuilder:
    """Observation space and batched construction for one robot model.

    Args:
        config: the ``learning.env.observation`` block.
        robot: the robot model (laser beams and range, velocity limits).
    """

    def __init__(self, config: ObservationConfig, robot: RobotModel) -> None:
        self.config = config
        self.lidar_spec = robot.lidar(
            config.sensor, path="learning.env.observation.sensor"
        )
        self.beams = int(self.lidar_spec.num_beams)
        self.range_max = float(self.lidar_spec.range_max)
        lim = robot.limits()
        parts: dict[str, spaces.Box] = {}
        if config.lidar:
            parts["lidar"] = spaces.Box(
                0.0, self.range_max, lidar_shape(config.laser_stack, self.beams), np.float32
            )
        if config.goal:
            parts["goal"] = spaces.Box(
                np.array([0.0, -np.pi], np.float32),
                np.array([config.goal_max_distance, np.pi], np.float32),
            )
        if config.last_action:
            # vy is 0 for non-holonomic robots; its bounds then reuse vx's (no empty interval)
            vy = (lim.vy_min, lim.vy_max) if lim.vy_max > lim.vy_min else (lim.vx_min, lim.vx_max)
            lo = np.array([lim.vx_min, vy[0], -lim.omega_max], np.float32)
            hi = np.array([lim.vx_max, vy[1], lim.omega_max], np.float32)
            parts["last_action"] = spaces.Box(np.minimum(lo, 0), np.maximum(hi, 0))
        if config.velocity:
            vy = (lim.vy_min, lim.vy_max) if lim.vy_max > lim.vy_min else (lim.vx_min, lim.vx_max)
            lo = np.array([lim.vx_min, vy[0], -lim.omega_max], np.float32)
            hi = np.array([lim.vx_max, vy[1], lim.omega_max], np.float32)
            parts["velocity"] = spaces.Box(np.minimum(lo, 0), np.maximum(hi, 0))
        pc = config.pedestrians
        if pc.enabled:
            r, v = pc.max_range, MAX_SPEED
            lo = np.array([-r, -r, -v, -v, -1, 0], np.float32)
            hi = np.array([r, r, v, v, 1, _N_STATES - 1], np.float32)
            parts["pedestrians"] = spaces.Box(
                np.tile(lo, (pc.k, 1)), np.tile(hi, (pc.k, 1)), dtype=np.float32
            )
            parts["pedestrians_mask"] = spaces.Box(0.0, 1.0, (pc.k,), np.float32)
        sc = config.semantic
        if sc.enabled:
            bounds = {
                "pedestrian_location": (0.0, 1.0),
                "pedestrian_type": (-1.0, 1.0),
                "pedestrian_vel_x": (-MAX_SPEED, MAX_SPEED),
                "pedestrian_vel_y": (-MAX_SPEED, MAX_SPEED),
                "pedestrian_social_state": (0.0, 6.0),
            }
            lo = np.array([min(bounds[c][0], 0.0) for c in sc.channels], np.float32)
            hi = np.array([bounds[c][1] for c in sc.channels], np.float32)
            shape = (len(sc.channels), sc.size, sc.size)
            parts["semantic"] = spaces.Box(
                np.broadcast_to(lo[:, None, None], shape).copy(),
                np.broadcast_to(hi[:, None, None], shape).copy(),
                dtype=np.float32,
            )
        self.camera_spec = self._camera_parts(config, robot, parts)
        if not parts:
            raise ValueError("the observation is empty: enable at least one part")
        self.dict_space = spaces.Dict(parts)
        self.keys = tuple(self.dict_space.keys())  # the order flatten_space uses
        self._lidar = "lidar" in parts
        self._people = config.pedestrians.enabled or config.semantic.enabled
        self._goal = "goal" in parts
        # float64 copies of the last_action bounds: the float32 arrays would make each clip cast
        la = parts.get("last_action")
        self._action_bounds: tuple[FloatArray, FloatArray] | None = (
            (la.low.astype(np.float64), la.high.astype(np.float64)) if la is not None else None
        )
        ve = parts.get("velocity")
        self._velocity_bounds: tuple[FloatArray, FloatArray] | None = (
            (ve.low.astype(np.float64), ve.high.astype(np.float64)) if ve is not None else None
        )
        # operands and results (dx, dy, ρ, atan2) of the one-world goal path, see _goal_single;
        # the (1,) views are made once (each costs a numpy call)
        buf = np.zeros((4, 1))
        self._goal_views = (buf[0], buf[1], buf[2], buf[3], buf[2:, 0])
        # the same bounds as lists, for the one-world path (_clip_one)
        self._action_bounds_l = _as_lists(self._action_bounds)
        self._velocity_bounds_l = _as_lists(self._velocity_bounds)
        self.space: spaces.Space[object] = (
            spaces.flatten_space(self.dict_space) if config.flatten else self.dict_space
        )

    @staticmethod
    def _camera_parts(
        config: ObservationConfig, robot: RobotModel, parts: dict[str, spaces.Box]
    ) -> RgbdSpec | None:
        """Add the ``depth``/``rgb`` parts of ``config.camera``; its sensor's spec (or None)."""
        cam = config.camera
        if cam.sensor is None:
            return None
        where = "learning.env.observation.camera.sensor"
        spec = robot.sensors.get(cam.sensor)
        if not isinstance(spec, RgbdSpec):
            cameras = sorted(n for n, s in robot.sensors.items() if isinstance(s, RgbdSpec))
            raise ConfigError(
                f"{where}: robot {robot.name!r} has no rgbd sensor {cam.sensor!r}; expected one "
                f"of its cameras: {', '.join(cameras) or 'none (add one under sensors:)'}"
            )
        if config.flatten:
            raise ConfigError("learning.env.observation.flatten: camera images need the Dict "
                              "observation (flatten: false), for an image encoder")
        h, w = spec.height, spec.width
        if "depth" in cam.channels:
            parts["depth"] = spaces.Box(0.0, spec.far, (h, w), np.float32)
        if "rgb" in cam.channels:
            parts["rgb"] = spaces.Box(0, 255, (h, w, 3), np.uint8)
        return spec

    def build(self, inp: ObsInput) -> Obs:
        """The observation dict with a leading ``N`` axis."""
        n = inp.poses.shape[0]
        out: Obs = {}
        cfg = self.config
        # The array method clip is np.clip without its dispatch layer (this runs every step).
        if self._lidar:
            scans = inp.scans if cfg.laser_stack > 1 else inp.scans[:, 0]
            out["lidar"] = scans.clip(0.0, self.range_max).astype(np.float32)
        if self._goal:
            if n == 1:
                rho_1, theta_1 = self._goal_single(inp.poses, inp.goals)
                # Python's min: numpy's np.minimum for non-NaN ρ, NaN ρ stays NaN in both
                out["goal"] = np.array(
                    [[min(rho_1, cfg.goal_max_distance), theta_1]], np.float32
                )
            else:
                rho, theta = _goal_rho_theta(inp.poses, inp.goals)
                goal = np.empty((n, 2), np.float32)  # assignment rounds to float32 as astype
                goal[:, 0] = np.minimum(rho, cfg.goal_max_distance)
                goal[:, 1] = theta
                out["goal"] = goal
        if self._action_bounds is not None:
            out["last_action"] = _clipped(
                inp.last_action, self._action_bounds, self._action_bounds_l
            )
        if self._velocity_bounds is not None:
            out["velocity"] = _clipped(inp.twists, self._velocity_bounds, self._velocity_bounds_l)
        if self._people:
            rel = to_robot_frame(inp.ped_pos - inp.poses[:, None, :2], inp.poses[:, 2])
            if cfg.pedestrians.enabled:
                out.update(self._pedestrians(inp, rel, n))
            if cfg.semantic.enabled:
                out["semantic"] = self._semantic(inp, rel, n)
        if self.camera_spec is not None:
            if len(inp.frames) != n:
                raise ValueError(f"a camera observation needs {n} frames, got {len(inp.frames)}")
            if "depth" in cfg.camera.channels:
                out["depth"] = np.stack([f.depth for f in inp.frames])
            if "rgb" in cfg.camera.channels:
                out["rgb"] = np.stack([f.rgb for f in inp.frames])
        return out

    def _goal_single(self, poses: FloatArray, goals: FloatArray) -> tuple[float, float]:
        """:func:`_goal_rho_theta` of world 0 as floats ``(ρ m, θ rad)``, the same bits.

        ``np.hypot``/``np.arctan2`` (on preallocated ``(1,)`` buffers: ``math.hypot`` and
        ``math.atan2`` round differently from numpy's kernels) and Python float arithmetic
        for the rest (``+ − %`` round as numpy's, ``%`` takes the divisor's sign in both).
        """
        px, py, heading = poses.tolist()[0]
        gx, gy = goals.tolist()[0][:2]
        dx, dy, rho_out, angle_out, results = self._goal_views
        dx[0] = gx - px
        dy[0] = gy - py
        np.hypot(dx, dy, out=rho_out)
        np.arctan2(dy, dx, out=angle_out)
        rho, angle = results.tolist()
        return rho, (angle - heading + math.pi) % (2 * math.pi) - math.pi

    def _robot_world_velocity(self, inp: ObsInput) -> FloatArray:
        c, s = np.cos(inp.poses[:, 2]), np.sin(inp.poses[:, 2])
        vx, vy = inp.twists[:, 0], inp.twists[:, 1]
        return np.column_stack([c * vx - s * vy, s * vx + c * vy])

    def _pedestrians(self, inp: ObsInput, rel: FloatArray, n: int) -> Obs:
        pc = self.config.pedestrians
        k = pc.k
        feats = np.zeros((n, k, len(PED_FEATURES)), np.float32)
        mask = np.zeros((n, k), np.float32)
        m = rel.shape[1]
        if m:
            dist = np.hypot(rel[..., 0], rel[..., 1])
            valid = inp.ped_mask & (dist <= pc.max_range)
            key = np.where(valid, dist, np.inf)
            order = np.argsort(key, axis=1, kind="stable")[:, :k]
            take = order.shape[1]
            rows = np.arange(n)[:, None]
            ok = valid[rows, order]
            rel_v = to_robot_frame(
                inp.ped_vel - self._robot_world_velocity(inp)[:, None, :], inp.poses[:, 2]
            )
            f = np.concatenate(
                [
                    rel[rows, order],
                    np.clip(rel_v[rows, order], -MAX_SPEED, MAX_SPEED),
                    pedestrian_type_codes(inp.ped_kind[rows, order])[..., None],
                    np.clip(inp.ped_state[rows, order], 0, _N_STATES - 1)[..., None],
                ],
                axis=-1,
            )
            feats[:, :take] = np.where(ok[..., None], f, 0.0)
            mask[:, :take] = ok
        return {"pedestrians": feats, "pedestrians_mask": mask}

    def _semantic(self, inp: ObsInput, rel: FloatArray, n: int) -> NDArray[np.float32]:
        vel = to_robot_frame(inp.ped_vel, inp.poses[:, 2])
        return semantic_maps(self.config.semantic, rel, vel, inp.ped_kind, inp.ped_state,
                             inp.ped_mask)

    def flatten(self, obs: Obs) -> NDArray[np.float32]:
        """``(N, D)`` float32: the parts of a batched observation concatenated in key order."""
        n = next(iter(obs.values())).shape[0]
        return np.concatenate([obs[k].reshape(n, -1) for k in self.keys], axis=1).astype(
            np.float32
        )

    def single(
        self, obs: Obs, i: int = 0
    ) -> dict[str, NDArray[np.float32]] | NDArray[np.float32]:
        """World ``i`` of a batched observation, in the form of :attr:`space`."""
        if self.config.flatten:
            return self.flatten({k: v[i : i + 1] for k, v in obs.items()})[0]
        return {k: obs[k][i] for k in self.keys}
