"""Kinematics models against analytic solutions, plus a conformance run over the registry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import ConfigError, SimulationError, UnknownNameError
from arena.robots.kinematics import KINEMATICS, Kinematics, KinematicState, integrate_twist

HUGE = 1e12  # an acceleration limit that never binds

# Sample parameters for every built-in model (finite accelerations, asymmetric where allowed).
SAMPLES: dict[str, dict] = {
    "diff_drive": dict(vx_min=-0.3, vx_max=1.0, omega_max=2.0, acc_x=1.5, acc_omega=4.0),
    "omni": dict(
        vx_min=-0.5, vx_max=1.2, vy_min=-0.4, vy_max=0.6, omega_max=1.5, speed_max=1.0,
        acc_x=2.0, acc_y=1.0, acc_omega=3.0,
    ),
    "ackermann": dict(
        wheelbase=0.33, max_steering_angle=0.42, max_steering_rate=3.2, vx_min=-2.0,
        vx_max=4.0, acc_x=2.5,
    ),
    "legged": dict(
        vx_min=-0.4, vx_max=0.8, vy_max=0.5, omega_max=1.2, max_speed=0.7,
        acc_x=1.25, acc_y=1.0, acc_omega=1.5,
    ),
}


def build(kind: str, **params) -> Kinematics:
    return KINEMATICS.build({"type": kind, **params})


def run(kin: Kinematics, state: KinematicState, command, dt: float, steps: int) -> KinematicState:
    cmd = np.broadcast_to(np.asarray(command, dtype=float), (len(state), 3))
    for _ in range(steps):
        state = kin.step(state, cmd, dt)
    return state


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


# -- integration -------------------------------------------------------------------------------
def test_integrate_twist_is_continuous_at_zero_yaw_rate():
    poses = np.array([[1.0, -2.0, 0.7]])
    straight = integrate_twist(poses, np.array([[0.8, 0.3, 0.0]]), 0.5)
    almost = integrate_twist(poses, np.array([[0.8, 0.3, 1e-12]]), 0.5)
    np.testing.assert_allclose(almost, straight, atol=1e-12)
    expected = poses[0, :2] + 0.5 * np.array(
        [0.8 * math.cos(0.7) - 0.3 * math.sin(0.7), 0.8 * math.sin(0.7) + 0.3 * math.cos(0.7)]
    )
    np.testing.assert_allclose(straight[0, :2], expected, atol=1e-15)


# -- diff drive --------------------------------------------------------------------------------
@pytest.mark.parametrize("dt", [0.37, 0.1, 0.01])
def test_diff_drive_unicycle_arc_matches_circle(dt):
    v, w = 0.5, 0.7
    kin = build("diff_drive", vx_min=-1.0, vx_max=1.0, omega_max=2.0, acc_x=HUGE, acc_omega=HUGE)
    steps = round(7.4 / dt)
    t = steps * dt
    end = run(kin, KinematicState.at_rest([[0.0, 0.0, 0.0]]), [v, 0.0, w], dt, steps)
    expected = [(v / w) * math.sin(w * t), (v / w) * (1 - math.cos(w * t))]
    np.testing.assert_allclose(end.poses[0, :2], expected, atol=1e-9)
    assert abs(wrap(end.poses[0, 2] - w * t)) < 1e-9
    np.testing.assert_allclose(end.twists[0], [v, 0.0, w], atol=0)


def test_diff_drive_straight_line():
    kin = build("diff_drive", vx_min=-1.0, vx_max=1.0, omega_max=2.0)
    start = KinematicState.at_rest([[2.0, -1.0, 0.6]])
    end = run(kin, start, [0.8, 0.0, 0.0], 0.05, 200)
    t = 200 * 0.05
    np.testing.assert_allclose(
        end.poses[0], [2.0 + 0.8 * t * math.cos(0.6), -1.0 + 0.8 * t * math.sin(0.6), 0.6],
        atol=1e-9,
    )


def test_diff_drive_clips_commands_to_limits():
    kin = build("diff_drive", vx_min=-0.3, vx_max=1.0, omega_max=2.0)
    state = KinematicState.at_rest(np.zeros((2, 3)))
    out = kin.step(state, [[10.0, 5.0, 9.0], [-10.0, -5.0, -9.0]], 0.1)
    np.testing.assert_array_equal(out.twists, [[1.0, 0.0, 2.0], [-0.3, 0.0, -2.0]])


def test_diff_drive_acceleration_limits_one_step():
    kin = build("diff_drive", vx_min=-1.0, vx_max=1.0, omega_max=2.0, acc_x=0.5, acc_omega=3.0)
    out = kin.step(KinematicState.at_rest([[0.0, 0.0, 0.0]]), [[1.0, 0.0, -2.0]], 0.1)
    np.testing.assert_allclose(out.twists[0], [0.05, 0.0, -0.3], atol=1e-15)
    # the executed twist is held for the whole step
    expected = integrate_twist(np.zeros((1, 3)), out.twists, 0.1)
    np.testing.assert_allclose(out.poses, expected, atol=1e-15)
    # speed ramps linearly until it reaches the command
    speeds = [out.twists[0, 0]]
    state = out
    for _ in range(30):
        state = kin.step(state, [[1.0, 0.0, 0.0]], 0.1)
        speeds.append(state.twists[0, 0])
    np.testing.assert_allclose(speeds[:20], 0.05 * np.arange(1, 21), atol=1e-12)
    assert speeds[-1] == 1.0


def test_diff_drive_rejects_bad_params():
    with pytest.raises(ConfigError, match="vx_min"):
        build("diff_drive", vx_min=0.1, vx_max=1.0, omega_max=1.0)
    with pytest.raises(ConfigError, match="omega_max"):
        build("diff_drive", vx_min=-0.1, vx_max=1.0)
    with pytest.raises(ConfigError, match="acc_x"):
        build("diff_drive", vx_min=-0.1, vx_max=1.0, omega_max=1.0, acc_x=0.0)
    with pytest.raises(UnknownNameError, match="did you mean 'diff_drive'"):
        KINEMATICS.build({"type": "diffdrive"})


# -- omni --------------------------------------------------------------------------------------
@pytest.mark.parametrize("dt", [0.25, 0.02])
def test_omni_exact_integration_under_rotation(dt):
    vx, vy, w = 0.6, -0.35, 0.9
    x0, y0, th0 = 1.0, 2.0, -0.4
    kin = build("omni", vx_min=-1, vx_max=1, vy_min=-1, vy_max=1, omega_max=2)
    steps = round(5.0 / dt)
    t = steps * dt
    end = run(kin, KinematicState.at_rest([[x0, y0, th0]]), [vx, vy, w], dt, steps)
    th = th0 + w * t
    x = x0 + (vx * (math.sin(th) - math.sin(th0)) + vy * (math.cos(th) - math.cos(th0))) / w
    y = y0 + (-vx * (math.cos(th) - math.cos(th0)) + vy * (math.sin(th) - math.sin(th0))) / w
    np.testing.assert_allclose(end.poses[0, :2], [x, y], atol=1e-9)
    assert abs(wrap(end.poses[0, 2] - th)) < 1e-9


def test_omni_sideways_while_turning_closes_a_circle():
    # pure lateral speed with a full turn: the robot drives a circle of radius vy/omega
    kin = build("omni", vx_min=-1, vx_max=1, vy_min=-1, vy_max=1, omega_max=2)
    w = 2 * math.pi / 8.0
    end = run(kin, KinematicState.at_rest([[0.0, 0.0, 0.0]]), [0.0, 0.5, w], 0.1, 80)
    np.testing.assert_allclose(end.poses[0], [0.0, 0.0, 0.0], atol=1e-9)


def test_omni_box_and_speed_cap():
    kin = build("omni", **SAMPLES["omni"] | dict(acc_x=HUGE, acc_y=HUGE, acc_omega=HUGE))
    out = kin.step(KinematicState.at_rest(np.zeros((3, 3))),
                   [[5.0, 0.0, 9.0], [0.0, -5.0, 0.0], [0.8, 0.6, 0.0]], 0.1)
    np.testing.assert_allclose(out.twists[0], [1.0, 0.0, 1.5])  # speed cap 1.0 < vx_max 1.2
    np.testing.assert_allclose(out.twists[1], [0.0, -0.4, 0.0])  # box
    np.testing.assert_allclose(out.twists[2], [0.8, 0.6, 0.0])  # norm exactly 1: unchanged
    # a command beyond the disc is scaled along its direction onto it
    out = kin.step(KinematicState.at_rest(np.zeros((1, 3))), [[1.2, 0.6, 0.0]], 0.1)
    assert math.hypot(*out.twists[0, :2]) == pytest.approx(1.0, abs=1e-12)
    assert out.twists[0, 1] / out.twists[0, 0] == pytest.approx(0.5)


def test_omni_per_axis_acceleration_and_disc_together():
    kin = build("omni", vx_min=-1, vx_max=1, vy_min=-1, vy_max=1, omega_max=1, speed_max=1.0,
                acc_x=HUGE, acc_y=0.5, acc_omega=HUGE)
    prev = KinematicState(np.zeros((1, 3)), np.array([[0.0, -1.0, 0.0]]), np.zeros(1))
    out = kin.step(prev, [[1.0, 0.0, 0.0]], 0.1)
    dv = out.twists[0] - prev.twists[0]
    assert abs(dv[1]) <= 0.05 + 1e-12
    assert math.hypot(*out.twists[0, :2]) <= 1.0 + 1e-12
    assert math.hypot(*out.twists[0, :2]) == pytest.approx(1.0, abs=1e-12)  # stops on the rim


# -- ackermann ---------------------------------------------------------------------------------
def car(**kw) -> Kinematics:
    params = dict(wheelbase=0.3302, max_steering_angle=0.4189, vx_min=-5.0, vx_max=5.0)
    return build("ackermann", **params | kw)


def circumradius(a, b, c) -> float:
    ab, bc, ca = np.linalg.norm(a - b), np.linalg.norm(b - c), np.linalg.norm(c - a)
    area2 = abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    return float(ab * bc * ca / (2.0 * area2))


@pytest.mark.parametrize("v", [1.0, -0.7])
def test_ackermann_full_lock_circle_has_min_turning_radius(v):
    L, dmax = 0.3302, 0.4189
    kin = car()
    radius = L / math.tan(dmax)
    assert kin.limits().min_turning_radius == pytest.approx(radius, rel=1e-15)
    # a yaw-rate demand far beyond full lock steers to full lock
    dt = 0.01
    period = 2 * math.pi * radius / abs(v)
    steps = int(period / dt)
    state = KinematicState.at_rest([[0.0, 0.0, 0.0]])
    traj = []
    for _ in range(steps):
        state = kin.step(state, [[v, 0.0, 50.0 * np.sign(v)]], dt)
        traj.append(state.poses[0, :2].copy())
    traj = np.array(traj)
    assert state.steering[0] == dmax  # curvature omega/v > 0 in both directions: left lock
    k = len(traj)
    r = circumradius(traj[0], traj[k // 3], traj[2 * k // 3])
    assert r == pytest.approx(radius, abs=1e-9)
    # the rear axle stays on the circle about (0, R) through the start; the yaw rate is v/R
    centre = np.array([0.0, radius])
    np.testing.assert_allclose(np.linalg.norm(traj - centre, axis=1), radius, atol=1e-9)
    assert state.twists[0, 2] == pytest.approx(v / radius, rel=1e-12)
    # after one period minus a fraction of a step the car is back near the start
    rest = period - steps * dt
    back = kin.step(state, [[v, 0.0, 50.0 * np.sign(v)]], rest)
    np.testing.assert_allclose(back.poses[0], [0.0, 0.0, 0.0], atol=1e-9)


def test_ackermann_steering_rate_limit():
    kin = car(max_steering_rate=2.0)
    state = KinematicState.at_rest([[0.0, 0.0, 0.0]])
    angles = []
    for _ in range(6):
        state = kin.step(state, [[1.0, 0.0, 100.0]], 0.05)
        angles.append(state.steering[0])
        assert state.twists[0, 2] == pytest.approx(math.tan(state.steering[0]) / 0.3302)
    np.testing.assert_allclose(angles[:4], 0.1 * np.arange(1, 5), atol=1e-12)
    np.testing.assert_allclose(angles[4:], 0.4189, atol=0)


def test_ackermann_follows_feasible_curvature_forward_and_reverse():
    kin = car()
    state = KinematicState.at_rest(np.zeros((2, 3)))
    out = kin.step(state, [[1.0, 0.3, 0.5], [-1.0, 0.0, 0.5]], 0.1)
    np.testing.assert_allclose(out.twists[:, 2], [0.5, 0.5], atol=1e-12)
    np.testing.assert_allclose(out.twists[:, 1], 0.0)  # no side slip
    np.testing.assert_allclose(out.steering, [math.atan(0.3302 * 0.5), -math.atan(0.3302 * 0.5)])


def test_ackermann_behaviour_at_zero_speed():
    kin = car(max_steering_rate=1.0)
    held = KinematicState(np.zeros((3, 3)), np.zeros((3, 3)), np.array([0.2, 0.2, 0.2]))
    out = kin.step(held, [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0]], 0.1)
    # yaw demand at standstill steers toward full lock; no demand holds the wheels
    np.testing.assert_allclose(out.steering, [0.3, 0.2, 0.1], atol=1e-15)
    np.testing.assert_array_equal(out.poses, 0.0)  # a car cannot turn on the spot
    np.testing.assert_array_equal(out.twists, 0.0)


def test_ackermann_limits_and_params():
    kin = car(max_steering_rate=3.2, acc_x=2.5)
    lim = kin.limits()
    t = math.tan(0.4189)
    assert lim.omega_max == pytest.approx(5.0 * t / 0.3302)
    assert lim.acc_omega == pytest.approx((2.5 * t + 5.0 * 3.2 * (1 + t * t)) / 0.3302)
    assert not kin.holonomic and not lim.holonomic
    with pytest.raises(ConfigError, match="max_steering_angle"):
        car(max_steering_angle=math.pi / 2)


# -- legged ------------------------------------------------------------------------------------
def dog(**kw) -> Kinematics:
    params = dict(vx_min=-0.4, vx_max=0.8, vy_max=0.5, omega_max=1.2)
    return build("legged", **params | kw)


def test_legged_command_at_every_axis_max_is_scaled_onto_the_ellipsoid():
    kin = dog()
    out = kin.step(KinematicState.at_rest(np.zeros((1, 3))), [[0.8, 0.5, 1.2]], 0.1)
    np.testing.assert_allclose(out.twists[0], np.array([0.8, 0.5, 1.2]) / math.sqrt(3), atol=1e-15)


def test_legged_ellipsoid_is_asymmetric_in_vx_and_keeps_direction():
    kin = dog()
    cmds = np.array([
        [0.8, 0.0, 0.0],  # one axis alone reaches its limit
        [-0.4, 0.0, 0.0],
        [-2.0, 0.0, 0.0],
        [-0.4, 0.5, 0.0],  # backward uses |vx_min| as the semi-axis
        [0.2, 0.1, 0.3],  # inside: unchanged
    ])
    out = kin.step(KinematicState.at_rest(np.zeros((5, 3))), cmds, 0.1).twists
    np.testing.assert_allclose(out[0], [0.8, 0, 0], atol=1e-15)
    np.testing.assert_allclose(out[1], [-0.4, 0, 0], atol=1e-15)
    np.testing.assert_allclose(out[2], [-0.4, 0, 0], atol=1e-15)
    np.testing.assert_allclose(out[3], np.array([-0.4, 0.5, 0.0]) / math.sqrt(2), atol=1e-15)
    np.testing.assert_allclose(out[4], cmds[4], atol=0)


def test_legged_without_side_stepping_and_speed_cap():
    kin = dog(vy_max=0.0, max_speed=0.5)
    assert not kin.holonomic
    lim = kin.limits()
    assert (lim.vy_min, lim.vy_max, lim.acc_y, lim.vx_max) == (0.0, 0.0, 0.0, 0.5)
    cmds = [[0.8, 0.3, 0.0], [0.4, 0.0, 1.2]]
    out = kin.step(KinematicState.at_rest(np.zeros((2, 3))), cmds, 0.1)
    np.testing.assert_allclose(out.twists[0], [0.5, 0.0, 0.0], atol=1e-15)  # speed cap
    g = (out.twists[1, 0] / 0.8) ** 2 + (out.twists[1, 2] / 1.2) ** 2
    assert g == pytest.approx(1.0, abs=1e-12)
    assert out.twists[1, 2] / out.twists[1, 0] == pytest.approx(1.2 / 0.4)


def test_legged_acceleration_window_stops_on_the_ellipsoid():
    kin = dog(acc_x=HUGE, acc_y=HUGE, acc_omega=0.5)
    prev = KinematicState(np.zeros((2, 3)), np.array([[0.0, 0.0, 1.2], [0.0, 0.0, -1.2]]),
                          np.zeros(2))
    out = kin.step(prev, [[-0.4, 0.0, 0.0], [0.8, 0.0, 0.0]], 0.1)
    dv = out.twists - prev.twists
    assert np.all(np.abs(dv[:, 2]) <= 0.05 + 1e-12)
    w_back = np.array([1 / 0.4**2, 1 / 0.5**2, 1 / 1.2**2])
    w_fwd = np.array([1 / 0.8**2, 1 / 0.5**2, 1 / 1.2**2])
    assert np.sum(w_back * out.twists[0] ** 2) == pytest.approx(1.0, abs=1e-12)
    assert np.sum(w_fwd * out.twists[1] ** 2) == pytest.approx(1.0, abs=1e-12)
    assert out.twists[0, 0] < 0 < out.twists[1, 0]
    # backward, the semi-axis is |vx_min| = 0.4: s² + (1 - s/24)² = 1 gives s = 0.0832
    assert out.twists[0, 0] == pytest.approx(-0.4 * (1 / 12) / (1 + 1 / 576), rel=1e-12)


def test_legged_segment_crossing_vx_zero():
    # from forward to backward: the segment crosses vx = 0 and ends on the backward half
    kin = dog(acc_x=HUGE, acc_y=HUGE, acc_omega=0.3)
    prev = KinematicState(np.zeros((1, 3)), np.array([[0.6, 0.0, 0.79]]), np.zeros(1))
    out = kin.step(prev, [[-0.4, 0.0, 0.0]], 0.1)
    v = out.twists[0]
    assert v[0] < 0
    g = (v[0] / 0.4) ** 2 + (v[2] / 1.2) ** 2
    assert g == pytest.approx(1.0, abs=1e-12)
    assert abs(v[2] - 0.79) <= 0.03 + 1e-12


# -- every model ---------------------------------------------------------------------------------
def random_inputs(kind: str, n: int, rng: np.random.Generator):
    kin = build(kind, **SAMPLES[kind])
    lim = kin.limits()
    scale = np.array([max(-lim.vx_min, lim.vx_max), max(lim.vy_max, 1.0), lim.omega_max])
    poses = rng.uniform(-5, 5, (n, 3))
    state = KinematicState(poses, np.zeros((n, 3)), np.zeros(n))
    state = kin.step(state, rng.uniform(-1, 1, (n, 3)) * scale, 0.2)  # a valid moving state
    commands = rng.uniform(-3, 3, (n, 3)) * scale
    return kin, state, commands


@pytest.mark.parametrize("kind", sorted(SAMPLES))
def test_vectorised_equals_per_robot(kind):
    kin, state, commands = random_inputs(kind, 7, np.random.default_rng(1))
    together = kin.step(state, commands, 0.1)
    for i in range(len(state)):
        one = KinematicState(state.poses[i : i + 1], state.twists[i : i + 1],
                             state.steering[i : i + 1])
        alone = kin.step(one, commands[i : i + 1], 0.1)
        np.testing.assert_allclose(alone.poses[0], together.poses[i], atol=1e-14)
        np.testing.assert_allclose(alone.twists[0], together.twists[i], atol=1e-14)
        np.testing.assert_allclose(alone.steering[0], together.steering[i], atol=1e-14)


@pytest.mark.parametrize("kind", sorted(SAMPLES))
def test_inputs_are_never_mutated(kind):
    kin, state, commands = random_inputs(kind, 5, np.random.default_rng(2))
    copies = [a.copy() for a in (state.poses, state.twists, state.steering, commands)]
    for a in (state.poses, state.twists, state.steering, commands):
        a.flags.writeable = False  # a write attempt would raise
    out = kin.step(state, commands, 0.1)
    for a, b in zip((state.poses, state.twists, state.steering, commands), copies, strict=True):
        np.testing.assert_array_equal(a, b)
    assert not np.shares_memory(out.twists, state.twists)
    assert not np.shares_memory(out.poses, state.poses)


@pytest.mark.parametrize("kind", sorted(SAMPLES))
def test_bad_step_inputs_raise(kind):
    kin, state, commands = random_inputs(kind, 3, np.random.default_rng(3))
    with pytest.raises(SimulationError, match="dt"):
        kin.step(state, commands, 0.0)
    with pytest.raises(SimulationError, match="shape"):
        kin.step(state, commands[:2], 0.1)
    bad = commands.copy()
    bad[1, 2] = np.nan
    with pytest.raises(SimulationError, match=r"non-finite commands for robots \[1\]"):
        kin.step(state, bad, 0.1)


def kinds_to_check() -> list[str]:
    names = KINEMATICS.names()
    return [n for n in names if n in SAMPLES or "third_party" not in KINEMATICS.entry(n).tags]


@pytest.mark.parametrize("kind", kinds_to_check())
def test_conformance(kind):
    """Every registered model: contract, finite output, limits kept, deterministic, pure."""
    assert kind in SAMPLES, f"add sample params for the built-in kinematics {kind!r}"
    kin = build(kind, **SAMPLES[kind])
    assert isinstance(kin, Kinematics)
    assert kin.name == kind
    assert kin.holonomic == kin.limits().holonomic
    lim = kin.limits()
    lo, hi, acc = lim.lower - 1e-9, lim.upper + 1e-9, lim.acceleration
    rng = np.random.default_rng(42)
    scale = np.array([max(-lim.vx_min, lim.vx_max), max(lim.vy_max, 1.0), lim.omega_max])
    n = 16
    state = KinematicState.at_rest(rng.uniform(-5, 5, (n, 3)))
    for _ in range(60):
        dt = float(rng.uniform(0.01, 0.5))
        commands = rng.uniform(-3, 3, (n, 3)) * scale
        commands[rng.random(n) < 0.2] = 0.0  # stops too
        before = [a.copy() for a in (state.poses, state.twists, state.steering, commands)]
        out = kin.step(state, commands, dt)
        again = kin.step(state, commands, dt)
        after = (state.poses, state.twists, state.steering, commands)
        for a, b in zip(after, before, strict=True):
            np.testing.assert_array_equal(a, b)  # no mutation
        for a, b in zip((out.poses, out.twists, out.steering),
                        (again.poses, again.twists, again.steering), strict=True):
            np.testing.assert_array_equal(a, b)  # deterministic
        assert out.poses.shape == (n, 3) and out.twists.shape == (n, 3)
        assert out.steering.shape == (n,)
        assert np.all(np.isfinite(out.poses)) and np.all(np.isfinite(out.twists))
        assert np.all(np.isfinite(out.steering))
        assert np.all(out.twists >= lo) and np.all(out.twists <= hi), "velocity limits"
        dv = np.abs(out.twists - state.twists)
        assert np.all(dv <= acc * dt + 1e-9), "acceleration limits"
        assert np.all(np.abs(out.poses[:, 2]) <= np.pi)
        # the pose moves exactly by the executed twist held over dt
        np.testing.assert_allclose(out.poses, integrate_twist(state.poses, out.twists, dt),
                                   atol=1e-12)
        state = out


def test_round_limits_hold_under_random_commands():
    """The omni speed disc and the legged gait ellipsoid, with accelerations, over many steps."""
    rng = np.random.default_rng(7)
    omni = build("omni", **SAMPLES["omni"])
    legged = build("legged", **SAMPLES["legged"])
    n = 32
    so = sl = KinematicState.at_rest(np.zeros((n, 3)))
    p = SAMPLES["legged"]
    for _ in range(200):
        dt = float(rng.uniform(0.02, 0.3))
        cmd = rng.uniform(-2, 2, (n, 3))
        new_o, new_l = omni.step(so, cmd, dt), legged.step(sl, cmd, dt)
        assert np.all(np.hypot(new_o.twists[:, 0], new_o.twists[:, 1]) <= 1.0 + 1e-9)
        lim_x = np.where(new_l.twists[:, 0] >= 0, p["vx_max"], -p["vx_min"])
        g = ((new_l.twists[:, 0] / lim_x) ** 2 + (new_l.twists[:, 1] / p["vy_max"]) ** 2
             + (new_l.twists[:, 2] / p["omega_max"]) ** 2)
        assert np.all(g <= 1.0 + 1e-9)
        assert np.all(np.hypot(new_l.twists[:, 0], new_l.twists[:, 1]) <= p["max_speed"] + 1e-9)
        for kin, old, new in ((omni, so, new_o), (legged, sl, new_l)):
            assert np.all(np.abs(new.twists - old.twists) <= kin.limits().acceleration * dt + 1e-9)
        so, sl = new_o, new_l


@pytest.mark.parametrize("kind", ["diff_drive", "omni"])
def test_box_step_rows_matches_step_bitwise(kind):
    """The simulator's in-place row stepping gives the bits of ``Kinematics.step``."""
    from arena.robots.kinematics.base import box_step_rows

    params = dict(SAMPLES[kind])
    params.pop("speed_max", None)  # the box pipeline only: no speed disc
    kin = build(kind, **params)
    box = kin.box_limits
    assert box is not None
    rng = np.random.default_rng(0)
    n = 4
    poses = rng.normal(size=(n, 3)) * [5.0, 5.0, 3.0]
    twists = rng.normal(size=(n, 3))
    cmd = rng.normal(size=(n, 3)) * 2.0
    cmd[0, 2] = 1e-7  # the series branch of the arc integration
    for dt in (0.01, 0.1, 0.5):
        ref = kin.step(KinematicState(poses, twists, np.zeros(n)), cmd, dt)
        out_p, out_t = np.empty((n, 3)), np.empty((n, 3))
        for i in range(n):  # one row per call, as a simulator with one robot of this model
            box_step_rows(poses, twists, cmd, *box, dt, np.array([i]), out_p, out_t, np.empty(n))
        assert out_p.tobytes() == ref.poses.tobytes()
        assert out_t.tobytes() == ref.twists.tobytes()


def test_box_limits_absent_with_a_speed_disc():
    assert build("omni", **SAMPLES["omni"]).box_limits is None
