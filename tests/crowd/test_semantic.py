"""Semantic layers: points per attribute, encodings, rasters (arena_specs §5.4)."""

from __future__ import annotations

import numpy as np
import pytest

from arena.crowd.semantic import (
    Animation,
    GridSpec,
    SemanticAttribute,
    SemanticData,
    SemanticLayers,
    decode_animation,
    encode_social_state,
    rasterize,
    semantic_points,
)
from arena.crowd.state import AgentType, CrowdState, SocialState
from arena.maps.grid import OccupancyGrid


def crowd() -> CrowdState:
    p = np.array([[0.5, 0.5], [1.5, 0.5], [2.5, 2.5], [9.0, 9.0]])
    n = len(p)
    return CrowdState(
        ids=np.arange(n),
        positions=p,
        velocities=np.array([[0.3, -0.4], [0.0, 0.0], [0.04, 0.0], [-1.0, 2.0]]),
        headings=np.zeros(n),
        radii=np.full(n, 0.3),
        vmax=np.ones(n),
        vmax_factor=np.ones(n),
        waypoints=p[:, None, :].copy(),
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_index=np.zeros(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        destinations=p.copy(),
        startup_mode=np.zeros(n, dtype=np.int64),
        wait_time=np.zeros(n),
        trigger_radius=np.zeros(n),
        started=np.ones(n, dtype=bool),
        group=np.full(n, -1),
        leader=np.arange(n),
        kinds=np.array([AgentType.ADULT, AgentType.ELDER, AgentType.CHILD, AgentType.ADULT]),
        social_state=np.array(
            [SocialState.WALKING, SocialState.TALKING, SocialState.PANIC, SocialState.IDLE]
        ),
        stress=np.array([0.1, 0.2, 0.3, 0.4]),
        energy=np.array([0.5, 0.6, 0.7, 0.8]),
        social=np.array([0.9, 0.8, 0.7, 0.6]),
        forces={"desired": np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.0], [0.0, 0.01]])},
    )


def test_every_attribute_with_counts_and_values():
    state = crowd()
    pts = semantic_points(state)
    assert set(pts) == {a.value for a in SemanticAttribute}
    for name, data in pts.items():
        assert data.evidence.dtype == np.float32
        assert data.locations.shape == (len(data), 2), name
    assert len(pts["pedestrian"]) == 4
    np.testing.assert_array_equal(pts["pedestrian"].evidence, 1.0)
    np.testing.assert_array_equal(pts["pedestrian"].locations, state.positions)
    # Moving by speed > 0.05 m/s: agents 0 (0.5) and 3 (2.24); agent 2 creeps at 0.04.
    np.testing.assert_array_equal(pts["pedestrian_moving"].locations, state.positions[[0, 3]])
    np.testing.assert_array_equal(pts["pedestrian_moving"].evidence, 1.0)
    np.testing.assert_allclose(pts["pedestrian_vel_x"].evidence, [0.3, 0.0, 0.04, -1.0], rtol=1e-6)
    np.testing.assert_allclose(pts["pedestrian_vel_y"].evidence, [-0.4, 0.0, 0.0, 2.0], rtol=1e-6)
    np.testing.assert_array_equal(pts["pedestrian_type"].evidence, [0, 1, -1, 0])
    np.testing.assert_array_equal(pts["social_state"].evidence, [513, 1281, 769, 257])
    np.testing.assert_allclose(pts["stress"].evidence, state.stress, rtol=1e-6)
    np.testing.assert_allclose(pts["energy"].evidence, state.energy, rtol=1e-6)
    np.testing.assert_allclose(pts["social"].evidence, state.social, rtol=1e-6)


def test_moving_from_acceleration_is_arenas_criterion():
    state = crowd()
    layers = SemanticLayers(SemanticLayers.Params(moving_from="acceleration"))
    # From state.forces: only agent 1 (0.1 m/s²) is above 0.05.
    np.testing.assert_array_equal(
        layers.points(state)["pedestrian_moving"].locations, state.positions[[1]]
    )
    acc = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.06]])
    moving = layers.points(state, acc)["pedestrian_moving"]
    np.testing.assert_array_equal(moving.locations, state.positions[[0, 3]])


def test_social_state_encoding_matches_arena_animation_enum():
    codes = np.arange(7)
    ev = encode_social_state(codes)
    assert ev.tolist() == [257, 513, 769, 1025, 1281, 1537, 769]
    assert (ev.astype(np.int64) & 0xFF == 1).all()
    anim = decode_animation(ev)
    assert anim.tolist() == [
        Animation.IDLE,
        Animation.WALKING,
        Animation.RUNNING,
        Animation.INTERACTING,
        Animation.TALKING,
        Animation.PHONE,
        Animation.RUNNING,
    ]


GRID = GridSpec(resolution=1.0, origin=(0.0, 0.0), shape=(3, 4))


def data(points, values) -> SemanticData:
    return SemanticData(np.asarray(points, float), np.asarray(values, np.float32))


def test_rasterize_reduces_points_per_cell():
    d = data(
        [[0.2, 0.3], [0.9, 0.9], [2.5, 1.5], [3.99, 2.01], [-0.1, 0.5], [4.0, 0.5]],
        [2.0, -5.0, 1.5, 7.0, 100.0, 100.0],
    )
    mx = rasterize(d, GRID, reduce="max")
    sm = rasterize(d, GRID, reduce="sum")
    mn = rasterize(d, GRID, reduce="mean")
    assert mx.shape == (3, 4) and mx.dtype == np.float32
    expected_max = np.zeros((3, 4))
    expected_max[0, 0], expected_max[1, 2], expected_max[2, 3] = 2.0, 1.5, 7.0
    np.testing.assert_array_equal(mx, expected_max)
    assert sm[0, 0] == -3.0 and mn[0, 0] == -1.5
    assert sm[1, 2] == mn[1, 2] == 1.5
    assert sm.sum() == pytest.approx(-3.0 + 1.5 + 7.0)  # off-grid points dropped
    # A cell with only negative evidence keeps it under max (empty cells are 0).
    neg = rasterize(data([[1.5, 1.5]], [-1.0]), GRID, reduce="max")
    assert neg[1, 1] == -1.0 and np.count_nonzero(neg) == 1


def test_rasterize_radius_covers_a_disc_of_cells():
    grid = GridSpec(resolution=0.5, origin=(-2.5, -2.5), shape=(10, 10))
    d = data([[0.0, 0.0]], [3.0])
    disc = rasterize(d, grid, reduce="sum", radius=1.0)
    rows, cols = np.nonzero(disc)
    cx = -2.5 + (cols + 0.5) * 0.5
    cy = -2.5 + (rows + 0.5) * 0.5
    assert (np.hypot(cx, cy) <= 1.0).all()
    # Cell centres at (±0.25 + 0.5k): those within 1 m of the origin form a 12-cell disc.
    assert len(rows) == 12
    np.testing.assert_array_equal(disc[rows, cols], 3.0)
    # Two overlapping discs: sum adds, max keeps the larger, mean averages.
    two = data([[0.0, 0.0], [0.5, 0.0]], [3.0, 1.0])
    s = rasterize(two, grid, reduce="sum", radius=0.6)
    m = rasterize(two, grid, reduce="max", radius=0.6)
    a = rasterize(two, grid, reduce="mean", radius=0.6)
    both = s == 4.0
    assert both.any()
    np.testing.assert_array_equal(m[both], 3.0)
    np.testing.assert_array_equal(a[both], 2.0)
    # A tiny radius still marks the point's own cell.
    one = rasterize(d, grid, radius=0.01)
    assert np.count_nonzero(one) == 1 and one[5, 5] == 3.0


def test_rasterize_accepts_an_occupancy_grid_and_rejects_bad_arguments():
    grid = OccupancyGrid.empty(2.0, 1.0, 0.5, walls=False, origin=(1.0, 1.0))
    out = rasterize(data([[1.6, 1.1]], [4.0]), grid)
    assert out.shape == (2, 4) and out[0, 1] == 4.0
    pts = semantic_points(crowd())
    full = rasterize(pts["pedestrian"], GridSpec(1.0, (0.0, 0.0), (10, 10)), reduce="sum")
    assert full.sum() == 4.0 and full[9, 9] == 1.0
    with pytest.raises(ValueError, match="reduce"):
        rasterize(pts["pedestrian"], grid, reduce="median")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="radius"):
        rasterize(pts["pedestrian"], grid, radius=-1.0)
