"""iPlanner training: geometry, the SDF cost, data shapes, numpy = torch, the loss decreasing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.learn.iplanner.data import (
    DataParams,
    Dataset,
    MapStack,
    sample_goals,
    signed_distance,
    to_world,
)
from arena.learn.iplanner.geometry import (
    CAMERA,
    INPUT_SHAPE,
    MAX_DEPTH,
    CostParams,
    arc_length,
    depth_input,
    horizontal_fov,
    obstacle_cost,
    spline_matrix,
    trajectory,
)
from arena.learn.iplanner.network import layer_shapes, load_net, save_net
from arena.maps.grid import OccupancyGrid


def _corridor() -> OccupancyGrid:
    """6 × 4 m, 5 cm cells: border walls and a wall across x ∈ [3, 3.2], y < 2.5."""
    occ = np.zeros((80, 120), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[:50, 60:64] = True
    return OccupancyGrid.from_occupied(occ, 0.05)


def _synthetic(n: int, rng: np.random.Generator) -> Dataset:
    """Images of the corridor map: noise-free fake depth (no renderer needed)."""
    grid = _corridor()
    sdf = signed_distance(grid)
    pose = np.column_stack([rng.uniform(0.5, 2.5, n), rng.uniform(0.5, 3.5, n),
                            rng.uniform(-0.5, 0.5, n)])
    depth = rng.uniform(0.2, 1.0, (n, *INPUT_SHAPE)).astype(np.float16)
    return Dataset(depth, pose, np.zeros(n, dtype=np.int64), MapStack.from_grids([sdf], [grid]))


# -- geometry ----------------------------------------------------------------------------------


def test_spline_passes_through_the_origin_and_every_waypoint() -> None:
    wp = np.array([[0.5, 0.2], [1.0, 0.6], [1.8, 0.5], [2.4, -0.1], [3.0, 0.0]])
    traj = trajectory(wp)
    assert traj.shape == (51, 2)
    np.testing.assert_allclose(traj[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(traj[10::10], wp, atol=1e-12)
    assert np.allclose(spline_matrix().sum(axis=1), 1.0)  # affine: moves with the points
    # a straight line is sampled evenly along itself
    line = trajectory(np.outer(np.arange(1, 6), [0.6, 0.0]))
    np.testing.assert_allclose(arc_length(line)[-1], 3.0, atol=1e-9)


def test_depth_input_normalises_and_subsamples() -> None:
    depth = np.full((96, 160), 3.0, dtype=np.float32)
    depth[:, :80] = 0.0  # no return: as far as the network looks
    depth[0, 100] = 50.0
    x = depth_input(depth)
    assert x.shape == (1, *INPUT_SHAPE) and x.dtype == np.float32
    assert np.all(x[0, :, :40] == 1.0)
    np.testing.assert_allclose(x[0, :, 40:], 3.0 / MAX_DEPTH)
    with pytest.raises(ValueError, match="whole multiple"):
        depth_input(np.ones((50, 80)))


def test_camera_is_wide() -> None:
    assert math.degrees(horizontal_fov()) == pytest.approx(87.8, abs=0.1)
    assert CAMERA.width / CAMERA.height == INPUT_SHAPE[1] / INPUT_SHAPE[0]


def test_signed_distance_is_negative_inside_walls_and_bilinear_between_centres() -> None:
    grid = _corridor()
    sdf = signed_distance(grid)
    assert sdf[40, 61] < 0 < sdf[40, 40]
    assert sdf[40, 40] == pytest.approx(20 * 0.05 - 0.025)  # 20 cells left of the wall
    maps = MapStack.from_grids([sdf], [grid])
    centre = np.array([[[(40 + 0.5) * 0.05, (40 + 0.5) * 0.05]]])
    assert maps.distance(np.array([0]), centre)[0, 0] == pytest.approx(sdf[40, 40])
    between = centre + np.array([0.025, 0.0])
    assert maps.distance(np.array([0]), between)[0, 0] == pytest.approx(
        0.5 * (sdf[40, 40] + sdf[40, 41]))


def test_obstacle_cost_is_one_at_contact_and_zero_beyond_the_safe_distance() -> None:
    p = CostParams()
    assert obstacle_cost(p.robot_radius, p) == pytest.approx(1.0)
    assert obstacle_cost(p.safe_distance + 0.01, p) == 0.0
    assert obstacle_cost(0.0, p) > obstacle_cost(0.2, p) > obstacle_cost(0.4, p)


def test_goals_keep_their_clearance_and_ranges() -> None:
    rng = np.random.default_rng(0)
    data = _synthetic(200, rng)
    params = DataParams()
    rows = np.arange(200)
    goals = sample_goals(data, rows, params, rng)
    r, b = np.hypot(*goals.T), np.arctan2(goals[:, 1], goals[:, 0])
    assert np.all((r >= params.goal_min) & (r <= params.goal_max))
    assert np.all(np.abs(b) <= params.goal_bearing)
    d = data.maps.distance(data.map_index, to_world(goals[:, None], data.pose))[:, 0]
    assert np.mean(d >= params.goal_clearance) > 0.9


# -- the file ----------------------------------------------------------------------------------


def test_network_file_round_trip_and_bad_files(tmp_path) -> None:
    rng = np.random.default_rng(1)
    weights = {k: rng.normal(0, 0.1, s).astype(np.float32) for k, s in layer_shapes().items()}
    path = save_net(tmp_path / "p.npz", weights, {"waypoints": 5})
    net = load_net(path)
    plan = net.plan(depth_input(np.full(INPUT_SHAPE, 2.0)), np.array([2.0, 0.5]))
    assert plan.waypoints.shape == (5, 2) and 0.0 <= plan.fear <= 1.0
    with pytest.raises(ConfigError, match="train one with"):
        load_net(tmp_path / "missing.npz")
    del weights["fc_w"]
    with pytest.raises(ConfigError, match="fc_w"):
        load_net(save_net(tmp_path / "q.npz", weights, {"waypoints": 5}))


# -- torch -------------------------------------------------------------------------------------


def test_numpy_forward_equals_torch_forward(tmp_path) -> None:
    torch = pytest.importorskip("torch")
    from arena.learn.iplanner.torch_net import TorchIPlanner

    torch.manual_seed(0)
    tnet = TorchIPlanner()
    rng = np.random.default_rng(2)
    depth = rng.uniform(0, 1, (3, 1, *INPUT_SHAPE)).astype(np.float32)
    goal = rng.uniform(-3, 3, (3, 2)).astype(np.float32)
    with torch.no_grad():
        wp, logit = tnet(torch.from_numpy(depth), torch.from_numpy(goal))
    net = load_net(save_net(tmp_path / "p.npz", tnet.export(), {"waypoints": 5}))
    for i in range(3):
        plan = net.plan(depth[i], goal[i])
        np.testing.assert_allclose(plan.waypoints, wp[i].numpy(), atol=1e-4)
        assert plan.fear == pytest.approx(float(torch.sigmoid(logit[i])), abs=1e-5)


def test_sdf_cost_is_differentiable_and_lower_away_from_walls() -> None:
    torch = pytest.importorskip("torch")
    from arena.learn.iplanner.loss import LossWeights, TrajectoryCost

    grid = _corridor()
    maps = MapStack.from_grids([signed_distance(grid)], [grid])
    cost = TrajectoryCost(maps, CostParams(), LossWeights(), 5)
    pose = torch.tensor([[0.5, 3.4, 0.0]])  # 0.55 m below the top wall (y = 3.95)
    near = torch.tensor([[[0.5 * k, 0.3] for k in range(1, 6)]], requires_grad=True)  # 0.25 m
    far = torch.tensor([[[0.5 * k, -0.6] for k in range(1, 6)]], requires_grad=True)  # 1.15 m
    c_near = cost.obstacle_cost(cost.distance(torch.tensor([0]), pose,
                                              cost.trajectory(near))).mean()
    c_far = cost.obstacle_cost(cost.distance(torch.tensor([0]), pose,
                                             cost.trajectory(far))).mean()
    assert float(c_far.detach()) < float(c_near.detach())
    c_near.backward()
    assert near.grad is not None and torch.all(torch.isfinite(near.grad))
    # descending the gradient moves the waypoints away from the wall above (-y)
    assert float(near.grad[0, :, 1].sum()) > 0


def test_loss_decreases_on_a_tiny_training_run() -> None:
    torch = pytest.importorskip("torch")
    torch.set_num_threads(1)
    from arena.learn.iplanner.loss import LossWeights, TrajectoryCost
    from arena.learn.iplanner.torch_net import TorchIPlanner
    from arena.learn.iplanner.train import fit

    rng = np.random.default_rng(3)
    data = _synthetic(256, rng)
    params = DataParams()
    goals = sample_goals(data, np.arange(256), params, np.random.default_rng(9))

    def loss_of(net: TorchIPlanner) -> float:
        cost = TrajectoryCost(data.maps, CostParams(), LossWeights(), 5)
        with torch.no_grad():
            wp, logit = net(torch.from_numpy(data.depth.astype(np.float32))[:, None],
                            torch.from_numpy(goals.astype(np.float32)))
            return float(cost(wp, logit, torch.from_numpy(goals.astype(np.float32)),
                              torch.from_numpy(data.map_index),
                              torch.from_numpy(data.pose.astype(np.float32))).total)

    torch.manual_seed(4)
    before = loss_of(TorchIPlanner())
    net = fit(data, params, epochs=6, batch=64, lr=2e-3, seed=4)
    assert loss_of(net) < 0.8 * before
