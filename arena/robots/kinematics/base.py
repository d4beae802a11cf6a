"""The kinematics contract, its registry, and the shared vectorised helpers.

A kinematics model turns desired body twists into executed twists and new poses for ``n`` robots
of one model at once. Every model runs the same pipeline in :meth:`Kinematics.step`:

1. velocity limits on the command (the model's feasible velocity set),
2. acceleration limits over ``dt`` from the previous executed twist (a per-axis "dynamic window",
   as in DWA and ``diff_drive_controller``),
3. kinematic constraints (no side slip, steering geometry ...),
4. exact integration of the pose for a twist held constant over ``dt`` (zero-order hold), i.e.
   motion along the circular arc, not an Euler step.

Velocity limits are hard: where a previous twist lies outside the feasible set (a hand-made initial
state), the result is brought back inside at once, even if that breaks an acceleration limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import SimulationError
from arena.core.registry import Registry
from arena.robots.limits import VelocityLimits

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class KinematicState:
    """Kinematic state of ``n`` robots of one model (a struct of arrays).

    Attributes:
        poses: ``(n, 3)`` world poses ``[x, y, theta]`` (m, m, rad).
        twists: ``(n, 3)`` body-frame twists ``[vx, vy, omega]`` (m/s, m/s, rad/s) actually
            executed during the last step (the starting point of the next acceleration window).
        steering: ``(n,)`` front-wheel steering angle (rad); used by ``ackermann`` only, zeros
            for every other model.
    """

    poses: FloatArray
    twists: FloatArray
    steering: FloatArray

    def __post_init__(self) -> None:
        poses = np.asarray(self.poses, dtype=np.float64)
        twists = np.asarray(self.twists, dtype=np.float64)
        steering = np.asarray(self.steering, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != 3:
            raise SimulationError(f"poses must have shape (n, 3), got {poses.shape}")
        n = poses.shape[0]
        if twists.shape != (n, 3):
            raise SimulationError(f"twists must have shape ({n}, 3), got {twists.shape}")
        if steering.shape != (n,):
            raise SimulationError(f"steering must have shape ({n},), got {steering.shape}")
        # frozen dataclass: the converted arrays are stored through object.__setattr__
        object.__setattr__(self, "poses", poses)
        object.__setattr__(self, "twists", twists)
        object.__setattr__(self, "steering", steering)

    @classmethod
    def at_rest(cls, poses: ArrayLike) -> KinematicState:
        """Robots standing still at ``poses`` ``(n, 3)`` with straight wheels."""
        p = np.array(poses, dtype=np.float64).reshape(-1, 3)
        n = p.shape[0]
        return cls(p, np.zeros((n, 3)), np.zeros(n))

    def __len__(self) -> int:
        return int(self.poses.shape[0])


@runtime_checkable
class Kinematics(Protocol):
    """A motion model for ``n`` robots of one kind, vectorised.

    Attributes:
        name: the registry key (``diff_drive`` ...).
        holonomic: whether the model can move sideways (``vy ≠ 0``).
        params: the validated ``Params`` model the instance was built from.
    """

    name: ClassVar[str]
    params: Any

    @property
    def holonomic(self) -> bool:
        """Whether the model can move sideways."""
        ...

    def limits(self) -> VelocityLimits:
        """The box summary of the model's velocity and acceleration limits, for planners."""
        ...

    def step(self, state: KinematicState, commands: ArrayLike, dt: float) -> KinematicState:
        """Advance ``n`` robots by ``dt`` seconds; pure (inputs are never mutated).

        Args:
            state: the current state of the ``n`` robots.
            commands: ``(n, 3)`` desired body twists ``[vx, vy, omega]`` (m/s, m/s, rad/s).
            dt: step length (s), > 0.

        Returns:
            The new state: poses after ``dt``, the twists executed during the step, steering.

        Raises:
            SimulationError: on a wrong command shape, non-finite commands or ``dt <= 0``.
        """
        ...


KINEMATICS: Registry[Kinematics] = Registry("kinematics", entry_points="arena.kinematics")


# -- helpers shared by the models -------------------------------------------------------------
def check_step_inputs(state: KinematicState, commands: ArrayLike, dt: float) -> FloatArray:
    """Validate ``commands`` against ``state`` and ``dt``; return them as a new ``(n, 3)`` array."""
    if not (np.isfinite(dt) and dt > 0):
        raise SimulationError(f"dt must be a finite number > 0, got {dt!r}")
    cmd = np.array(commands, dtype=np.float64)  # a copy: the caller's array is never touched
    n = len(state)
    if cmd.shape != (n, 3):
        raise SimulationError(f"commands must have shape ({n}, 3) for {n} robots, got {cmd.shape}")
    if not np.all(np.isfinite(cmd)):
        bad = np.flatnonzero(~np.all(np.isfinite(cmd), axis=1)).tolist()
        raise SimulationError(f"non-finite commands for robots {bad}")
    return cmd


def rate_limit(current: FloatArray, target: FloatArray, max_delta: ArrayLike) -> FloatArray:
    """Move ``current`` toward ``target`` by at most ``max_delta`` per component (any shape).

    ``max_delta`` may be ``inf`` (no limit); the result equals ``target`` then.
    """
    lim = np.asarray(max_delta, dtype=np.float64)
    return current + np.clip(target - current, -lim, lim)


def integrate_twist(poses: FloatArray, twists: FloatArray, dt: float) -> FloatArray:
    """Exact pose after holding each body twist constant for ``dt`` (the SE(2) exponential).

    For ``phi = omega·dt`` the body-frame displacement is
    ``[S·vx − C·vy, C·vx + S·vy]`` with ``S = sin(phi)/omega`` and ``C = (1 − cos phi)/omega``;
    near ``omega = 0`` their Taylor series are used (straight line in the limit).

    Args:
        poses: ``(n, 3)`` start poses ``[x, y, theta]``.
        twists: ``(n, 3)`` body twists ``[vx, vy, omega]``.
        dt: duration (s).

    Returns:
        ``(n, 3)`` end poses, heading wrapped to ``[-pi, pi)``.
    """
    out = np.empty((poses.shape[0], 3))
    _integrate_kernel(
        np.ascontiguousarray(poses, dtype=np.float64),
        np.ascontiguousarray(twists, dtype=np.float64),
        float(dt),
        out,
    )
    return out


@njit(cache=True)
def _integrate_kernel(poses: FloatArray, twists: FloatArray, dt: float, out: FloatArray) -> None:
    for i in range(poses.shape[0]):
        _integrate_row(poses, twists, dt, i, out)


@njit(cache=True, inline="always")
def _integrate_row(poses: FloatArray, twists: FloatArray, dt: float, i: int,
                   out: FloatArray) -> None:
    """Row ``i`` of :func:`_integrate_kernel`: exact arc under the constant twist ``twists[i]``."""
    vx, vy, om = twists[i, 0], twists[i, 1], twists[i, 2]
    phi = om * dt
    if abs(phi) < 1e-4:
        p2 = phi * phi
        s = dt * (1.0 - p2 / 6.0 + p2 * p2 / 120.0)  # sin(phi)/omega
        c = dt * phi * (0.5 - p2 / 24.0 + p2 * p2 / 720.0)  # (1 - cos phi)/omega
    else:
        s = math.sin(phi) / om
        c = (1.0 - math.cos(phi)) / om
    dxb = s * vx - c * vy
    dyb = c * vx + s * vy
    th = poses[i, 2]
    ct, st = math.cos(th), math.sin(th)
    out[i, 0] = poses[i, 0] + ct * dxb - st * dyb
    out[i, 1] = poses[i, 1] + st * dxb + ct * dyb
    out[i, 2] = (th + phi + math.pi) % (2.0 * math.pi) - math.pi


def box_step(
    poses: FloatArray,
    twists: FloatArray,
    commands: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    acc: FloatArray,
    dt: float,
) -> tuple[FloatArray, FloatArray]:
    """The whole pipeline for box velocity limits and per-axis acceleration limits, compiled.

    Equivalent to ``target = clip(cmd)``, ``prev = clip(twist)``,
    ``twist = clip(prev + clip(target - prev, ±acc·dt))`` and :func:`integrate_twist`; one call
    instead of a dozen small numpy operations (the simulator's hot path for one robot).

    Returns:
        ``(poses, twists)``, each ``(n, 3)``.
    """
    n = poses.shape[0]
    out_p = np.empty((n, 3))
    out_t = np.empty((n, 3))
    _box_kernel(poses, twists, commands, lower, upper, acc, float(dt), out_t)
    _integrate_kernel(poses, out_t, float(dt), out_p)
    return out_p, out_t


@njit(cache=True)
def _box_kernel(
    poses: FloatArray,
    twists: FloatArray,
    cmd: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    acc: FloatArray,
    dt: float,
    out: FloatArray,
) -> None:
    for i in range(poses.shape[0]):
        _box_twist_row(twists, cmd, lower, upper, acc, dt, i, out)


@njit(cache=True, inline="always")
def _box_twist_row(
    twists: FloatArray, cmd: FloatArray, lower: FloatArray, upper: FloatArray, acc: FloatArray,
    dt: float, i: int, out: FloatArray,
) -> None:
    """Row ``i`` of :func:`_box_kernel`: the command clipped to the box, steps up to ``acc·dt``."""
    for k in range(3):
        lo, hi = lower[k], upper[k]
        target = min(max(cmd[i, k], lo), hi)
        prev = min(max(twists[i, k], lo), hi)
        step = acc[k] * dt
        d = min(max(target - prev, -step), step)
        out[i, k] = min(max(prev + d, lo), hi)


@njit(cache=True)
def box_step_rows(
    poses: FloatArray,
    twists: FloatArray,
    commands: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    acc: FloatArray,
    dt: float,
    rows: NDArray[np.int64],
    out_poses: FloatArray,
    out_twists: FloatArray,
    out_steering: FloatArray,
) -> None:
    """:func:`box_step` for the rows ``rows`` only, written into those rows of the outputs.

    For a simulator that keeps the poses ``(r, 3)``, twists ``(r, 3)`` and commands ``(r, 3)``
    of all its robots in C-contiguous float64 arrays and steps the robots of one box model by
    one call: no input checks, no intermediate arrays (the caller has validated ``commands``
    and ``dt``). Each row runs :func:`_box_kernel`'s then :func:`_integrate_kernel`'s row
    function, the operations of :func:`box_step` in the same order, so the results are
    bit-identical.

    Args:
        poses: ``(r, 3)`` poses ``[x m, y m, theta rad]``.
        twists: ``(r, 3)`` executed twists of the last step ``[vx m/s, vy m/s, omega rad/s]``.
        commands: ``(r, 3)`` desired twists, finite.
        lower: ``(3,)`` a model's :attr:`box_limits` lower velocity bounds.
        upper: ``(3,)`` upper velocity bounds.
        acc: ``(3,)`` acceleration limits.
        dt: step (s), finite and > 0.
        rows: the rows to step.
        out_poses: ``(r, 3)``, each row of ``rows`` receives its new pose.
        out_twists: ``(r, 3)``, each row receives its executed twist.
        out_steering: ``(r,)``, each row receives 0 (box models have no steering).
    """
    for k in range(rows.shape[0]):
        i = rows[k]
        _box_twist_row(twists, commands, lower, upper, acc, dt, i, out_twists)
        _integrate_row(poses, out_twists, dt, i, out_poses)
        out_steering[i] = 0.0


def quadric_norm(v: FloatArray, weights: FloatArray) -> FloatArray:
    """``sqrt(Σ_i w_i v_i²)`` over the last axis: ≤ 1 inside the ellipsoid ``Σ w v² ≤ 1``."""
    norm: FloatArray = np.sqrt(np.sum(weights * v * v, axis=-1))
    return norm


def larger_root(a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
    """Larger real root of ``a·s² + b·s + c = 0`` per element, for ``a ≥ 0``.

    Returns ``inf`` where ``a = 0`` (no quadratic growth: the bound is never reached) and 0 where
    there is no non-negative real root (the start is already outside: do not move).
    """
    disc = b * b - 4.0 * a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    # the numerically stable form of (-b + sq) / 2a: no cancellation for b >= 0
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.where(b >= 0.0, -2.0 * c / (b + sq), (sq - b) / (2.0 * a))
    # no real root, or only negative ones: the start is outside already, so do not move
    root = np.where(np.isnan(root) | (disc < 0.0), 0.0, np.maximum(root, 0.0))
    return np.where(a > 0.0, root, np.inf)


def quadric_step_fraction(start: FloatArray, delta: FloatArray, weights: ArrayLike) -> FloatArray:
    """Largest ``s`` with ``Σ_i w_i (start_i + s·delta_i)² ≤ 1``, per row.

    Used to stop a twist on the boundary of an elliptical velocity limit: with ``start`` inside,
    ``start + s·delta`` for ``s ∈ [0, result]`` stays inside.

    Args:
        start: ``(n, k)`` points (inside the ellipsoid for the result to be meaningful).
        delta: ``(n, k)`` directions.
        weights: ``(n, k)`` or ``(k,)`` non-negative inverse squared semi-axes.

    Returns:
        ``(n,)`` fractions; ``inf`` where ``delta`` has no weighted component.
    """
    w = np.asarray(weights, dtype=np.float64)
    a = np.sum(w * delta * delta, axis=-1)
    b = 2.0 * np.sum(w * start * delta, axis=-1)
    c = np.sum(w * start * start, axis=-1) - 1.0
    return larger_root(a, b, c)
