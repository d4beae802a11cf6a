"""``iplanner``: a depth image and a subgoal → waypoints and a collision probability, tracked.

Description:
    "iPlanner: Imperative Path Planning" (Yang, Wang, Cadena, Hutter; RSS 2023): a network
    trained self-supervised through a differentiable trajectory cost (:mod:`arena.learn.iplanner`)
    maps the robot's depth image and a goal in the robot frame to ``K`` = 5 waypoints and a
    collision probability ("fear"). Every control tick:

    1. the goal is the global path's point ``lookahead`` m (3 m) ahead of the robot's projection
       on it (the path's end when that is nearer), in the robot frame; within
       ``goal_tolerance`` of the path's end the robot brakes (and turns to the goal heading when
       the stack asks);
    2. a goal more than ``turn_bearing`` (75°) off the robot's heading lies outside what the
       network was trained on and mostly outside the camera's 88° view: the robot turns on the
       spot toward it;
    3. otherwise the network plans on the latest frame of the rgbd sensor ``sensor`` (every n-th
       pixel of an image n × 80 × 48; the camera must be the trained one:
       :data:`arena.learn.iplanner.geometry.CAMERA`, as on
       ``arena/tasks/data/robots/jackal_rgbd.yaml``). The spline through the waypoints goes,
       in the world frame, to the pure-pursuit tracker
       (:class:`~arena.nav.local_planners.pure_pursuit.PurePursuitPlanner`, without a laser:
       iPlanner sees through its camera only), which gives ``[v, ω]``;
    4. fear: above ``fear_slow`` the speed is scaled down linearly (curvature kept) to
       ``creep_fraction`` of it at ``fear_stop``; at or above ``fear_stop`` the robot **stops and
       turns on the spot** toward the more open half of the image (larger mean depth above the
       horizon) and keeps that direction until the fear falls below ``fear_resume``.

    A frame with no depth at all (the MuJoCo camera before its first render) brakes. The
    network runs in numpy (:class:`~arena.learn.iplanner.network.IPlannerNet`).

Sensors:
    The robot needs an ``rgbd`` sensor and the 3-D backend (``sim.backend.type: mujoco``); a
    missing frame is a one-line :class:`~arena.core.errors.ConfigError` naming both, unless
    ``missing_frame: floor``, which plans on the image an empty floor gives (for contract
    checks without a simulator: :func:`arena.testing.check_local_planner` feeds no camera).

Arguments:
    See :class:`IPlannerPlanner.Params`.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from types import MappingProxyType
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.learn.iplanner.geometry import CAMERA, INPUT_SHAPE, depth_input, trajectory
from arena.learn.iplanner.network import IPlannerNet, Plan, load_net
from arena.nav.local_planners.base import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.path_tracking import (
    PathTracker,
    at_goal,
    finish_command,
    goal_command,
    to_robot_frame,
)
from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner
from arena.sensors.spec3d import RgbdFrame

IPLANNER_WEIGHTS = Path(__file__).resolve().parents[1] / "data" / "policies" / "iplanner.npz"
"""The packaged network (``arena/learn/data/policies/iplanner.npz``)."""

_SENSOR_KEY = "navigation.local_planner.sensor"


def floor_depth(shape: tuple[int, int] = INPUT_SHAPE) -> NDArray[np.float32]:
    """``(rows, cols)`` depth (m) the training camera sees of an empty floor (0: no return)."""
    _, fy, _, cy = CAMERA.intrinsics()
    h, pitch = CAMERA.mount[2], CAMERA.mount[4]
    v = np.arange(shape[0], dtype=np.float64)[:, None]
    denom = math.sin(pitch) + (v - cy) / fy * math.cos(pitch)
    with np.errstate(divide="ignore"):
        d = np.where(denom > 0, h / np.where(denom > 0, denom, 1.0), 0.0)
    d = np.where(d <= CAMERA.far, d, 0.0)
    return np.broadcast_to(d, shape).astype(np.float32)


@LOCAL_PLANNERS.register("iplanner", tags=("learned",))
class IPlannerPlanner:
    """iPlanner's network on the depth image and the path's subgoal, tracked by pure pursuit."""

    # turns on the spot (far goals, fear) and drives [v, ω] or [vx, vy, ω]: no car-like robots
    supports: ClassVar[frozenset[str]] = frozenset({"diff_drive", "omni", "legged"})

    class Params(BaseModel):
        """Parameters of ``iplanner``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        weights: str | None = Field(
            None, description="iPlanner network file (.npz, RUN/policy.npz); None: the packaged one"
        )
        sensor: str = Field("camera", description="the robot's rgbd sensor the network reads")
        missing_frame: Literal["error", "floor"] = Field(
            "error", description="no frame of `sensor`: error, or plan on an empty floor's image "
            "(contract checks without a simulator)")
        lookahead: float = Field(3.0, gt=0, description="m along the path to the network's goal")
        max_speed: float = Field(1.0, gt=0, description="m/s, cruise speed (capped by vx_max)")
        track_lookahead: float = Field(
            0.6, gt=0, description="m, pure pursuit's lookahead on the planned trajectory")
        turn_bearing: float = Field(
            math.radians(75), gt=0, le=math.pi,
            description="rad, goal bearing beyond which the robot turns on the spot first")
        fear_slow: float = Field(0.3, ge=0, le=1, description="fear above which it slows down")
        fear_stop: float = Field(0.7, gt=0, le=1, description="fear at which it stops and turns")
        fear_resume: float = Field(0.5, ge=0, le=1, description="fear below which it drives on")
        creep_fraction: float = Field(
            0.3, ge=0, le=1, description="share of the speed kept just below fear_stop")
        turn_rate: float = Field(1.0, gt=0, description="rad/s of a fear turn on the spot")
        goal_tolerance: float = Field(0.1, gt=0, description="m to the path end to brake at")
        yaw_tolerance: float = Field(0.1, gt=0, description="rad, heading error at the goal")
        heading_gain: float = Field(2.0, gt=0, description="1/s, turn rate per rad of bearing")

        @model_validator(mode="after")
        def _check(self) -> IPlannerPlanner.Params:
            if not self.fear_resume <= self.fear_stop or not self.fear_slow < self.fear_stop:
                raise ValueError(f"need fear_slow ({self.fear_slow}) < fear_stop "
                                 f"({self.fear_stop}) and fear_resume ({self.fear_resume}) <= "
                                 "fear_stop")
            return self

    def __init__(self, params: Params | None = None) -> None:
        self.params = p = params if params is not None else self.Params()
        self.net: IPlannerNet = load_net(p.weights if p.weights is not None else IPLANNER_WEIGHTS)
        self.tracker = PathTracker()
        self.pursuit = PurePursuitPlanner(PurePursuitPlanner.Params(
            lookahead=p.track_lookahead, max_lookahead=max(1.5, p.track_lookahead),
            max_speed=p.max_speed, detour_after=None))
        self.reset()

    def reset(self) -> None:
        """Forget the path progress, the last plan and the fear turn."""
        self.tracker.reset()
        self.pursuit.reset()
        self._turn = 0.0  # sign of the fear turn on the spot, 0: not turning
        self.last_plan: Plan | None = None
        """The network's last plan (robot frame of that tick)."""
        self.last_source = "network"
        """What made the last command: ``network``, ``fear_turn``, ``turn``, ``goal``, ``wait``."""

    def _depth(self, obs: LocalObservation) -> NDArray[np.float32] | None:
        """The network input of the frame, ``None`` before the camera's first image."""
        p = self.params
        frame = obs.sensors.get(p.sensor)
        if frame is None:
            if p.missing_frame == "floor":
                return depth_input(floor_depth())
            have = ", ".join(sorted(obs.sensors)) or "none"
            raise ConfigError(
                f"iplanner needs the robot's rgbd sensor {p.sensor!r} (sensors seen: {have}): "
                "give the robot a forward camera (arena/tasks/data/robots/jackal_rgbd.yaml) "
                "and run on sim.backend.type: mujoco (native2d renders no images)",
                path=_SENSOR_KEY)
        if not isinstance(frame, RgbdFrame):
            raise ConfigError(f"iplanner: sensor {p.sensor!r} is a {type(frame).__name__}, not "
                              "an rgbd camera", path=_SENSOR_KEY)
        depth = np.asarray(frame.depth)
        if not np.any(depth > 0):
            return None
        try:
            return depth_input(depth)
        except ValueError as e:
            raise ConfigError(f"iplanner: camera {p.sensor!r}: {e} (the network's camera is "
                              f"{CAMERA.width} x {CAMERA.height} px, fovy {CAMERA.fovy} deg)",
                              path=_SENSOR_KEY) from None

    def _open_side(self, x: NDArray[np.float32]) -> float:
        """+1 (left) or -1 (right): the image half with the larger mean depth above the horizon."""
        _, fy, _, cy = CAMERA.intrinsics()
        horizon = int(cy - fy * math.tan(CAMERA.mount[4]))
        top = x[0, : max(horizon, 1)]
        half = top.shape[1] // 2
        # image columns run left to right: the left half is the robot's +y side
        return 1.0 if float(top[:, :half].mean()) >= float(top[:, half:].mean()) else -1.0

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """The tracked plan's command (module docstring)."""
        p, lim = self.params, obs.limits
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        dt = float(obs.dt)
        goal = obs.goal_pose
        path = PathTracker.normalise(obs.path, np.array([goal.x, goal.y]))
        s = self.tracker.track(path, pose[:2])
        d_end = max(self.tracker.total - s, float(np.hypot(*(path[-1] - pose[:2]))))
        if at_goal(obs, d_end, p.goal_tolerance):
            self.last_source, self._turn = "goal", 0.0
            return goal_command(obs, p.heading_gain, p.yaw_tolerance)
        target = to_robot_frame(self.tracker.point_at(s + p.lookahead)[None], pose)[0]
        bearing = math.atan2(target[1], target[0])
        x = self._depth(obs)
        if x is None:  # no image yet: brake
            self.last_source = "wait"
            return finish_command(np.zeros(3), twist, lim, dt, False)
        if abs(bearing) > p.turn_bearing and self._turn == 0.0:
            self.last_source = "turn"
            cmd = np.array([0.0, 0.0, float(np.clip(p.heading_gain * bearing, -lim.omega_max,
                                                    lim.omega_max))])
            return finish_command(cmd, twist, lim, dt, False)
        plan = self.net.plan(x, target)
        self.last_plan = plan
        if plan.fear >= p.fear_stop or (self._turn != 0.0 and plan.fear >= p.fear_resume):
            if self._turn == 0.0:
                self._turn = self._open_side(x)
            self.last_source = "fear_turn"
            cmd = np.array([0.0, 0.0, self._turn * min(p.turn_rate, lim.omega_max)])
            return finish_command(cmd, twist, lim, dt, False)
        self._turn = 0.0
        self.last_source = "network"
        return self._track(obs, plan, pose, twist)

    def _track(self, obs: LocalObservation, plan: Plan, pose: NDArray[np.float64],
               twist: NDArray[np.float64]) -> NDArray[np.float64]:
        """Pure pursuit along the plan's spline, slowed by the fear."""
        p, lim = self.params, obs.limits
        local = trajectory(plan.waypoints)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        world = pose[:2] + local @ np.array([[c, s], [-s, c]])
        end = world[-1]
        sub = replace(obs, path=world, goal=Pose2D(float(end[0]), float(end[1]),
                                                      obs.goal_pose.theta),
                      scan_ranges=np.zeros(0), scan_angles=np.zeros(0),
                      sensors=MappingProxyType({}), goal_yaw_tolerance=None,
                      goal_xy_tolerance=None)
        self.pursuit.reset()  # a new path every tick: no progress or latch to carry over
        cmd = np.asarray(self.pursuit.compute(sub), dtype=np.float64)
        span = p.fear_stop - p.fear_slow
        scale = 1.0 - (1.0 - p.creep_fraction) * min(max((plan.fear - p.fear_slow) / span, 0.0),
                                                      1.0)
        return finish_command(cmd * np.array([scale, scale, scale]), twist, lim, float(obs.dt),
                              False)
