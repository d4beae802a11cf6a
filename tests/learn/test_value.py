"""The value-policy core (arena.learn.value): rotation, action sets, lookahead, networks, files."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.learn.value import (
    build_action_set,
    joint_state,
    load_value_policy,
    lookahead,
    rotate,
    save_value_policy,
)
from arena.learn.value.network import random_network
from arena.learn.value.state import PHANTOM_DISTANCE


def test_rotate_by_hand():
    # Robot at (1, 1) heading +y toward a goal 3 m up: the goal frame's x is world +y.
    robot = np.array([1.0, 1.0, 0.0, 1.0, 0.25, 1.0, 4.0, 1.5, math.pi / 2])
    # A human 1 m to the robot's right (world +x) walking toward world -x.
    humans = np.array([[2.0, 1.0, -1.0, 0.0, 0.3]])
    f = rotate(robot, humans, holonomic=False)
    assert f.shape == (1, 13)
    expect = [3.0, 1.5, 0.0, 0.25, 1.0, 0.0,  # dg, v_pref, theta', radius, vx', vy'
              0.0, -1.0, 0.0, 1.0, 0.3, 1.0, 0.55]  # px1', py1', vx1', vy1', r1, da, r_sum
    np.testing.assert_allclose(f[0], expect, atol=1e-12)
    # Holonomic robots carry no heading; a heading off the goal direction shows up wrapped.
    assert rotate(robot, humans, holonomic=True)[0, 2] == 0.0
    robot[8] = -math.pi  # facing -x: goal is π/2 to its left... theta' = -π - π/2 → π/2
    assert rotate(robot, humans, holonomic=False)[0, 2] == pytest.approx(math.pi / 2)


def test_rotate_broadcasts_over_actions():
    rng = np.random.default_rng(0)
    robots = rng.normal(size=(7, 9))
    humans = rng.normal(size=(3, 5))
    f = rotate(robots, humans, holonomic=False)
    assert f.shape == (7, 3, 13)
    np.testing.assert_allclose(f[4], rotate(robots[4], humans, holonomic=False))


def _scene_transform(robot, humans, angle, shift):
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    r = robot.copy()
    r[0:2] = rot @ robot[0:2] + shift
    r[2:4] = rot @ robot[2:4]
    r[5:7] = rot @ robot[5:7] + shift
    r[8] = robot[8] + angle
    h = humans.copy()
    h[:, 0:2] = humans[:, 0:2] @ rot.T + shift
    h[:, 2:4] = humans[:, 2:4] @ rot.T
    return r, h


@pytest.mark.parametrize("kind", ["cadrl", "sarl"])
def test_value_invariant_to_global_rotation_and_translation(kind):
    rng = np.random.default_rng(1)
    net = random_network(kind, rng)
    robot = np.array([0.5, -1.0, 0.3, 0.4, 0.27, 3.0, 2.0, 2.0, 0.7])
    humans = np.column_stack([rng.uniform(-3, 3, (4, 2)), rng.normal(size=(4, 2)),
                              np.full(4, 0.3)])
    f0 = rotate(robot, humans, holonomic=False)[None]
    r1, h1 = _scene_transform(robot, humans, 2.1, np.array([-4.0, 7.5]))
    f1 = rotate(r1, h1, holonomic=False)[None]
    np.testing.assert_allclose(f0, f1, atol=1e-9)
    np.testing.assert_allclose(net.value(f0), net.value(f1), atol=1e-9)
    # The whole lookahead (rewards and next values) is invariant too.
    from arena.learn.value.state import JointState

    acts = build_action_set(2.0, False, 0.25)
    wall0 = np.array([[1.2, -1.0 + y] for y in np.linspace(-1, 1, 21)])
    wall1 = wall0 @ np.array([[math.cos(2.1), math.sin(2.1)], [-math.sin(2.1), math.cos(2.1)]])
    wall1 = wall1 + np.array([-4.0, 7.5])
    la0 = lookahead(JointState(robot, humans), acts, wall0)
    la1 = lookahead(JointState(r1, h1), acts, wall1)
    np.testing.assert_allclose(la0.rewards, la1.rewards, atol=1e-9)
    np.testing.assert_array_equal(la0.pruned, la1.pruned)
    v0 = net.value(rotate(la0.next_robot, la0.next_humans, False))
    v1 = net.value(rotate(la1.next_robot, la1.next_humans, False))
    np.testing.assert_allclose(v0, v1, atol=1e-9)


def test_joint_state_selects_nearest_and_adds_a_phantom():
    peds = np.array([[5.0, 0.0, 0, 0], [1.0, 0.0, 0, 0], [20.0, 0.0, 0, 0], [2.0, 0.0, 1, 0]])
    s = joint_state(np.zeros(3), np.zeros(2), 0.3, np.array([3.0, 0.0]), 1.0, peds,
                    0.3, 6.0, 2)
    np.testing.assert_allclose(s.humans[:, 0], [1.0, 2.0])
    assert np.all(s.humans[:, 4] == 0.3)
    none = joint_state(np.zeros(3), np.zeros(2), 0.3, np.array([0.0, 3.0]), 1.0,
                       np.zeros((0, 4)), 0.3, 6.0, 10)
    np.testing.assert_allclose(none.humans[0, :4], [0.0, -PHANTOM_DISTANCE, 0.0, 0.0])


def test_action_sets():
    holo = build_action_set(1.0, True, 0.25)
    uni = build_action_set(1.0, False, 0.25)
    # 16 rotations in ±π/4 include no 0 (as in CrowdNav); all 16 also turn on the spot.
    assert len(holo) == 81 and len(uni) == 81 + 16
    assert holo.speeds[0] == 0 and uni.speeds[0] == 0
    np.testing.assert_allclose(np.unique(holo.speeds)[1:],
                               (np.exp(np.arange(1, 6) / 5) - 1) / (math.e - 1))
    assert np.max(np.abs(uni.angles)) == pytest.approx(math.pi / 4)
    # A unicycle action follows the arc of its twist [v, 0, r / Δt].
    poses, vel = uni.propagate(np.array([0.0, 0.0, 0.0]))
    k = int(np.flatnonzero((uni.speeds == 1.0) & np.isclose(uni.angles, math.pi / 4))[0])
    w = (math.pi / 4) / 0.25
    np.testing.assert_allclose(poses[k, -1], [math.sin(math.pi / 4) / w,
                                              (1 - math.cos(math.pi / 4)) / w, math.pi / 4])
    np.testing.assert_allclose(vel[k], [math.cos(math.pi / 4), math.sin(math.pi / 4)])
    np.testing.assert_allclose(uni.twists()[k], [1.0, 0.0, w])


def test_lookahead_prunes_actions_into_a_wall():
    from arena.learn.value.state import JointState

    acts = build_action_set(2.0, False, 0.25)
    robot = np.array([0.0, 0.0, 0.0, 0.0, 0.3, 5.0, 0.0, 2.0, 0.0])
    humans = np.array([[0.0, -PHANTOM_DISTANCE, 0.0, 0.0, 0.3]])
    wall = np.array([[0.6, y] for y in np.linspace(-3, 3, 121)])  # a wall 0.3 m ahead
    la = lookahead(JointState(robot, humans), acts, wall)
    ahead = la.next_robot[:, 0] + 0.3 + 0.05 > 0.6
    assert np.all(la.pruned[ahead & (acts.speeds > 0)])
    assert not la.pruned[0]  # stop is always allowed
    assert not np.any(la.pruned[acts.speeds == 0])  # turning on the spot keeps the clearance
    # A robot already grazing the wall may still back... turn away: moves that open the gap.
    close = np.array([[0.32, y] for y in np.linspace(-3, 3, 121)])
    la2 = lookahead(JointState(robot, humans), build_action_set(2.0, True, 0.25), close)
    backwards = la2.next_robot[:, 0] < -1e-6
    assert not np.any(la2.pruned[backwards])
    assert np.all(la2.pruned[la2.next_robot[:, 0] > 1e-6])
    # Without laser returns nothing is pruned.
    assert not lookahead(JointState(robot, humans), acts, np.zeros((0, 2))).pruned.any()


def test_lookahead_rewards_collision_goal_and_discomfort():
    from arena.learn.value.state import JointState

    acts = build_action_set(1.0, True, 0.25)
    robot = np.array([0.0, 0.0, 0.0, 0.0, 0.3, 0.2, 0.0, 1.0, 0.0])  # goal 0.2 m ahead
    humans = np.array([[0.0, -PHANTOM_DISTANCE, 0.0, 0.0, 0.3]])
    la = lookahead(JointState(robot, humans), acts, np.zeros((0, 2)))
    assert la.rewards[0] == 1.0  # stopping within its radius of the goal reaches it
    crowd = np.array([[1.0, 0.0, -2.0, 0.0, 0.3]])  # walks into the robot
    la = lookahead(JointState(robot, crowd), acts, np.zeros((0, 2)))
    assert la.rewards[0] == -0.25
    far = np.array([[0.0, 0.75, 0.0, 0.0, 0.3]])  # 0.15 m gap: discomfort
    la = lookahead(JointState(robot, far), acts, np.zeros((0, 2)))
    assert la.rewards[0] == pytest.approx(1.0)  # goal wins over discomfort, as in CrowdNav
    robot[5] = 5.0
    la = lookahead(JointState(robot, far), acts, np.zeros((0, 2)))
    assert la.rewards[0] == pytest.approx((0.15 - 0.2) * 0.5 * 0.25)


@pytest.mark.parametrize("kind", ["cadrl", "sarl"])
def test_numpy_network_equals_torch(kind):
    torch = pytest.importorskip("torch")
    from arena.learn.value.train import to_numpy, torch_network

    torch.manual_seed(3)
    model = torch_network(kind)
    net = to_numpy(model)
    rng = np.random.default_rng(2)
    x = rng.normal(size=(6, 5, 13)).astype(np.float32)
    mask = rng.random((6, 5)) < 0.7
    mask[:, 0] = True
    with torch.no_grad():
        want = model(torch.from_numpy(x), torch.from_numpy(mask)).double().numpy()
    np.testing.assert_allclose(net.value(x.astype(np.float64), mask), want, rtol=1e-5,
                               atol=1e-5)
    # Padding is ignored: the unpadded rows give the same values.
    for b in range(6):
        alone = net.value(x[b:b + 1, mask[b]].astype(np.float64))
        np.testing.assert_allclose(alone, want[b:b + 1], rtol=1e-5, atol=1e-5)


def test_policy_file_round_trip_and_errors(tmp_path):
    net = random_network("sarl", np.random.default_rng(0))
    meta = {"gamma": 0.9, "time_step": 0.25, "v_pref": 2.0, "kinematics": "unicycle",
            "human_radius": 0.3}
    path = save_value_policy(tmp_path / "p.npz", net, meta)
    assert path.stat().st_size < 1_000_000
    back = load_value_policy(path)
    assert back.meta["policy"] == "sarl" and back.meta["gamma"] == 0.9
    x = np.random.default_rng(1).normal(size=(3, 4, 13))
    np.testing.assert_allclose(back.network.value(x), net.value(x), rtol=1e-4, atol=1e-5)

    with pytest.raises(ConfigError, match=r"missing\.npz"):
        load_value_policy(tmp_path / "missing.npz")
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip")
    with pytest.raises(ConfigError, match=r"junk\.npz.*readable"):
        load_value_policy(junk, where="navigation.local_planner.weights")
    data = dict(np.load(path))
    bad = tmp_path / "bad.npz"
    np.savez(bad, **{**data, "value.0.weight": np.zeros((3, 3), np.float32)})
    with pytest.raises(ConfigError, match=r"bad\.npz.*value\.0"):
        load_value_policy(bad)
    other = json.loads(str(data["meta"]))
    other["format"] = "something else"
    wrong = tmp_path / "wrong.npz"
    np.savez(wrong, **{**data, "meta": np.array(json.dumps(other))})
    with pytest.raises(ConfigError, match=r"wrong\.npz.*format"):
        load_value_policy(wrong)
