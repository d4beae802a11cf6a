"""Costmap layers: inflation formula, obstacle marking/clearing, rolling window, semantic layer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.types import Pose2D
from arena.maps.grid import UNKNOWN, OccupancyGrid
from arena.nav.costmap import (
    FREE_SPACE,
    INSCRIBED,
    LETHAL,
    NO_INFORMATION,
    Costmap,
    CostmapParams,
    GlobalCostmap,
    LocalCostmap,
    inflate,
    inflation_cost,
    social_costs,
    static_costs,
    update_obstacles,
)
from arena.nav.global_planners import GLOBAL_PLANNERS

RES = 0.05


def _ros_cost(d: float, inscribed: float, inflation: float, k: float) -> int:
    """costmap_2d InflationLayer::computeCost, written out independently."""
    if d == 0.0:
        return 254
    if d <= inscribed:
        return 253
    if d > inflation:
        return 0
    return int(252 * math.exp(-k * (d - inscribed)))


def test_inflation_cost_matches_formula_at_known_distances() -> None:
    inscribed, inflation, k = 0.3, 1.0, 3.0
    ds = np.array([0.0, 0.05, 0.3, 0.3001, 0.35, 0.5, 0.7, 0.99, 1.0, 1.05, 3.0])
    got = inflation_cost(ds, inscribed, inflation, k)
    want = [_ros_cost(float(d), inscribed, inflation, k) for d in ds]
    np.testing.assert_array_equal(got, want)


def test_inflate_raster_against_formula() -> None:
    costs = np.zeros((41, 41), dtype=np.uint8)
    costs[20, 20] = LETHAL
    inscribed, inflation, k = 0.2, 0.8, 5.0
    out = inflate(costs, RES, inscribed_radius=inscribed, inflation_radius=inflation,
                  cost_scaling_factor=k)
    rr, cc = np.mgrid[0:41, 0:41]
    d = np.hypot(rr - 20, cc - 20) * RES
    want = np.vectorize(lambda x: _ros_cost(float(x), inscribed, inflation, k))(d)
    np.testing.assert_array_equal(out, want)
    assert out[20, 20] == LETHAL
    assert out[20, 24] == INSCRIBED  # 0.2 m
    assert out[20, 30] == int(252 * math.exp(-k * (0.5 - inscribed)))


def test_inflation_keeps_unknown_unless_inscribed() -> None:
    costs = np.full((21, 21), NO_INFORMATION, dtype=np.uint8)
    costs[10, 10] = LETHAL
    out = inflate(costs, RES, inscribed_radius=0.1, inflation_radius=0.5, cost_scaling_factor=5.0)
    assert out[10, 11] == INSCRIBED
    assert out[10, 15] == NO_INFORMATION  # low inflation cost does not overwrite unknown
    out2 = inflate(costs, RES, inscribed_radius=0.1, inflation_radius=0.5,
                   cost_scaling_factor=5.0, inflate_unknown=True)
    assert 0 < out2[10, 15] < INSCRIBED


def test_static_layer_values() -> None:
    data = np.zeros((3, 3), dtype=np.int8)
    data[0, 0] = 100
    data[1, 1] = UNKNOWN
    grid = OccupancyGrid(data, RES)
    np.testing.assert_array_equal(
        static_costs(grid), [[LETHAL, 0, 0], [0, 0, 0], [0, 0, 0]]
    )
    assert static_costs(grid, track_unknown=True)[1, 1] == NO_INFORMATION


def test_costmap_geometry_helpers() -> None:
    cm = Costmap(np.zeros((10, 20), dtype=np.uint8), 0.1, (1.0, -2.0))
    cm.costs[3, 7] = 99
    np.testing.assert_array_equal(cm.world_to_cell([1.75, -1.65]), [3, 7])
    np.testing.assert_allclose(cm.cell_to_world([3, 7]), [1.75, -1.65])
    assert cm.cost_at([1.75, -1.65]) == 99
    assert cm.cost_at([0.0, 0.0]) == NO_INFORMATION
    assert cm.bounds == pytest.approx((1.0, -2.0, 3.0, -1.0))
    occ = cm.to_occupancy(99)
    assert occ.occupied[3, 7] and occ.occupied.sum() == 1


def _obstacle_layer() -> Costmap:
    return Costmap(np.zeros((100, 100), dtype=np.uint8), RES, (0.0, 0.0))


def test_obstacle_layer_marks_return_and_clears_between() -> None:
    layer = _obstacle_layer()
    layer.costs[50, 20:40] = LETHAL  # stale marks along the beam
    update_obstacles(layer, [0.5 + 0.025, 2.5 + 0.025], [0.0], [2.0],
                     obstacle_range=2.5, raytrace_range=3.0)
    hit = layer.world_to_cell([2.525, 2.525])
    assert layer.costs[hit[0], hit[1]] == LETHAL
    assert (layer.costs[50, 10:50] == FREE_SPACE).all()
    assert layer.costs.sum() == LETHAL  # only the return is marked


def test_moved_obstacle_disappears() -> None:
    layer = _obstacle_layer()
    sensor = [1.025, 2.525]
    update_obstacles(layer, sensor, [0.0], [1.0], obstacle_range=2.5, raytrace_range=3.0)
    old = layer.world_to_cell([2.025, 2.525])
    assert layer.costs[old[0], old[1]] == LETHAL
    # The obstacle moved 1 m further away: the old mark is cleared, the new one set.
    update_obstacles(layer, sensor, [0.0], [2.0], obstacle_range=2.5, raytrace_range=3.0)
    new = layer.world_to_cell([3.025, 2.525])
    assert layer.costs[old[0], old[1]] == FREE_SPACE
    assert layer.costs[new[0], new[1]] == LETHAL
    # Gone altogether: a max-range reading clears up to raytrace_range and marks nothing.
    update_obstacles(layer, sensor, [0.0], [4.0], obstacle_range=2.5, raytrace_range=3.0,
                     range_max=4.0)
    assert layer.costs.sum() == 0


def test_obstacle_range_limits_marking_and_raytrace_limits_clearing() -> None:
    layer = _obstacle_layer()
    layer.costs[50, 90] = LETHAL  # 4 m from the sensor: beyond raytrace_range
    update_obstacles(layer, [0.025, 2.525], [0.0], [4.6], obstacle_range=2.5,
                     raytrace_range=3.0)
    assert layer.costs[50, 90] == LETHAL  # not cleared
    assert layer.costs[50, 92] == FREE_SPACE  # not marked (beyond obstacle_range)
    assert (layer.costs[50, :60] == 0).all()


def test_many_beams_vectorised_scan() -> None:
    layer = _obstacle_layer()
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    update_obstacles(layer, [2.5, 2.5], angles, np.full(360, 1.0), obstacle_range=2.5,
                     raytrace_range=3.0)
    marked = np.argwhere(layer.costs == LETHAL)
    d = np.linalg.norm(layer.cell_to_world(marked) - 2.5, axis=1)
    assert len(marked) > 50
    assert np.all(np.abs(d - 1.0) < 2 * RES)


def test_local_costmap_follows_robot() -> None:
    grid = OccupancyGrid.empty(10.0, 10.0, RES)
    local = LocalCostmap(grid, width=4.0, height=3.0)
    for x, y in [(2.0, 2.0), (5.3, 4.1), (8.0, 7.7)]:
        cm = local.update([x, y, 0.3])
        assert cm.shape == (60, 80)
        xmin, ymin, xmax, ymax = cm.bounds
        assert (xmin + xmax) / 2 == pytest.approx(x, abs=RES)
        assert (ymin + ymax) / 2 == pytest.approx(y, abs=RES)
        # The window sits on the map lattice.
        assert (xmin / RES) == pytest.approx(round(xmin / RES))
    # Near the map edge the static wall shows up (inflated) inside the window.
    cm = local.update([9.0, 5.0, 0.0])
    assert cm.cost_at([9.975, 5.0]) == LETHAL
    assert cm.cost_at([9.0, 5.0]) == 0


def test_local_costmap_obstacle_memory_shifts_with_window() -> None:
    grid = OccupancyGrid.empty(10.0, 10.0, RES, walls=False)
    params = CostmapParams(use_semantic=False)
    local = LocalCostmap(grid, width=4.0, height=4.0, params=params)
    local.update([5.0, 5.0, 0.0], scan_ranges=[1.0], scan_angles=[0.0])
    assert local.master.cost_at([6.01, 5.01]) == LETHAL
    # Move 0.5 m without a scan: the mark stays at the same world place.
    cm = local.update([5.5, 5.3, 0.0])
    assert cm.cost_at([6.01, 5.01]) == LETHAL
    assert (cm.costs == LETHAL).sum() == 1
    # Drive so far that the mark leaves the window and comes back: it is forgotten.
    local.update([9.5, 9.5, 0.0])
    cm = local.update([5.0, 5.0, 0.0])
    assert (cm.costs == LETHAL).sum() == 0


def test_semantic_layer_is_higher_in_front_of_walking_pedestrian() -> None:
    shape = (100, 100)
    out = social_costs(shape, RES, (0.0, 0.0), [[2.5, 2.5]], [[1.2, 0.0]],
                       presence_radius=0.3, amplitude=200)
    cm = Costmap(out, RES, (0.0, 0.0))
    for d in (0.5, 0.8, 1.0):
        front = int(cm.cost_at([2.5 + d, 2.5]))
        behind = int(cm.cost_at([2.5 - d, 2.5]))
        side = int(cm.cost_at([2.5, 2.5 + d]))
        assert front > behind
        assert front > side
    assert cm.cost_at([2.5, 2.5]) == LETHAL  # presence
    # At rest the personal space is symmetric.
    still = Costmap(social_costs(shape, RES, (0.0, 0.0), [[2.525, 2.525]], [[0.0, 0.0]]), RES,
                    (0.0, 0.0))
    assert still.cost_at([3.025, 2.525]) == still.cost_at([2.025, 2.525]) > 0


def test_costmaps_read_the_crowds_semantic_layers() -> None:
    from arena.crowd.semantic import semantic_points
    from arena.nav.costmap import pedestrians_from_semantic
    from tests.crowd.test_semantic import crowd

    state = crowd()
    points = semantic_points(state)
    pos, vel = pedestrians_from_semantic(points)
    np.testing.assert_allclose(pos, state.positions)
    np.testing.assert_allclose(vel, state.velocities, atol=1e-6)  # float32 evidence
    grid = OccupancyGrid.empty(10.0, 10.0, RES)
    a, b = GlobalCostmap(grid), GlobalCostmap(grid)
    via_semantic = a.update(semantic=points).costs
    via_arrays = b.update(ped_positions=pos, ped_velocities=vel).costs
    np.testing.assert_array_equal(via_semantic, via_arrays)
    assert via_semantic.max() == LETHAL  # the people are in the layer
    local = LocalCostmap(grid, width=4.0, height=4.0)
    window = local.update([1.0, 1.0, 0.0], semantic=points)
    assert window.cost_at([0.5, 0.5]) == LETHAL


def test_global_costmap_combines_layers_and_plans() -> None:
    grid = OccupancyGrid.empty(8.0, 6.0, RES)
    gc = GlobalCostmap(grid, CostmapParams(inscribed_radius=0.2, inflation_radius=0.6))
    assert gc.master.cost_at([0.025, 3.0]) == LETHAL
    assert gc.master.cost_at([0.2, 3.0]) == INSCRIBED
    assert 0 < gc.master.cost_at([0.5, 3.0]) < INSCRIBED
    # A pedestrian blocking a corridor raises the costmap; the occupancy view blocks its body.
    cm = gc.update(ped_positions=[[4.0, 3.0]], ped_velocities=[[0.0, 1.0]])
    assert cm.cost_at([4.0, 3.0]) == LETHAL
    assert cm.cost_at([4.0, 4.0]) > cm.cost_at([4.0, 2.0]) > 0
    occ = cm.to_occupancy()
    planner = GLOBAL_PLANNERS.build({"type": "theta_star"})
    path = planner.plan(occ, Pose2D(1.0, 3.0), Pose2D(7.0, 3.0))
    assert not occ.is_occupied(path).any()
    # A scan return marks an obstacle in the global costmap too.
    cm = gc.update(sensor_xy=[1.0, 1.0], beam_angles=[0.0], ranges=[1.0])
    assert cm.cost_at([2.01, 1.01]) == LETHAL
    assert cm.cost_at([4.0, 3.0]) < INSCRIBED  # pedestrians are not remembered


def test_params_validate() -> None:
    with pytest.raises(ValueError, match="cost_scaling_factor"):
        CostmapParams(cost_scaling_factor=-1.0)
    with pytest.raises(ValueError, match="window size"):
        LocalCostmap(OccupancyGrid.empty(2.0, 2.0, RES), width=0.0)
