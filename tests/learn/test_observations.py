"""Observation construction for N worlds."""

import dataclasses
import math

import numpy as np
import pytest

from arena.learn.config import ObservationConfig
from arena.learn.observations import ObservationBuilder, ObsInput, goal_polar
from tests.learn.helpers import small_robot


def make_input(poses, peds=(), vels=None, kinds=None, states=None, beams=24, stack=1):
    poses = np.asarray(poses, float).reshape(-1, 3)
    n = len(poses)
    p = np.asarray(peds, float).reshape(n, -1, 2)
    m = p.shape[1]
    return ObsInput(
        poses=poses, twists=np.zeros((n, 3)), goals=np.zeros((n, 2)),
        scans=np.full((n, stack, beams), 5.0), last_action=np.zeros((n, 3)),
        ped_pos=p, ped_vel=np.zeros((n, m, 2)) if vels is None else np.asarray(vels, float),
        ped_kind=np.zeros((n, m), np.int64) if kinds is None else np.asarray(kinds),
        ped_state=np.zeros((n, m), np.int64) if states is None else np.asarray(states),
        ped_mask=np.ones((n, m), bool),
    )


def test_one_world_goal_matches_the_batched_rows_bit_for_bit():
    """The scalar goal path of ``build`` for N = 1 gives each row of the batched path."""
    rng = np.random.default_rng(0)
    b = ObservationBuilder(ObservationConfig(goal_max_distance=4.0), small_robot())
    n = 400
    poses = np.column_stack([rng.normal(size=(n, 2)) * 3, rng.uniform(-7, 7, n)])
    poses[:20, :2] = 0.0  # goal under the robot: ρ = 0, θ from atan2(±0, ±0)
    poses[20:40, 2] = np.pi * rng.choice([-3, -1, 0, 1, 2], 20)
    goals = np.where(rng.random((n, 2)) < 0.1, 0.0, rng.normal(size=(n, 2)) * 3)
    inp = dataclasses.replace(make_input(poses), goals=goals)
    batched = b.build(inp)["goal"]
    for i in range(n):
        one = dataclasses.replace(make_input(poses[i]), goals=goals[i : i + 1])
        got = b.build(one)["goal"]
        assert got.dtype == np.float32 and got.shape == (1, 2)
        assert got.tobytes() == batched[i : i + 1].tobytes(), i


def test_one_world_clipped_commands_match_the_batched_rows_bit_for_bit():
    """``last_action`` and ``velocity`` for N = 1 (Python clip) equal the batched numpy clip,
    signed zeros, NaN, infinities and the bounds themselves included."""
    b = ObservationBuilder(ObservationConfig(velocity=True), small_robot())
    lo, hi = b._action_bounds
    special = [0.0, -0.0, math.nan, math.inf, -math.inf, *lo.tolist(), *hi.tolist()]
    rng = np.random.default_rng(1)
    n = 300
    vals = np.where(
        rng.random((2, n, 3)) < 0.4, rng.choice(special, (2, n, 3)), rng.normal(size=(2, n, 3))
    )
    inp = dataclasses.replace(
        make_input(np.zeros((n, 3))), last_action=vals[0], twists=vals[1]
    )
    batched = b.build(inp)
    for i in range(n):
        one = dataclasses.replace(
            make_input(np.zeros(3)), last_action=vals[0, i : i + 1], twists=vals[1, i : i + 1]
        )
        got = b.build(one)
        for key in ("last_action", "velocity"):
            assert got[key].dtype == np.float32 and got[key].shape == (1, 3)
            assert got[key].tobytes() == batched[key][i : i + 1].tobytes(), (key, i)


def test_goal_angle_is_zero_straight_ahead():
    poses = np.array([[0, 0, 0], [0, 0, math.pi / 2], [1, 1, 0], [0, 0, 0]], float)
    goals = np.array([[2, 0], [0, 3], [1, 2], [-1, 0]], float)
    rho, theta = goal_polar(poses, goals).T
    np.testing.assert_allclose(rho, [2, 3, 1, 1])
    np.testing.assert_allclose(theta[:3], [0, 0, math.pi / 2], atol=1e-12)
    assert abs(abs(theta[3]) - math.pi) < 1e-12


def test_pedestrians_nearest_first_in_robot_frame_with_mask():
    cfg = ObservationConfig(pedestrians={"enabled": True, "k": 3, "max_range": 4.0})
    b = ObservationBuilder(cfg, small_robot())
    # robot at the origin facing +y; people at world (0, 2) ahead, (-1, 0) left, (5, 5) far
    inp = make_input(
        [[0, 0, math.pi / 2]], peds=[[[0, 2], [-1, 0], [5, 5]]],
        vels=[[[0, -1], [0, 0], [0, 0]]], kinds=[[1, 0, 0]], states=[[2, 0, 0]],
    )
    obs = b.build(inp)
    f, mask = obs["pedestrians"][0], obs["pedestrians_mask"][0]
    np.testing.assert_array_equal(mask, [1, 1, 0])
    np.testing.assert_allclose(f[0], [0, 1, 0, 0, 0, 0], atol=1e-6)  # nearest: left, y = +1
    np.testing.assert_allclose(f[1], [2, 0, -1, 0, 1, 2], atol=1e-6)
    np.testing.assert_array_equal(f[2], 0)
    assert b.space.contains({k: v[0] for k, v in obs.items()})


def test_semantic_cells_and_channels():
    cfg = ObservationConfig(
        semantic={"enabled": True, "size": 10, "roi": 10.0,
                  "channels": ["pedestrian_location", "pedestrian_type", "pedestrian_vel_x"]},
    )
    b = ObservationBuilder(cfg, small_robot())
    inp = make_input([[0, 0, 0], [0, 0, math.pi]], peds=[[[2.5, 0.5]], [[2.5, 0.5]]],
                     vels=[[[1.0, 0.0]], [[1.0, 0.0]]], kinds=[[1], [1]])
    sem = b.build(inp)["semantic"]
    assert sem.shape == (2, 3, 10, 10)
    # world 0: robot frame (2.5, 0.5) → col 2 + 5 = 7, row 0 + 5 = 5
    np.testing.assert_allclose(sem[0, :, 5, 7], [1, 1, 1])
    assert sem[0].sum() == 3
    # world 1 faces −x: the person is behind at (−2.5, −0.5) → col 2, row 4; vx = −1
    np.testing.assert_allclose(sem[1, :, 4, 2], [1, 1, -1], atol=1e-6)


@pytest.mark.parametrize("flatten", [False, True])
def test_space_matches_observation(flatten):
    cfg = ObservationConfig(laser_stack=3, flatten=flatten, pedestrians={"enabled": True, "k": 2},
                            semantic={"enabled": True, "size": 8})
    b = ObservationBuilder(cfg, small_robot())
    obs = b.build(make_input([[0, 0, 0]], peds=[[[1, 1]]], stack=3))
    assert b.space.contains(b.single(obs))
    if flatten:
        assert b.flatten(obs).shape == (1, b.space.shape[0])
