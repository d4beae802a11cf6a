"""The local-planner interface, its observation and its registry.

A local planner (controller) turns what the robot knows at one tick — its pose and velocity, the
global path, the goal and a laser scan — into a body-frame velocity command ``[vx, vy, omega]``
that respects the robot's velocity box and acceleration limits.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from arena.core.registry import Registry
from arena.core.types import Pose2D
from arena.robots.limits import VelocityLimits
from arena.sensors.spec import LidarReading

if TYPE_CHECKING:
    from arena.nav.costmap import Costmap

KINEMATICS: frozenset[str] = frozenset({"diff_drive", "omni", "ackermann", "legged"})
"""Kinematics names a local planner may declare in :attr:`LocalPlanner.supports`."""


def _empty() -> NDArray[np.float64]:
    return np.zeros(0, dtype=np.float64)


def _zero2() -> NDArray[np.float64]:
    return np.zeros(2, dtype=np.float64)


def _empty_peds() -> NDArray[np.float64]:
    return np.zeros((0, 4), dtype=np.float64)


@dataclass(frozen=True, eq=False)
class LocalObservation:
    """Everything a local planner sees at one control tick.

    Attributes:
        pose: ``(3,)`` robot pose ``[x m, y m, theta rad]`` in the world frame.
        twist: ``(3,)`` current body twist ``[vx m/s, vy m/s, omega rad/s]``.
        goal: the navigation goal, a :class:`Pose2D` or a ``(3,)`` array ``[x, y, theta]``.
        path: ``(k, 2)`` global-path waypoints (m, world frame), first near the robot, last at
            the goal; straight segments in between.
        limits: the robot's velocity and acceleration limits.
        robot_radius: radius of the robot's bounding circle (m).
        dt: control period (s): the time over which the command is held.
        scan_ranges: ``(beams,)`` laser ranges (m); ``inf``/``nan`` mean no return. Beams with
            no hit may also report the sensor's ``range_max``.
        scan_angles: ``(beams,)`` beam angles (rad) in the robot frame, mount yaw included.
        scan_origin: ``(2,)`` sensor position in the robot frame (m). The three ``scan_*``
            fields are the lidar the navigation stack reads (``navigation.scan_sensor``,
            default ``laser``).
        sensors: every sensor of the robot by name: a lidar as a
            :class:`~arena.sensors.spec.LidarReading` (ranges, angles, origin), another type
            as its reading array. Empty when the caller gives only the ``scan_*`` fields.
        time: simulation time (s).
        kinematics: the robot's kinematics name (one of :data:`KINEMATICS`), or ``None`` to let
            the planner infer it from ``limits`` (see :func:`infer_kinematics`).
        goal_yaw_tolerance: heading error (rad) the navigation stack accepts at the goal, or
            ``None`` when the goal heading does not matter. Planners that can turn the robot on
            the spot align it to the goal's ``theta`` when this is set.
        goal_xy_tolerance: distance (m) to the goal the navigation stack accepts as arrived, or
            ``None``. With a goal heading to meet, planners that can turn on the spot start
            aligning within this distance (see :func:`~.path_tracking.at_goal`).
        pedestrians: ``(n, 4)`` known pedestrians ``[x, y, vx, vy]`` (m, m/s, world frame) that
            the stack passes on (empty when it has none); human-aware planners use them.
        costmap: the navigation stack's rolling local costmap (``costmap_2d`` costs, world
            placement; see :mod:`arena.nav.costmap`) when ``navigation.local_costmap`` is
            configured, else ``None``. Read-only for planners.
    """

    pose: NDArray[np.float64]
    twist: NDArray[np.float64]
    goal: Pose2D | NDArray[np.float64]
    path: NDArray[np.float64]
    limits: VelocityLimits
    robot_radius: float
    dt: float
    scan_ranges: NDArray[np.float64] = field(default_factory=_empty)
    scan_angles: NDArray[np.float64] = field(default_factory=_empty)
    scan_origin: NDArray[np.float64] = field(default_factory=_zero2)
    sensors: Mapping[str, LidarReading | NDArray[np.float64]] = field(
        default_factory=lambda: MappingProxyType({})
    )
    time: float = 0.0
    kinematics: str | None = None
    goal_yaw_tolerance: float | None = None
    goal_xy_tolerance: float | None = None
    pedestrians: NDArray[np.float64] = field(default_factory=_empty_peds)
    costmap: Costmap | None = None

    @property
    def goal_pose(self) -> Pose2D:
        """The goal as a :class:`Pose2D`."""
        if isinstance(self.goal, Pose2D):
            return self.goal
        return Pose2D.from_array(np.asarray(self.goal, dtype=np.float64).reshape(-1))

    @property
    def drive(self) -> str:
        """The kinematics to control: :attr:`kinematics` if given, else inferred from limits."""
        return self.kinematics if self.kinematics is not None else infer_kinematics(self.limits)

    def scan_points(self) -> NDArray[np.float64]:
        """``(m, 2)`` laser returns in the robot frame (m); beams without a finite range dropped."""
        r = np.asarray(self.scan_ranges, dtype=np.float64).reshape(-1)
        a = np.asarray(self.scan_angles, dtype=np.float64).reshape(-1)
        if r.shape != a.shape:
            raise ValueError(f"scan_ranges {r.shape} and scan_angles {a.shape} differ in shape")
        ok = np.isfinite(r) & np.isfinite(a)
        r, a = r[ok], a[ok]
        o = np.asarray(self.scan_origin, dtype=np.float64).reshape(2)
        return np.stack([o[0] + r * np.cos(a), o[1] + r * np.sin(a)], axis=-1)


def infer_kinematics(limits: VelocityLimits) -> str:
    """Guess the kinematics name from limits.

    Sideways motion → ``omni``, a turning radius → ``ackermann``, else ``diff_drive`` (legged
    robots then drive like one of those; pass ``kinematics`` explicitly to be exact).
    """
    if limits.holonomic:
        return "omni"
    if limits.min_turning_radius > 0:
        return "ackermann"
    return "diff_drive"


@runtime_checkable
class LocalPlanner(Protocol):
    """Computes a body-frame velocity command from a :class:`LocalObservation`.

    A planner is a pure function of its observations and its own state; :meth:`reset` clears that
    state (call it at every episode start and whenever it should forget the past).

    Attributes:
        supports: kinematics names (from :data:`KINEMATICS`) the planner can drive.
    """

    supports: ClassVar[frozenset[str]]

    def reset(self) -> None:
        """Forget all internal state."""
        ...

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """Return the command ``(3,)`` ``[vx m/s, vy m/s, omega rad/s]`` to hold for ``obs.dt``.

        The command lies in ``obs.limits``' velocity box and within one tick of acceleration
        (``|cmd - obs.twist| ≤ acceleration · dt``) of ``obs.twist`` whenever ``obs.twist`` itself
        lies in the box. Car-like robots (``ackermann``, or any ``min_turning_radius > 0``) are
        the exception for ``omega``: their yaw rate is speed × curvature and follows the speed, so
        they keep ``|omega| ≤ |vx| / min_turning_radius`` instead of the yaw-acceleration bound.
        ``obs`` is not modified.
        """
        ...


_NAV = "arena.nav.local_planners."
_LEARNED = "arena.learn.planners."  # the planners running learned policies (above nav)
_BUILTIN_PLANNERS = {
    "cohan": _NAV + "cohan", "dwa": _NAV + "dwa", "mpc": _NAV + "mpc",
    "orca": _NAV + "orca_planner", "pure_pursuit": _NAV + "pure_pursuit",
    "social_force": _NAV + "social_force", "teb": _NAV + "teb",
    "crowdnav": _LEARNED + "crowdnav", "rlca": _LEARNED + "rlca", "rosnav_rl": _LEARNED + "learned",
    "sarl": _LEARNED + "crowdnav",
    "dragon": _NAV + "dragon",
    "brne": _NAV + "brne",
    "applr": _LEARNED + "applr",
    "lflh": _LEARNED + "lflh",
    "trail": _LEARNED + "trail",
    "iplanner": _LEARNED + "iplanner",
    # an external ROS node (arena.ros is above nav: it uses the episode runner's frames)
    "ros2": "arena.ros.planner",
    "ros1": "arena.ros.planner",
}

LOCAL_PLANNERS: Registry[LocalPlanner] = Registry(
    "local planner",
    entry_points="arena.local_planners",
    # name -> the module registering it, imported when first named: a config does not import
    # every planner (``orca`` compiles the ORCA crowd kernels)
    builtins=_BUILTIN_PLANNERS,
    # Arena-Rosnav's contest files name its learned planner ``rosnav``
    aliases={"rosnav": "rosnav_rl"},
)


def limit_command(
    cmd: NDArray[np.float64], twist: NDArray[np.float64], limits: VelocityLimits, dt: float
) -> NDArray[np.float64]:
    """Clip a command into the acceleration window around ``twist``, then into the velocity box.

    The box is applied last so a command is never outside it, even when ``twist`` already is.

    Args:
        cmd: ``(3,)`` desired twist ``[vx, vy, omega]``.
        twist: ``(3,)`` current body twist.
        limits: velocity and acceleration limits.
        dt: control period (s).

    Returns:
        ``(3,)`` new array.
    """
    cur = np.asarray(twist, dtype=np.float64).reshape(3)
    step = limits.acceleration * max(float(dt), 0.0)
    out = np.clip(np.asarray(cmd, dtype=np.float64).reshape(3), cur - step, cur + step)
    return limits.clip(out)


def stopping_speed(distance: float, deceleration: float) -> float:
    """Largest speed (m/s) from which braking at ``deceleration`` (m/s²) stops within ``distance``.

    Returns 0 for non-positive distances.
    """
    return math.sqrt(2.0 * deceleration * distance) if distance > 0 else 0.0
