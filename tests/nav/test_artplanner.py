"""ArtPlanner: the ramp, not the cliff or the steep slope; a flat PRM like A*; typed failures."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from arena.core.errors import ConfigError, GoalOccupied, MapError, NoPathFound, StartOccupied
from arena.core.geometry import polyline_length
from arena.core.types import Pose2D
from arena.learn.artplanner.model import ARTPLANNER_WEIGHTS, MotionCostModel
from arena.learn.artplanner.stepping import stepping_labels, track_points
from arena.learn.planners.artplanner import ArtPlanner
from arena.maps.grid import OccupancyGrid
from arena.maps.terrain import HeightMap
from arena.nav.global_planners import GLOBAL_PLANNERS, segment_is_free

RES = 0.1
TOP = 0.4  # m, the plateau: higher than the robot's 0.15 m step
RAMP = (6.0, 7.5)  # y range of the 12 deg ramp up the plateau's west face
STEEP = (0.5, 2.0)  # y range of the 40 deg slope (too steep) up the same face


def _course() -> tuple[OccupancyGrid, HeightMap]:
    """10 x 8 m: ground west of x = 6 m, a plateau 0.4 m high east of it (a cliff), a gentle ramp
    up at the far north and a too-steep slope straight between start and goal."""
    grid = OccupancyGrid.empty(10.0, 8.0, RES)
    rows, cols = grid.data.shape
    x = (np.arange(cols) + 0.5) * RES
    y = (np.arange(rows) + 0.5) * RES
    gx, gy = np.meshgrid(x, y)
    h = np.where(gx >= 6.0, TOP, 0.0)
    for (y0, y1), deg in ((RAMP, 12.0), (STEEP, 40.0)):
        run = TOP / math.tan(math.radians(deg))
        on = (gy >= y0) & (gy < y1) & (gx < 6.0) & (gx >= 6.0 - run)
        h[on] = TOP * (gx[on] - (6.0 - run)) / run
    return grid, HeightMap(h, RES)


def _walkable(path: np.ndarray, hm: HeightMap, model: MotionCostModel) -> bool:
    """Every leg of the path feasible under the stepping model that made the labels."""
    s = model.stepping
    for a, b in itertools.pairwise(path):
        n = max(1, math.ceil(np.linalg.norm(b - a) / 0.5))
        pts = a + np.linspace(0, 1, n + 1)[:, None] * (b - a)
        ok, _ = stepping_labels(hm.at(track_points(pts[:-1], pts[1:], s)),
                                np.linalg.norm(pts[1:] - pts[:-1], axis=1), s)
        if not ok.all():
            return False
    return True


@pytest.fixture(scope="module")
def course() -> tuple[OccupancyGrid, HeightMap]:
    return _course()


def test_takes_the_ramp_not_the_cliff_or_the_steep_slope(course):
    grid, hm = course
    planner = ArtPlanner(terrain=hm)
    start, goal = Pose2D(2.0, 1.25), Pose2D(8.0, 1.25)
    path = planner.plan(grid, start, goal)
    np.testing.assert_allclose(path[[0, -1]], [start.xy, goal.xy])
    # where the path climbs (crosses x = 5..6 m) it is on the ramp
    dense = np.concatenate([a + np.linspace(0, 1, 200)[:, None] * (b - a)
                            for a, b in itertools.pairwise(path)])
    climbing = dense[(dense[:, 0] > 5.0) & (dense[:, 0] < 6.0)]
    assert len(climbing) and climbing[:, 1].min() >= RAMP[0] + 0.1
    assert climbing[:, 1].max() <= RAMP[1] - 0.1
    assert _walkable(path, hm, planner.model)
    # the straight line, which A* takes on the flat map, crosses the steep slope: not walkable
    straight = np.array([start.xy, goal.xy])
    assert not _walkable(straight, hm, planner.model)
    np.testing.assert_allclose(GLOBAL_PLANNERS.build({"type": "astar"}).plan(grid, start, goal),
                               straight)
    np.testing.assert_array_equal(planner.plan(grid, start, goal), path)  # same seed, same path


def test_the_network_rates_edges_like_the_stepping_model(course):
    _, hm = course
    planner = ArtPlanner(terrain=hm)

    def rate(a, b):
        feas, cost = planner.edge_costs(np.array([a]), np.array([b]))
        return float(feas[0]), float(cost[0])

    assert rate((5.3, 1.25), (6.1, 1.25))[0] < 0.5  # up the 40 deg slope
    assert rate((5.6, 4.0), (6.4, 4.0))[0] < 0.5  # up the 0.4 m cliff
    assert rate((6.4, 4.0), (5.6, 4.0))[0] < 0.5  # down it
    up, down, flat = rate((4.4, 6.75), (5.2, 6.75)), rate((5.2, 6.75), (4.4, 6.75)), \
        rate((1.0, 4.0), (1.8, 4.0))
    assert min(up[0], down[0], flat[0]) > 0.5
    # time (s) over 0.8 m: level at the robot's 0.8 m/s, downhill slower, uphill slower still
    assert flat[1] == pytest.approx(1.0, abs=0.15)
    assert up[1] > down[1] > flat[1]


def test_goes_down_the_ramp_too(course):
    grid, hm = course
    planner = ArtPlanner(terrain=hm)
    path = planner.plan(grid, Pose2D(8.0, 4.0), Pose2D(2.0, 4.0))
    assert _walkable(path, hm, planner.model)
    assert path[:, 1].max() > RAMP[0]


def test_no_walkable_route_is_a_clear_no_path(course):
    grid, hm = course
    h = np.array(hm.heights)
    h[h > 0] = TOP  # no ramp, no slope: a cliff all along
    walled = HeightMap(h, RES)
    with pytest.raises(NoPathFound, match="walkable on the terrain"):
        ArtPlanner(ArtPlanner.Params(refinements=0), terrain=walled).plan(
            grid, Pose2D(2.0, 1.25), Pose2D(8.0, 1.25))


def test_goal_on_ground_too_steep_to_stand_on(course):
    grid, hm = course
    with pytest.raises(GoalOccupied, match="cannot stand"):
        ArtPlanner(terrain=hm).plan(grid, Pose2D(2.0, 1.25), Pose2D(5.75, 1.25))


def _boxes() -> OccupancyGrid:
    occ = np.zeros((160, 200), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[:110, 60:64] = True
    occ[50:, 130:134] = True
    occ[70:90, 90:110] = True
    return OccupancyGrid.from_occupied(occ, 0.05).inflate(0.2)


@pytest.mark.parametrize(("start", "goal"), [((0.5, 0.5), (9.5, 7.5)), ((9.5, 0.5), (0.6, 7.4)),
                                             ((4.0, 1.0), (4.2, 7.0))])
def test_flat_world_is_a_prm_close_to_astar(start, goal):
    grid = _boxes()
    s, g = Pose2D(*start), Pose2D(*goal)
    path = ArtPlanner().plan(grid, s, g)  # no height map: a PRM on the occupancy grid
    ref = GLOBAL_PLANNERS.build({"type": "astar"}).plan(grid, s, g)
    assert all(segment_is_free(grid, a, b) for a, b in itertools.pairwise(path))
    np.testing.assert_allclose(path[[0, -1]], [s.xy, g.xy])
    assert polyline_length(path) <= 1.15 * polyline_length(ref)


def test_typed_failures_on_a_flat_map():
    grid = _boxes()
    planner = ArtPlanner()
    with pytest.raises(StartOccupied):
        planner.plan(grid, Pose2D(3.1, 1.0), Pose2D(9.0, 7.0))
    with pytest.raises(GoalOccupied):
        planner.plan(grid, Pose2D(1.0, 1.0), Pose2D(50.0, 7.0))
    occ = np.array(grid.occupied)
    occ[10:30, 160:190] = True
    occ[14:26, 166:184] = False  # a sealed pocket
    sealed = OccupancyGrid.from_occupied(occ, 0.05)
    with pytest.raises(NoPathFound, match="not connected"):
        planner.plan(sealed, Pose2D(1.0, 1.0), Pose2D(8.75, 1.0))


def test_numpy_model_equals_torch_model():
    torch = pytest.importorskip("torch")
    from arena.learn.fit_mlp import build_mlp

    model = MotionCostModel.load(ARTPLANNER_WEIGHTS)
    net = build_mlp(model.features.size, model.weights[0].shape[0])
    layers = [m for m in net if isinstance(m, torch.nn.Linear)]
    with torch.no_grad():
        for layer, w, b in zip(layers, model.weights, model.biases, strict=True):
            layer.weight.copy_(torch.from_numpy(np.asarray(w)))
            layer.bias.copy_(torch.from_numpy(np.asarray(b)))
        x = np.random.default_rng(0).normal(0, 1, (64, model.features.size)).astype(np.float32)
        want = net(torch.from_numpy(x)).numpy()
    np.testing.assert_allclose(model.raw(x), want, rtol=1e-5, atol=1e-5)


def test_bad_config_is_one_clear_error(tmp_path, course):
    with pytest.raises(ConfigError, match="connect_radius"):
        GLOBAL_PLANNERS.build({"type": "artplanner", "spacing": 0.5, "connect_radius": 0.6})
    with pytest.raises(ConfigError, match="max_length"):
        GLOBAL_PLANNERS.build({"type": "artplanner", "connect_radius": 2.0})
    with pytest.raises(ConfigError, match="spacing"):
        GLOBAL_PLANNERS.build({"type": "artplanner", "spacing": -1})
    with pytest.raises(ConfigError, match="nodes"):
        GLOBAL_PLANNERS.build({"type": "artplanner", "nodes": 10})
    with pytest.raises(ConfigError, match="no ArtPlanner motion-cost policy file"):
        GLOBAL_PLANNERS.build({"type": "artplanner", "weights": str(tmp_path / "none.npz")})
    with pytest.raises(MapError, match="no height map file"):
        GLOBAL_PLANNERS.build({"type": "artplanner", "height_map": str(tmp_path / "h.npz")})
    grid, hm = course
    small = HeightMap(hm.heights[:20, :20], RES)
    with pytest.raises(MapError, match="covers"):
        ArtPlanner(terrain=small).plan(grid, Pose2D(1.0, 1.0), Pose2D(1.5, 1.0))


def test_height_map_from_a_file_through_the_registry(tmp_path, course):
    grid, hm = course
    planner = GLOBAL_PLANNERS.build({"type": "artplanner",
                                     "height_map": str(hm.save(tmp_path / "heights.npz"))})
    assert isinstance(planner, ArtPlanner) and planner.terrain is not None
    path = planner.plan(grid, Pose2D(2.0, 1.25), Pose2D(8.0, 1.25))
    assert path[:, 1].max() > RAMP[0]
