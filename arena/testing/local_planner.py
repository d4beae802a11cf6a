"""The local-planner contract (:class:`~arena.nav.local_planners.base.LocalPlanner`), checked.

:func:`check_local_planner` is what the project's conformance test runs on every registered local
planner; plugin authors run it on theirs::

    from arena.testing import check_local_planner

    def test_my_planner():
        check_local_planner(lambda: MyPlanner(MyPlanner.Params()))
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from arena.core.types import Pose2D
from arena.nav.local_planners.base import KINEMATICS, LocalObservation, LocalPlanner
from arena.robots.limits import VelocityLimits

#: Control period of the checks (s).
DT = 0.1

#: Velocity and acceleration limits per kinematics the checks drive with (SI units).
STANDARD_LIMITS: dict[str, VelocityLimits] = {
    "diff_drive": VelocityLimits(0.0, 1.0, 0.0, 0.0, 1.5, 1.0, 0.0, 3.0),
    "legged": VelocityLimits(-0.3, 0.7, 0.0, 0.0, 1.0, 0.8, 0.0, 2.0),
    "omni": VelocityLimits(-0.8, 0.8, -0.6, 0.6, 1.2, 1.0, 1.0, 2.0),
    "ackermann": VelocityLimits(0.0, 1.5, 0.0, 0.0, 1.5, 1.0, 0.0, 2.0, min_turning_radius=1.2),
}

_ARRAYS = ("pose", "twist", "path", "scan_ranges", "scan_angles", "scan_origin")


def free_road_observation(kinematics: str) -> LocalObservation:
    """At rest at the origin, facing a goal 3 m ahead on a straight path; no laser returns."""
    return LocalObservation(
        pose=np.zeros(3),
        twist=np.zeros(3),
        goal=Pose2D(3.0, 0.0),
        path=np.array([[0.0, 0.0], [3.0, 0.0]]),
        limits=STANDARD_LIMITS[kinematics],
        robot_radius=0.3,
        dt=DT,
        kinematics=kinematics,
    )


def random_twist(rng: np.random.Generator, lim: VelocityLimits, kinematics: str) -> np.ndarray:
    """A random twist ``(vx, vy, omega)`` (m/s, rad/s) that drive ``kinematics`` can have.

    Inside the box ``lim``; no sideways speed unless holonomic; an ackermann robot drives
    forward and turns no tighter than its minimum turning radius.
    """
    twist = rng.uniform(lim.lower, lim.upper)
    if not lim.holonomic:
        twist[1] = 0.0
    if kinematics == "ackermann":
        twist[0] = abs(twist[0])
        twist[2] = twist[0] / lim.min_turning_radius * rng.uniform(-1, 1)
    return twist


def random_observations(
    rng: np.random.Generator, kinematics: str, n: int = 20
) -> list[LocalObservation]:
    """``n`` observations with random pose, twist (inside the limits), path, goal and scan."""
    lim = STANDARD_LIMITS[kinematics]
    out = []
    for _ in range(n):
        twist = random_twist(rng, lim, kinematics)
        pose = rng.uniform([-2, -2, -math.pi], [2, 2, math.pi])
        steps = rng.normal(0, 1.0, (rng.integers(1, 6), 2))
        path = np.vstack([pose[:2], pose[:2] + np.cumsum(steps, axis=0)])
        beams = int(rng.integers(0, 60))
        out.append(LocalObservation(
            pose=pose,
            twist=twist,
            goal=Pose2D(*path[-1], rng.uniform(-3, 3)),
            path=path,
            limits=lim,
            robot_radius=float(rng.uniform(0.1, 0.5)),
            dt=DT,
            scan_ranges=rng.uniform(0.05, 6.0, beams),
            scan_angles=rng.uniform(-math.pi, math.pi, beams),
            scan_origin=rng.uniform(-0.1, 0.1, 2),
            time=float(rng.uniform(0, 100)),
            kinematics=kinematics,
        ))
    return out


def _fmt(a: Any) -> str:
    return np.array2string(np.asarray(a, dtype=float), precision=4, separator=", ")


def _check_command(cmd: np.ndarray, obs: LocalObservation, where: str) -> None:
    assert cmd.shape == (3,), f"{where}: the command must have shape (3,), got {cmd.shape}"
    assert np.all(np.isfinite(cmd)), f"{where}: the command must be finite, got {_fmt(cmd)}"
    lim = obs.limits
    assert np.all(cmd >= lim.lower - 1e-9) and np.all(cmd <= lim.upper + 1e-9), (
        f"{where}: command {_fmt(cmd)} outside the velocity box {_fmt(lim.lower)} .. "
        f"{_fmt(lim.upper)}"
    )
    room = lim.acceleration * obs.dt + 1e-9
    for i, axis in ((0, "vx"), (1, "vy")):
        assert abs(cmd[i] - obs.twist[i]) <= room[i], (
            f"{where}: {axis} changes by {abs(cmd[i] - obs.twist[i]):.4f} m/s in one tick, more "
            f"than acceleration · dt = {room[i]:.4f} (twist {_fmt(obs.twist)}, command {_fmt(cmd)})"
        )
    if obs.kinematics == "ackermann":
        cap = abs(cmd[0]) / lim.min_turning_radius + 1e-9
        assert abs(cmd[2]) <= cap, (
            f"{where}: |omega| = {abs(cmd[2]):.4f} rad/s exceeds |vx| / min_turning_radius = "
            f"{cap:.4f} (a car cannot turn on the spot)"
        )
    else:
        assert abs(cmd[2] - obs.twist[2]) <= room[2], (
            f"{where}: omega changes by {abs(cmd[2] - obs.twist[2]):.4f} rad/s in one tick, more "
            f"than acceleration · dt = {room[2]:.4f}"
        )
    if not lim.holonomic:
        assert cmd[1] == 0.0, f"{where}: a non-holonomic robot needs vy == 0, got {cmd[1]!r}"


def check_local_planner(
    make_planner: Callable[[], Any],
    *,
    kinematics: Iterable[str] | None = None,
    moves_on_free_road: bool = True,
    seed: int = 12345,
) -> None:
    """Check a local planner against the :class:`LocalPlanner` contract.

    For each kinematics checked it feeds 20 random observations (random pose, twist inside the
    limits, path, goal and laser scan) and asserts that every command is a finite ``(3,)`` array
    inside the velocity box, within one tick of acceleration of the current twist (car-like:
    ``|omega| ≤ |vx| / min_turning_radius``), with ``vy == 0`` for non-holonomic robots; that no
    observation array is modified; that after ``reset()`` the same observations give the same
    commands, as does a fresh instance; and (``moves_on_free_road``) that at rest with a goal
    3 m straight ahead and no laser returns it drives forward (``vx > 0``).

    Args:
        make_planner: builds a fresh planner, e.g. ``lambda: MyPlanner(MyPlanner.Params())``.
        kinematics: the kinematics to check (default: every name in the planner's ``supports``).
        moves_on_free_road: check the free-road start (False for planners that may rightly
            stand still there, e.g. an untrained learned policy).
        seed: seed of the random observations.

    Raises:
        AssertionError: naming the planner, the kinematics, the observation and the broken rule.
    """
    planner = make_planner()
    name = type(planner).__name__
    assert isinstance(planner, LocalPlanner), (
        f"{name} does not implement LocalPlanner: it needs a `supports` class attribute "
        "(frozenset of kinematics names), reset() and compute(obs)"
    )
    supports = frozenset(planner.supports)
    assert supports and supports <= KINEMATICS, (
        f"{name}.supports must be a non-empty subset of {sorted(KINEMATICS)}, "
        f"got {sorted(supports)}"
    )
    kins = sorted(supports if kinematics is None else kinematics)
    unsupported = sorted(set(kins) - supports)
    assert not unsupported, f"{name}: asked to check {unsupported}, not in supports"
    for kin in kins:
        observations = random_observations(np.random.default_rng(seed), kin)
        planner.reset()
        first = []
        for i, obs in enumerate(observations):
            before = {k: np.array(getattr(obs, k), copy=True) for k in _ARRAYS}
            cmd = np.asarray(planner.compute(obs))
            first.append(cmd.copy())
            _check_command(cmd, obs, f"{name} ({kin}), observation {i}")
            for key, value in before.items():
                assert np.array_equal(getattr(obs, key), value), (
                    f"{name} ({kin}), observation {i}: compute() modified obs.{key}"
                )
        planner.reset()
        for i, (obs, cmd) in enumerate(zip(observations, first, strict=True)):
            again = np.asarray(planner.compute(obs))
            assert np.array_equal(again, cmd), (
                f"{name} ({kin}), observation {i}: not deterministic after reset(): "
                f"{_fmt(cmd)} then {_fmt(again)}"
            )
        other = make_planner()
        for i, (obs, cmd) in enumerate(zip(observations, first, strict=True)):
            fresh = np.asarray(other.compute(obs))
            assert np.array_equal(fresh, cmd), (
                f"{name} ({kin}), observation {i}: a fresh instance answers {_fmt(fresh)}, "
                f"the first one {_fmt(cmd)}"
            )
        if moves_on_free_road:
            obs = free_road_observation(kin)
            cmd = np.asarray(make_planner().compute(obs))
            _check_command(cmd, obs, f"{name} ({kin}), free road")
            assert cmd[0] > 0, (
                f"{name} ({kin}): at rest with a goal 3 m straight ahead and no obstacles it must "
                f"drive forward (vx > 0), got {_fmt(cmd)}"
            )
