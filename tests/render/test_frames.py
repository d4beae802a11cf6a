"""Tests of the top-down frame renderer (pixels checked at known world points)."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.geometry import rectangle, transform_points
from arena.maps.grid import OccupancyGrid
from arena.render import FrameRenderer, Overlay, style
from arena.scene.state import AgentStates, Collisions, Obstacle, RobotStates, SimState, StaticWorld
from arena.sensors.spec import LidarSpec

RES = 0.1  # m per cell
W_PX = 500  # 10 m wide map → 50 px/m


def _world() -> StaticWorld:
    occ = np.zeros((80, 100), dtype=bool)  # 8 m × 10 m
    occ[40:45, 10:30] = True  # wall block: x 1..3 m, y 4..4.5 m
    grid = OccupancyGrid.from_occupied(occ, RES)
    data = grid.data.copy()
    data[60:70, 60:70] = -1  # unknown patch: x 6..7 m, y 6..7 m
    grid = OccupancyGrid(data, RES)
    box = Obstacle("box", "cuboid", np.array([7.0, 2.0, 0.0]), rectangle(1.0, 1.0))
    return StaticWorld.build(grid, (box,))


SPEC = LidarSpec(angle_min=-np.pi, angle_max=np.pi, num_beams=8, range_max=4.0)
SCAN = np.array([2.0, 4.0, 2.0, 4.0, 2.0, 4.0, 2.0, 4.0])
POSE0 = np.array([3.0, 2.0, 0.3])
POSE1 = np.array([5.0, 6.0, 1.0])
AGENT_POS = np.array([[2.0, 6.5], [8.5, 6.0], [8.5, 4.0]])
AGENT_HEAD = np.array([0.0, np.pi / 2, np.pi])


def _state(
    *, step: int = 3, pose0: np.ndarray = POSE0, colliding: bool = True, scan: np.ndarray = SCAN
) -> SimState:
    robots = RobotStates(
        names=("box_bot", "round_bot"),
        models=("jackal", "burger"),
        poses=np.stack([pose0, POSE1]),
        twists=np.zeros((2, 3)),
        commands=np.zeros((2, 3)),
        radii=np.array([np.hypot(0.3, 0.2), 0.3]),
        footprints=(rectangle(0.6, 0.4), None),
        scans=(scan, np.full(8, 4.0)),
    )
    agents = AgentStates(
        ids=np.arange(3),
        positions=AGENT_POS.copy(),
        velocities=np.zeros((3, 2)),
        headings=AGENT_HEAD.copy(),
        radii=np.full(3, 0.3),
        kinds=np.array([0, 1, 2]),
        states=np.array([0, 1, 0]),
    )
    neg = np.full(2, -1, dtype=np.int64)
    collisions = Collisions(np.array([False, colliding]), neg, neg.copy(), neg.copy())
    return SimState(step * 0.1, step, robots, agents, collisions)


@pytest.fixture(scope="module")
def world() -> StaticWorld:
    return _world()


@pytest.fixture(scope="module")
def renderer(world: StaticWorld) -> FrameRenderer:
    return FrameRenderer(world, lidar_specs=[SPEC, None], width_px=W_PX, show_trails=False)


@pytest.fixture(scope="module")
def frame(renderer: FrameRenderer) -> np.ndarray:
    return renderer.render(_state())


def _pixel(frame: np.ndarray, renderer: FrameRenderer, xy: tuple[float, float]) -> np.ndarray:
    col, row = np.floor(renderer.world_to_pixel(np.asarray(xy, dtype=float))).astype(int)
    return frame[row, col].astype(int)


def _near(
    frame: np.ndarray, renderer: FrameRenderer, xy: tuple[float, float], radius_px: int
) -> np.ndarray:
    """``(k, 3)`` int pixels in a square of ``radius_px`` around a world point."""
    col, row = np.floor(renderer.world_to_pixel(np.asarray(xy, dtype=float))).astype(int)
    patch = frame[row - radius_px : row + radius_px + 1, col - radius_px : col + radius_px + 1]
    return patch.reshape(-1, 3).astype(int)


def _has_color(pixels: np.ndarray, color: style.RGB, tol: int = 10) -> bool:
    return bool(np.any(np.max(np.abs(pixels - style.to_uint8(color).astype(int)), axis=1) <= tol))


def _is_color(pixel: np.ndarray, color: style.RGB, tol: int = 3) -> bool:
    return int(np.max(np.abs(pixel - style.to_uint8(color).astype(int)))) <= tol


def test_frame_shape_and_dtype(renderer: FrameRenderer, frame: np.ndarray) -> None:
    assert frame.shape == (400, 500, 3) == renderer.shape
    assert frame.dtype == np.uint8
    assert frame.flags.c_contiguous


def test_world_to_pixel_is_exact_and_y_up(renderer: FrameRenderer) -> None:
    np.testing.assert_allclose(renderer.world_to_pixel([0.0, 0.0]), [0.0, 400.0], atol=1e-6)
    np.testing.assert_allclose(renderer.world_to_pixel([10.0, 8.0]), [500.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(renderer.world_to_pixel([[1.0, 1.0]]), [[50.0, 350.0]], atol=1e-6)
    pts = np.array([[0.3, 7.1], [9.9, 0.2]])
    np.testing.assert_allclose(renderer.pixel_to_world(renderer.world_to_pixel(pts)), pts)
    assert renderer.extent == pytest.approx((0.0, 0.0, 10.0, 8.0))


def test_map_layers(renderer: FrameRenderer, frame: np.ndarray) -> None:
    assert _is_color(_pixel(frame, renderer, (2.0, 4.25)), style.OCCUPIED)  # wall block
    assert _is_color(_pixel(frame, renderer, (6.5, 6.5)), style.UNKNOWN)
    assert _is_color(_pixel(frame, renderer, (9.5, 7.2)), style.FREE)
    assert frame[200, 250].mean() > 0  # not a blank canvas
    assert _is_color(_pixel(frame, renderer, (7.0, 2.0)), style.OBSTACLE_FACE)  # obstacle middle


def test_robot_bodies_have_their_colours(renderer: FrameRenderer, frame: np.ndarray) -> None:
    # Behind the centre: the heading line runs from the centre to the front.
    behind0 = transform_points(np.array([[-0.15, 0.05]]), POSE0)[0]
    assert _is_color(_pixel(frame, renderer, tuple(behind0)), style.robot_color(0))
    behind1 = transform_points(np.array([[-0.15, 0.05]]), POSE1)[0]
    assert _is_color(_pixel(frame, renderer, tuple(behind1)), style.robot_color(1))
    assert style.robot_color(0) != style.robot_color(1)


def test_collision_outline(renderer: FrameRenderer, frame: np.ndarray) -> None:
    # Robot 1 (radius 0.3 m = 15 px) collides: its outline is red; robot 0 does not.
    assert _has_color(_near(frame, renderer, tuple(POSE1[:2]), 18), style.COLLISION)
    assert not _has_color(_near(frame, renderer, tuple(POSE0[:2]), 18), style.COLLISION)
    calm = renderer.render(_state(colliding=False))
    assert not _has_color(_near(calm, renderer, tuple(POSE1[:2]), 18), style.COLLISION)


def test_agents_coloured_by_state_and_outlined_by_kind(
    renderer: FrameRenderer, frame: np.ndarray
) -> None:
    colors = []
    for pos, head in zip(AGENT_POS, AGENT_HEAD, strict=True):
        # Half a radius behind the centre, away from the heading tick.
        p = pos - 0.15 * np.array([np.cos(head), np.sin(head)])
        colors.append(tuple(_pixel(frame, renderer, tuple(p))))
    assert _is_color(np.array(colors[0]), style.agent_state_color(0))
    assert _is_color(np.array(colors[1]), style.agent_state_color(1))
    assert _is_color(np.array(colors[2]), style.agent_state_color(0))
    assert colors[0] != colors[1]
    assert colors[0] == colors[2]
    # Kind 1 (elder) outline colour appears around agent 1 only.
    assert _has_color(_near(frame, renderer, tuple(AGENT_POS[1]), 17), style.agent_kind_color(1))
    assert not _has_color(
        _near(frame, renderer, tuple(AGENT_POS[0]), 17), style.agent_kind_color(1)
    )


def test_lidar_hits_drawn_but_not_max_range_beams(
    renderer: FrameRenderer, frame: np.ndarray
) -> None:
    hit_color = style.shade(style.robot_color(0), 0.8)
    angles = POSE0[2] + SPEC.angles()
    ends = POSE0[:2] + SCAN[:, None] * np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    assert _is_color(_pixel(frame, renderer, tuple(ends[4])), hit_color)  # 2 m: a hit
    assert not _has_color(_near(frame, renderer, tuple(ends[5]), 2), hit_color)  # 4 m = max
    plain = FrameRenderer(renderer.world, lidar_specs=[SPEC], width_px=W_PX, show_lidar=False)
    assert not _has_color(_near(plain.render(_state()), plain, tuple(ends[4]), 2), hit_color)


def test_scan_length_mismatch_is_an_error(renderer: FrameRenderer) -> None:
    with pytest.raises(ConfigError, match="num_beams"):
        renderer.render(_state(scan=np.full(5, 1.0)))


def test_overlay_goal_path_and_text(renderer: FrameRenderer, frame: np.ndarray) -> None:
    goal = np.array([[8.0, 1.0, 0.0], [np.nan, np.nan, np.nan]])
    overlay = Overlay(
        paths=[np.array([[3.0, 2.0], [5.0, 0.8], [8.0, 1.0]]), None],
        goals=goal,
        subgoals=np.array([[5.0, 0.8], [np.nan, np.nan]]),
        text="outcome: success",
    )
    with_ov = renderer.render(_state(), overlay)
    assert _has_color(_near(with_ov, renderer, (8.0, 1.0), 8), style.robot_color(0))
    assert not _has_color(_near(frame, renderer, (8.0, 1.0), 8), style.robot_color(0))
    # The path passes through (4, 1.4), halfway along its first segment.
    assert _has_color(_near(with_ov, renderer, (4.0, 1.4), 2), style.robot_color(0))
    # The text box grows by one line in the top-left corner.
    assert not np.array_equal(with_ov[:60, :200], frame[:60, :200])


def test_rendering_is_deterministic(world: StaticWorld, renderer: FrameRenderer) -> None:
    a = renderer.render(_state())
    b = renderer.render(_state())
    fresh = FrameRenderer(world, lidar_specs=[SPEC, None], width_px=W_PX, show_trails=False)
    c = fresh.render(_state())
    assert np.array_equal(a, b)
    assert np.array_equal(a, c)


def test_trails_follow_the_robot_and_reset(world: StaticWorld) -> None:
    r = FrameRenderer(world, width_px=W_PX, show_trails=True)
    trail_color = style.shade(style.robot_color(0), style.TRAIL_TINT)
    for k in range(5):
        pose = POSE0 + np.array([0.0, 0.5 * k, 0.0])
        f = r.render(_state(step=k, pose0=pose, colliding=False))
    # Robot 0 went from y = 2 to y = 4; the trail passes (3, 2.6).
    assert _has_color(_near(f, r, (3.0, 2.6), 2), trail_color)
    # A state with a lower step starts a new episode: no trail left.
    f = r.render(_state(step=0, pose0=POSE0 + np.array([0.0, 2.0, 0.0]), colliding=False))
    assert not _has_color(_near(f, r, (3.0, 2.6), 2), trail_color)


def test_no_agents_and_no_robots(world: StaticWorld) -> None:
    r = FrameRenderer(world, width_px=200)
    empty = RobotStates((), (), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                        np.zeros(0), (), ())
    f = r.render(SimState(0.0, 0, empty, AgentStates.empty(), Collisions.none(0)))
    assert f.shape == r.shape == (160, 200, 3)


def test_thin_walls_survive_zoomed_out_frames() -> None:
    # 100 m × 100 m at 5 cm → 2000 cells across on 200 px: 10 cells per pixel.
    occ = np.zeros((2000, 2000), dtype=bool)
    occ[1000, :] = True  # one-cell wall at y = 50 m
    r = FrameRenderer(StaticWorld.build(OccupancyGrid.from_occupied(occ, 0.05)), width_px=200)
    empty = RobotStates((), (), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                        np.zeros(0), (), ())
    f = r.render(SimState(0.0, 0, empty, AgentStates.empty(), Collisions.none(0)))
    _, row = np.floor(r.world_to_pixel([50.0, 50.025])).astype(int)
    assert _is_color(f[row, 100], style.OCCUPIED)
    dark = np.all(np.abs(f[row, 60:190].astype(int) - style.to_uint8(style.OCCUPIED)) <= 3, axis=1)
    assert dark.all()


def test_bad_arguments(world: StaticWorld) -> None:
    with pytest.raises(ConfigError):
        FrameRenderer(world, width_px=4)
    with pytest.raises(ConfigError, match=r"width_px must lie in \[16, 8000\] pixels"):
        FrameRenderer(world, width_px=100_000_000)  # arena maps generate --width-px
    with pytest.raises(ConfigError):
        FrameRenderer(world, margin_m=-1.0)


def test_margin_and_obstacles_outside_map_extend_the_view() -> None:
    grid = OccupancyGrid.empty(4.0, 4.0, 0.1)
    out = Obstacle("far", "cuboid", np.array([5.0, 2.0, 0.0]), rectangle(1.0, 1.0))
    r = FrameRenderer(StaticWorld.build(grid, (out,)), width_px=220, margin_m=0.5)
    xmin, ymin, xmax, ymax = r.extent
    assert xmin == pytest.approx(-0.5)
    assert xmax == pytest.approx(6.0)
    assert ymin < -0.49
    assert ymax > 4.49
    assert r.height_px % 2 == 0


def test_unknown_space_around_a_building_is_cropped() -> None:
    data = np.full((400, 400), -1, dtype=np.int8)  # 40 m x 40 m of unknown space ...
    data[100:160, 150:250] = 0  # ... around a 10 m x 6 m mapped block at x 15..25, y 10..16
    world = StaticWorld.build(OccupancyGrid(data, 0.1))
    r = FrameRenderer(world, width_px=800)
    xmin, ymin, xmax, ymax = r.extent
    assert (xmin, xmax) == (pytest.approx(14.0), pytest.approx(26.0))  # 1 m of margin
    assert ymin <= 9.0 and ymax >= 17.0 and ymax - ymin < 12.0
    assert r.scale == pytest.approx(800 / 12.0)
    assert FrameRenderer(world, width_px=800, crop_unknown=False).extent[:3] == (
        pytest.approx(0.0), pytest.approx(0.0), pytest.approx(40.0))


def test_a_still_picture_of_a_world_has_no_empty_text_box(world: StaticWorld) -> None:
    """render_world (map previews) shows no time line, so its corner holds no empty box."""
    from arena.render.frames import render_world

    still = render_world(world, width_px=400, title="preview")
    corner = still[2:30, 2:30].reshape(-1, 3)
    assert len(np.unique(corner, axis=0)) == 1  # background only
    timed = FrameRenderer(world, width_px=400, title="preview").render(_state())
    assert len(np.unique(timed[2:30, 2:30].reshape(-1, 3), axis=0)) > 1  # the time line's box


def test_detections_are_crosses_and_tracks_rings_with_their_id(
    renderer: FrameRenderer, frame: np.ndarray
) -> None:
    overlay = Overlay(detections=np.array([[6.0, 3.0]]),
                      tracks=(np.array([4, 11]), np.array([[2.0, 6.5], [5.0, 4.0]])))
    with_ov = renderer.render(_state(), overlay)
    assert _has_color(_near(with_ov, renderer, (6.0, 3.0), 3), style.DETECTION)
    assert not _has_color(_near(frame, renderer, (6.0, 3.0), 8), style.DETECTION)
    # a ring around each track in its id's colour, hollow: the person's disc shows through
    for tid, xy in ((4, (2.0, 6.5)), (11, (5.0, 4.0))):
        colour = style.TRACK_COLORS[tid % len(style.TRACK_COLORS)]
        assert _has_color(_near(with_ov, renderer, xy, 12), colour, tol=20), tid
    assert np.array_equal(_pixel(with_ov, renderer, (2.0, 6.5)), _pixel(frame, renderer,
                                                                       (2.0, 6.5)))
    # the id label sits up and right of the ring
    col, row = np.floor(renderer.world_to_pixel(np.array([5.0, 4.0]))).astype(int)
    off = int(style.TRACK_LABEL_OFFSET_PX)
    label = with_ov[row - off - 20 : row - off, col + off : col + off + 20].reshape(-1, 3)
    assert _has_color(label.astype(int), style.TRACK_COLORS[11 % len(style.TRACK_COLORS)],
                      tol=40)
    # the next frame without perception draws none of it again
    again = renderer.render(_state())
    assert np.array_equal(again, frame)
