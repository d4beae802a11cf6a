"""Pure pursuit: geometry of the commanded arc, limits, goal braking and the laser safety check."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.nav.local_planners import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner
from arena.robots.limits import VelocityLimits

DT = 0.1
RADIUS = 0.3

DIFF = VelocityLimits(
    vx_min=0.0, vx_max=1.0, vy_min=0.0, vy_max=0.0, omega_max=1.5,
    acc_x=1.0, acc_y=0.0, acc_omega=3.0,
)
OMNI = VelocityLimits(
    vx_min=-0.8, vx_max=0.8, vy_min=-0.6, vy_max=0.6, omega_max=1.2,
    acc_x=1.0, acc_y=1.0, acc_omega=2.0,
)
CAR = VelocityLimits(
    vx_min=0.0, vx_max=1.5, vy_min=0.0, vy_max=0.0, omega_max=1.5,
    acc_x=1.0, acc_y=0.0, acc_omega=2.0, min_turning_radius=1.2,
)
LEGGED = VelocityLimits(
    vx_min=-0.3, vx_max=0.7, vy_min=0.0, vy_max=0.0, omega_max=1.0,
    acc_x=0.8, acc_y=0.0, acc_omega=2.0,
)
DRIVES = {"diff_drive": DIFF, "omni": OMNI, "ackermann": CAR, "legged": LEGGED}


def _pp(**kw: object) -> PurePursuitPlanner:
    return LOCAL_PLANNERS.build({"type": "pure_pursuit", **kw})


def _obs(
    pose, path, *, twist=(0.0, 0.0, 0.0), limits=DIFF, kinematics=None, ranges=None, angles=None,
    goal=None,
) -> LocalObservation:
    path = np.asarray(path, dtype=float)
    return LocalObservation(
        pose=np.asarray(pose, dtype=float),
        twist=np.asarray(twist, dtype=float),
        goal=goal if goal is not None else Pose2D(*path[-1]),
        path=path,
        limits=limits,
        robot_radius=RADIUS,
        dt=DT,
        scan_ranges=np.zeros(0) if ranges is None else np.asarray(ranges, dtype=float),
        scan_angles=np.zeros(0) if angles is None else np.asarray(angles, dtype=float),
        kinematics=kinematics,
    )


def _line(x0: float, x1: float, y: float = 0.0, n: int = 50) -> np.ndarray:
    return np.stack([np.linspace(x0, x1, n), np.full(n, y)], axis=-1)


def _circle(radius: float, sign: float = 1.0, n: int = 400) -> np.ndarray:
    # Starts at the origin heading +x; CCW (left) for sign > 0, CW for sign < 0.
    t = np.linspace(0.0, 1.5 * math.pi, n)
    return np.stack([radius * np.sin(t), sign * radius * (1.0 - np.cos(t))], axis=-1)


def _integrate(pose: np.ndarray, cmd: np.ndarray, dt: float = DT) -> np.ndarray:
    x, y, th = pose
    vx, vy, w = cmd
    c, s = math.cos(th), math.sin(th)
    return np.array([x + (c * vx - s * vy) * dt, y + (s * vx + c * vy) * dt, th + w * dt])


def _within_limits(
    cmd: np.ndarray, twist: np.ndarray, lim: VelocityLimits, ackermann: bool
) -> None:
    eps = 1e-9
    assert np.all(cmd >= lim.lower - eps) and np.all(cmd <= lim.upper + eps)
    step = lim.acceleration * DT + eps
    assert abs(cmd[0] - twist[0]) <= step[0]
    assert abs(cmd[1] - twist[1]) <= step[1]
    if ackermann:
        assert abs(cmd[2]) <= abs(cmd[0]) / lim.min_turning_radius + eps
    else:
        assert abs(cmd[2] - twist[2]) <= step[2]


# -- geometry -----------------------------------------------------------------------------------


def test_straight_path_drives_straight() -> None:
    pp = _pp()
    cmd = pp.compute(_obs([0.0, 0.0, 0.0], _line(0, 10), twist=(0.5, 0, 0)))
    assert cmd[0] == pytest.approx(0.6)  # accelerating by acc_x·dt from 0.5
    assert cmd[1] == 0.0
    assert cmd[2] == pytest.approx(0.0, abs=1e-12)


def test_offset_robot_steers_back_to_the_path() -> None:
    cmd = _pp().compute(_obs([0.0, 0.3, 0.0], _line(0, 10), twist=(0.5, 0, 0)))
    assert cmd[2] < 0  # path is to the right


@pytest.mark.parametrize(("radius", "sign"), [(2.0, 1.0), (2.0, -1.0), (3.5, 1.0)])
def test_circle_path_curvature(radius: float, sign: float) -> None:
    v = min(DIFF.vx_max, DIFF.omega_max * radius)
    twist = (v, 0.0, sign * v / radius)  # steady state on the circle
    cmd = _pp(lookahead=0.8, lookahead_gain=0.0).compute(
        _obs([0.0, 0.0, 0.0], _circle(radius, sign), twist=twist)
    )
    assert cmd[0] > 0
    assert cmd[2] / cmd[0] == pytest.approx(sign / radius, rel=0.02)


def test_circle_curvature_from_mid_path() -> None:
    radius = 2.5
    path = _circle(radius)
    t = 0.7  # a point part-way round, heading tangent
    pose = [radius * math.sin(t), radius * (1 - math.cos(t)), t]
    v = DIFF.vx_max
    cmd = _pp(lookahead=0.7, lookahead_gain=0.0).compute(
        _obs(pose, path, twist=(v, 0, v / radius))
    )
    assert cmd[2] / cmd[0] == pytest.approx(1.0 / radius, rel=0.02)


def test_rotates_in_place_when_target_is_behind() -> None:
    pp = _pp()
    cmd = pp.compute(_obs([0.0, 0.0, 0.0], _line(0, -5)))
    assert cmd[0] == 0.0
    assert abs(cmd[2]) > 0


def test_rotation_hysteresis() -> None:
    pp = _pp(rotate_threshold=0.8)
    path = _line(0, 5)
    # Heading error 1.0 rad: rotate in place.
    assert pp.compute(_obs([0.0, 0.0, -1.0], path))[0] == 0.0
    # 0.6 rad: still latched (above half the threshold).
    assert pp.compute(_obs([0.0, 0.0, -0.6], path))[0] == 0.0
    # 0.3 rad: released, drives.
    assert pp.compute(_obs([0.0, 0.0, -0.3], path))[0] > 0.0
    # A fresh planner at 0.6 rad drives at once (no latch).
    assert _pp(rotate_threshold=0.8).compute(_obs([0.0, 0.0, -0.6], path))[0] > 0.0


def test_omni_moves_sideways_toward_the_path() -> None:
    path = np.stack([np.zeros(30), np.linspace(0, 6, 30)], axis=-1)  # straight up +y
    cmd = _pp().compute(_obs([0.0, 0.0, 0.0], path, limits=OMNI, twist=(0, 0.5, 0)))
    assert cmd[1] > 0.5  # keeps moving left, accelerating
    assert abs(cmd[0]) < 1e-9
    assert cmd[2] > 0  # turns to face the motion


def test_ackermann_curvature_is_bounded() -> None:
    pp = _pp(lookahead=0.5, lookahead_gain=0.0)
    tight = _circle(0.5)  # tighter than the 1.2 m turning radius
    cmd = pp.compute(_obs([0.0, 0.0, 0.0], tight, limits=CAR, twist=(1.0, 0, 0.5)))
    assert cmd[0] > 0
    assert cmd[2] / cmd[0] == pytest.approx(1.0 / CAR.min_turning_radius)
    # A target behind: still moving forward with the tightest turn toward it, never spinning.
    pp.reset()
    cmd = pp.compute(_obs([0.0, 0.0, 0.0], _line(0, -5, y=0.5), limits=CAR, twist=(0.5, 0, 0)))
    assert cmd[0] > 0
    assert cmd[2] / cmd[0] == pytest.approx(1.0 / CAR.min_turning_radius)


@pytest.mark.parametrize("kin", sorted(DRIVES))
def test_commands_respect_velocity_and_acceleration_limits(kin: str) -> None:
    lim = DRIVES[kin]
    rng = np.random.default_rng(7)
    for _ in range(300):
        pp = _pp()
        pose = rng.uniform([-3, -3, -math.pi], [3, 3, math.pi])
        twist = rng.uniform(lim.lower, lim.upper)
        if not lim.holonomic:
            twist[1] = 0.0
        if lim.min_turning_radius > 0:
            twist[0] = abs(twist[0])
            twist[2] = twist[0] / lim.min_turning_radius * rng.uniform(-1, 1)
        path = np.cumsum(rng.normal(0, 1.0, size=(rng.integers(1, 8), 2)), axis=0)
        beams = rng.integers(0, 40)
        obs = _obs(
            pose, path, twist=twist, limits=lim, kinematics=kin,
            ranges=rng.uniform(0.1, 5.0, beams), angles=rng.uniform(-math.pi, math.pi, beams),
        )
        cmd = pp.compute(obs)
        assert cmd.shape == (3,)
        assert np.all(np.isfinite(cmd))
        _within_limits(cmd, twist, lim, ackermann=(kin == "ackermann"))
        if not lim.holonomic:
            assert cmd[1] == 0.0


# -- closed loop --------------------------------------------------------------------------------


@pytest.mark.parametrize("kin", sorted(DRIVES))
def test_stops_at_the_goal(kin: str) -> None:
    lim = DRIVES[kin]
    pp = _pp()
    path = _line(0.0, 4.0)
    pose, twist = np.zeros(3), np.zeros(3)
    for _ in range(400):
        cmd = pp.compute(_obs(pose, path, twist=twist, limits=lim, kinematics=kin))
        _within_limits(cmd, twist, lim, ackermann=(kin == "ackermann"))
        pose, twist = _integrate(pose, cmd), cmd
        assert pose[0] < 4.0 + 0.05  # never overshoots past the tolerance
    assert np.linalg.norm(pose[:2] - path[-1]) <= pp.params.goal_tolerance + 1e-6
    assert np.allclose(twist, 0.0)


def test_aligns_goal_heading_when_asked() -> None:
    pp = _pp(align_goal_heading=True)
    path = _line(0.0, 2.0)
    goal = Pose2D(2.0, 0.0, 1.2)
    pose, twist = np.zeros(3), np.zeros(3)
    for _ in range(300):
        cmd = pp.compute(_obs(pose, path, twist=twist, goal=goal))
        pose, twist = _integrate(pose, cmd), cmd
    assert np.linalg.norm(pose[:2] - goal.xy) <= pp.params.goal_tolerance + 1e-6
    assert abs(pose[2] - 1.2) <= pp.params.goal_yaw_tolerance + 0.05
    without = _pp()
    cmd = without.compute(_obs([2.0, 0.0, 0.0], path, goal=goal))
    assert np.allclose(cmd, 0.0)


def _scan_of_disc(pose: np.ndarray, centre: np.ndarray, radius: float, n: int = 180,
                  range_max: float = 8.0) -> tuple[np.ndarray, np.ndarray]:
    """Exact 2-D lidar returns of one disc, beams in the robot frame (range_max when no hit)."""
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    world = angles + pose[2]
    d = np.stack([np.cos(world), np.sin(world)], axis=-1)
    oc = pose[:2] - centre
    b = d @ oc
    c = oc @ oc - radius * radius
    disc = b * b - c
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    ranges = np.where((disc >= 0) & (t > 0), t, range_max)
    return np.minimum(ranges, range_max), angles


@pytest.mark.parametrize("kin", ["diff_drive", "omni", "legged"])
def test_stops_before_an_obstacle_ahead(kin: str) -> None:
    lim = DRIVES[kin]
    pp = _pp()
    path = _line(0.0, 8.0)
    ped, ped_r = np.array([3.0, 0.0]), 0.3
    pose, twist = np.zeros(3), np.array([min(lim.vx_max, 0.7), 0.0, 0.0])
    for _ in range(300):
        ranges, angles = _scan_of_disc(pose, ped, ped_r)
        cmd = pp.compute(_obs(pose, path, twist=twist, limits=lim, kinematics=kin,
                              ranges=ranges, angles=angles))
        _within_limits(cmd, twist, lim, ackermann=False)
        pose, twist = _integrate(pose, cmd), cmd
        gap = np.linalg.norm(pose[:2] - ped) - RADIUS - ped_r
        assert gap > 0.05
    assert np.allclose(twist[:2], 0.0)
    assert gap >= pp.params.stop_distance - 0.05


def test_obstacle_within_stop_distance_brakes_hard() -> None:
    pp = _pp()
    ranges = np.array([RADIUS + 0.1])  # a return dead ahead, inside stop_distance
    angles = np.array([0.0])
    cmd = pp.compute(_obs([0, 0, 0], _line(0, 5), ranges=ranges, angles=angles))
    assert cmd[0] == 0.0
    cmd = pp.compute(_obs([0, 0, 0], _line(0, 5), twist=(0.8, 0, 0), ranges=ranges, angles=angles))
    assert cmd[0] == pytest.approx(0.8 - DIFF.acc_x * DT)  # braking at the acceleration limit


def test_obstacle_ahead_slows_down_and_beside_does_not() -> None:
    path = _line(0, 8)
    free = _pp().compute(_obs([0, 0, 0], path, twist=(0.5, 0, 0)))
    ahead = _pp().compute(_obs([0, 0, 0], path, twist=(0.5, 0, 0),
                               ranges=[RADIUS + 0.5], angles=[0.0]))
    beside = _pp().compute(_obs([0, 0, 0], path, twist=(0.5, 0, 0),
                                ranges=[1.0, 1.0], angles=[math.pi / 2, -math.pi / 2]))
    behind = _pp().compute(_obs([0, 0, 0], path, twist=(0.5, 0, 0),
                                ranges=[RADIUS + 0.2], angles=[math.pi]))
    assert ahead[0] < free[0]
    assert beside[0] == pytest.approx(free[0])
    assert behind[0] == pytest.approx(free[0])


def test_pedestrian_stepping_in_then_leaving() -> None:
    pp = _pp()
    path = _line(0.0, 10.0)
    pose, twist = np.zeros(3), np.zeros(3)
    ped = np.array([2.5, 0.0])
    stopped_at = None
    for k in range(400):
        present = k < 60
        if present:
            ranges, angles = _scan_of_disc(pose, ped, 0.25)
        else:
            ranges, angles = np.full(180, 8.0), np.linspace(-math.pi, math.pi, 180, endpoint=False)
        cmd = pp.compute(_obs(pose, path, twist=twist, ranges=ranges, angles=angles))
        pose, twist = _integrate(pose, cmd), cmd
        if present:
            assert np.linalg.norm(pose[:2] - ped) > RADIUS + 0.25
            stopped_at = pose[0]
    assert stopped_at is not None and stopped_at < 2.5
    assert pose[0] == pytest.approx(10.0, abs=0.06)  # resumed and finished once it left


def test_shorter_lookahead_used_when_the_nominal_arc_is_blocked() -> None:
    # The inner corner of a box sits beside a bending path: the nominal (long) arc cuts toward
    # it, a halved lookahead follows the path and keeps clear.
    cx, cy = 0.3, -0.34
    xs, ys = np.linspace(-1.5, cx, 80), np.linspace(-2.5, cy, 80)
    pts = np.vstack([np.stack([xs, np.full(80, cy)], 1), np.stack([np.full(80, cx), ys], 1)])
    path = np.array([[0.0, 0.0], [0.45, -0.05], [0.7, -0.4], [0.75, -2.0]])
    obs = _obs([0, 0, 0], path, twist=(0.4, 0, 0), ranges=np.hypot(*pts.T),
               angles=np.arctan2(pts[:, 1], pts[:, 0]))
    adaptive = _pp().compute(obs)
    fixed = _pp(min_lookahead=0.6).compute(obs)
    assert adaptive[0] > 0
    assert abs(adaptive[2]) < abs(fixed[2])  # the gentler arc of the shorter lookahead


def test_margin_band_slows_but_never_stops() -> None:
    # A wall parallel to the path, inside the safety margin but clear of the robot itself.
    wall_y = RADIUS + 0.03
    xs = np.linspace(-1.0, 4.0, 200)
    ranges = np.hypot(xs, wall_y)
    angles = np.arctan2(np.full_like(xs, wall_y), xs)
    pp = _pp(safety_margin=0.1, creep_fraction=0.2)
    pose, twist = np.zeros(3), np.zeros(3)
    for _ in range(30):
        cmd = pp.compute(_obs(pose, _line(0, 10), twist=twist, ranges=ranges, angles=angles))
        pose, twist = _integrate(pose, cmd), cmd
    assert twist[0] == pytest.approx(0.2 * DIFF.vx_max)


# -- state and params -----------------------------------------------------------------------------


def test_reset_restores_fresh_behaviour() -> None:
    path = _line(0, 5)
    fresh = _pp().compute(_obs([0.0, 0.0, -0.6], path))
    pp = _pp()
    pp.compute(_obs([0.0, 0.0, -1.2], path))  # latches rotate-in-place
    pp.reset()
    np.testing.assert_array_equal(pp.compute(_obs([0.0, 0.0, -0.6], path)), fresh)


def test_progress_does_not_jump_back_on_a_looping_path() -> None:
    # An out-and-back path: at the turn the robot must keep following the return leg.
    out = _line(0, 3, y=0.0, n=31)
    back = _line(3, 0, y=0.6, n=31)
    path = np.vstack([out, [[3.3, 0.3]], back])
    pp = _pp(lookahead=0.4, lookahead_gain=0.0)
    pose, twist = np.zeros(3), np.zeros(3)
    for _ in range(600):
        cmd = pp.compute(_obs(pose, path, twist=twist))
        pose, twist = _integrate(pose, cmd), cmd
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.1


def test_params_validation() -> None:
    with pytest.raises(ConfigError, match="slow_distance"):
        _pp(stop_distance=1.0, slow_distance=0.5)
    with pytest.raises(ConfigError, match="lookahead"):
        _pp(lookahead=-1)
    with pytest.raises(ConfigError, match="min_lookahead"):
        _pp(lookahead=0.5, min_lookahead=0.8)


def test_supports_every_kinematics() -> None:
    assert PurePursuitPlanner.supports == frozenset({"diff_drive", "omni", "ackermann", "legged"})


def test_observation_is_not_mutated() -> None:
    obs = _obs([0.1, 0.2, 0.3], _line(0, 5), twist=(0.2, 0, 0.1), ranges=[1.0, 2.0],
               angles=[0.0, 1.0])
    copies = {k: np.array(getattr(obs, k)) for k in ("pose", "twist", "path", "scan_ranges")}
    _pp().compute(obs)
    for k, v in copies.items():
        np.testing.assert_array_equal(getattr(obs, k), v)


def _drive_past_standing_person(pp: PurePursuitPlanner, kin: str, ticks: int = 400):
    """Drive a straight 8 m path with a person standing on it at x = 3 m; time advances."""
    lim = DRIVES[kin]
    path = _line(0.0, 8.0)
    ped, ped_r = np.array([3.0, 0.0]), 0.3
    pose, twist = np.zeros(3), np.zeros(3)
    stopped, left_path, min_gap = None, None, math.inf
    for k in range(ticks):
        ranges, angles = _scan_of_disc(pose, ped, ped_r)
        obs = _obs(pose, path, twist=twist, limits=lim, kinematics=kin, ranges=ranges,
                   angles=angles)
        obs = dataclasses.replace(obs, time=k * DT)
        cmd = pp.compute(obs)
        _within_limits(cmd, twist, lim, ackermann=False)
        pose, twist = _integrate(pose, cmd), cmd
        min_gap = min(min_gap, float(np.linalg.norm(pose[:2] - ped)) - RADIUS - ped_r)
        if stopped is None and k > 5 and abs(cmd[0]) < 1e-9:
            stopped = k * DT
        if left_path is None and abs(pose[1]) > 0.05:
            left_path = k * DT
    return pose, min_gap, stopped, left_path


@pytest.mark.parametrize("kin", ["diff_drive", "legged"])
def test_steps_around_a_person_who_stays_in_the_way(kin: str) -> None:
    """Blocked for detour_after s, a robot that turns on the spot detours and reaches the goal."""
    pp = _pp()
    pose, min_gap, stopped, left_path = _drive_past_standing_person(pp, kin)
    assert pose[0] == pytest.approx(8.0, abs=0.06) and abs(pose[1]) < 0.06  # at the goal
    assert min_gap > 0.0  # never touched the person
    assert stopped is not None and left_path is not None
    assert left_path >= stopped + pp.params.detour_after - DT  # it waited first


def test_without_detour_the_robot_waits_for_good() -> None:
    pose, min_gap, _, left_path = _drive_past_standing_person(_pp(detour_after=None), "diff_drive")
    assert pose[0] < 3.0 - RADIUS - 0.3 and left_path is None and min_gap > 0.05


@pytest.mark.parametrize("kin", ["legged", "diff_drive"])
def test_backs_off_when_no_side_is_free(kin: str) -> None:
    """Returns all around the front half: a robot that can reverse backs off, others wait."""
    lim = DRIVES[kin]
    pp = _pp()
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    ranges = np.where(np.abs(angles) < 1.75, RADIUS + 0.1, 8.0)  # front and sides, 0.1 m away
    path = _line(0.0, 5.0)
    cmds = []
    for k in range(30):
        obs = dataclasses.replace(_obs([0, 0, 0], path, limits=lim, kinematics=kin,
                                       ranges=ranges, angles=angles), time=k * DT)
        cmds.append(pp.compute(obs))
    first_reverse = next((k for k, c in enumerate(cmds) if c[0] < 0), None)
    if lim.vx_min < 0:
        assert first_reverse is not None
        assert first_reverse * DT >= pp.params.detour_after - 1e-9  # it waited first
        assert all(c[0] <= 0 and c[2] == 0 for c in cmds[first_reverse:])  # straight back
    else:
        assert first_reverse is None and all(c[0] == 0 for c in cmds)
