"""The frame legend: what it lists, that each entry is drawn, and that nothing is clipped."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.geometry import rectangle
from arena.crowd.state import SocialState
from arena.maps.grid import OccupancyGrid
from arena.render import FrameRenderer, Overlay, legend_items, style
from arena.render.legend import ELEMENTS, legend_entries
from arena.scene.state import AgentStates, Collisions, RobotStates, SimState, StaticWorld
from arena.sensors.spec import LidarSpec

LONG_TITLE = "default/corridor_scenario · jackal · pysocial"
SPEC = LidarSpec(angle_min=-np.pi, angle_max=np.pi, num_beams=90, range_max=30.0)


def test_state_names_match_social_state_codes():
    assert tuple(s.name.lower() for s in SocialState) == style.AGENT_STATE_NAMES
    assert len(style.AGENT_STATE_COLORS) >= len(SocialState)
    # Distinct colours for every state.
    assert len(set(style.AGENT_STATE_COLORS[: len(SocialState)])) == len(SocialState)


def _state(
    *, step: int = 0, xy: tuple[float, float] = (2.0, 2.0), colliding: bool = False,
    people: tuple[int, ...] = (), scan: float | None = None,
) -> SimState:
    scans = (np.full(SPEC.num_beams, scan),) if scan is not None else (np.zeros(0),)
    robots = RobotStates(("r",), ("jackal",), np.array([[*xy, 0.0]]), np.zeros((1, 3)),
                         np.zeros((1, 3)), np.array([0.3]), (rectangle(0.5, 0.4),), scans)
    n = len(people)
    agents = AgentStates(np.arange(n), np.tile([[1.0, 1.0]], (n, 1)), np.zeros((n, 2)),
                         np.zeros(n), np.full(n, 0.3), np.zeros(n, dtype=np.int64),
                         np.asarray(people, dtype=np.int64))
    neg = np.full(1, -1)
    return SimState(0.1 * step, step, robots, agents,
                    Collisions(np.array([colliding]), neg, neg.copy(), neg.copy()))


def test_legend_entries_are_checked_and_ordered():
    assert legend_entries(["walking", "goal", "robot", "goal"]) == ("robot", "goal", "walking")
    assert legend_entries(True) == ELEMENTS + style.AGENT_STATE_NAMES
    assert legend_entries(False) == ()
    with pytest.raises(ConfigError, match=r"legend: unknown entry 'gaol'; known: robot, collision"):
        legend_entries(["gaol"])
    with pytest.raises(ConfigError, match="legend: unknown entry 'gaol'"):
        FrameRenderer(StaticWorld.build(OccupancyGrid.empty(4, 4, 0.1)), legend=["gaol"])


def test_legend_items_list_exactly_what_the_frames_show():
    quiet = [_state(step=k, people=(1, 1)) for k in range(3)]
    plan = Overlay(paths=[np.array([[0.0, 0.0], [3.0, 3.0]])], goals=np.array([[3.0, 3.0, 0.0]]))
    assert legend_items(quiet, [plan], lidar=True, trails=True) == (
        "robot", "trail", "plan", "goal", "lidar", "walking")
    # a collision in one state, people in two states, a subgoal, no plan, no lidar, no trails
    busy = [*quiet, _state(step=3, colliding=True, people=(0, 6))]
    assert legend_items(busy, [Overlay(subgoals=np.array([[1.0, 1.0]])), None]) == (
        "robot", "collision", "subgoal", "idle", "walking", "panic")
    # a single state draws no trail; a goal of NaN and a one-point path draw nothing
    empty = Overlay(paths=[np.zeros((1, 2)), None], goals=np.full((1, 3), np.nan))
    assert legend_items(quiet[:1], [empty], trails=True) == ("robot", "walking")
    # perceived people: detections and tracks where some overlay has them
    seen = Overlay(detections=np.array([[1.0, 1.0]]),
                   tracks=(np.array([3]), np.array([[1.0, 1.2]])))
    assert legend_items(quiet, [None, seen]) == ("robot", "detection", "track", "walking")
    none_seen = Overlay(detections=np.zeros((0, 2)), tracks=(np.zeros(0), np.zeros((0, 2))))
    assert legend_items(quiet, [none_seen]) == ("robot", "walking")


def _near(img: np.ndarray, color: style.RGB, tol: int = 12) -> bool:
    """Some pixel of ``img`` has ``color`` within ``tol`` per channel."""
    diff = np.abs(img.astype(int) - style.to_uint8(color).astype(int)).max(axis=-1)
    return bool(np.any(diff <= tol))


def _legend_crop(entries: list[str]) -> np.ndarray:
    r = FrameRenderer(StaticWorld.build(OccupancyGrid.empty(6, 6, 0.1)), width_px=400,
                      legend=entries, show_trails=False)
    frame = r.render(_state(xy=(-50.0, -50.0)))  # the robot far outside the view
    c0, r0, c1, r1 = (round(v) for v in r.legend_box)
    return frame[r0:r1, c0:c1]


ROBOT = style.robot_color(0)
# Each entry's own colour: it appears in the legend exactly when the entry is listed.
SIGNATURES: dict[str, style.RGB] = {
    "collision": style.COLLISION,
    "trail": style.shade(ROBOT, style.TRAIL_TINT),
    "subgoal": style.shade(ROBOT, 1.35),
    "lidar": style.shade(ROBOT, 0.8),
    "detection": style.DETECTION,
    "track": style.TRACK_COLORS[0],
    **{name: style.agent_state_color(code) for code, name in enumerate(style.AGENT_STATE_NAMES)},
}


@pytest.mark.parametrize("entry", ELEMENTS + style.AGENT_STATE_NAMES)
def test_each_entry_is_drawn_in_its_frame_colour(entry: str):
    alone = _legend_crop([entry])
    color = SIGNATURES.get(entry, ROBOT)  # robot, plan and goal are drawn in the robot's colour
    assert _near(alone, color)
    if entry in SIGNATURES:
        others = _legend_crop([e for e in ELEMENTS + style.AGENT_STATE_NAMES if e != entry])
        assert not _near(others, color, tol=4)
    else:
        assert not _near(_legend_crop(["subgoal"]), ROBOT, tol=4)


def _texts_inside(r: FrameRenderer, box: tuple[float, float, float, float]) -> list[str]:
    """Static texts whose drawn extent leaves ``box`` (col0, row0, col1, row1 pixels)."""
    renderer = r._canvas.get_renderer()
    bad = []
    for text in r._ax.texts:
        if text.get_animated() or not text.get_text():
            continue
        ext = text.get_window_extent(renderer)
        if text.get_bbox_patch() is not None:  # the white box around it
            ext = text.get_bbox_patch().get_window_extent(renderer)
        c0, c1, r0, r1 = ext.x0, ext.x1, r.height_px - ext.y1, r.height_px - ext.y0
        if c0 < box[0] - 0.5 or r0 < box[1] - 0.5 or c1 > box[2] + 0.5 or r1 > box[3] + 0.5:
            bad.append(text.get_text())
    return bad


@pytest.mark.parametrize("size", [(3, 30), (40, 3), (2, 2), (20, 20), (100, 1)],
                         ids=["tall", "wide", "small", "square", "corridor"])
@pytest.mark.parametrize("width", [200, 480, 800, 1600])
def test_legend_and_texts_lie_inside_the_frame(size: tuple[int, int], width: int):
    world = StaticWorld.build(OccupancyGrid.empty(*size, 0.1))
    r = FrameRenderer(world, width_px=width, legend=True, title=LONG_TITLE)
    frame = r.render(_state(), Overlay(text="t = 123.4 s   step 1234   collision"))
    assert frame.shape == (r.height_px, width, 3) and r.height_px % 2 == 0
    c0, r0, c1, r1 = r.legend_box
    assert 0 <= c0 < c1 <= width and 0 <= r0 < r1 <= r.height_px
    assert _texts_inside(r, (0, 0, width, r.height_px)) == []
    legend_texts = {*(r._ax.texts[i].get_text() for i in range(len(r._ax.texts)))} & {
        "robot", "people", *style.AGENT_STATE_NAMES}
    assert len(legend_texts) == 2 + len(style.AGENT_STATE_NAMES)
    # the legend's own texts lie in its box
    renderer = r._canvas.get_renderer()
    for text in r._ax.texts:
        if text.get_text() in legend_texts:
            ext = text.get_window_extent(renderer)
            assert c0 <= ext.x0 and ext.x1 <= c1, text.get_text()
            assert r0 <= r.height_px - ext.y1 and r.height_px - ext.y0 <= r1, text.get_text()
    # the map lies left of the legend and inside the frame
    corners = r.world_to_pixel([[0.0, 0.0], [float(size[0]), float(size[1])]])
    assert corners[:, 0].min() >= -1e-6 and corners[:, 0].max() <= c0 + 1e-6
    assert corners[:, 1].min() >= 0 and corners[:, 1].max() <= r.height_px
    # the time line and the title do not overlap
    hud = r._hud.get_bbox_patch().get_window_extent(renderer)
    title = next(t for t in r._ax.texts if t.get_text().startswith("default/"))
    tb = title.get_bbox_patch().get_window_extent(renderer)
    assert hud.x1 <= tb.x0 or tb.y1 <= hud.y0


def test_a_tall_map_is_scaled_to_a_frame_no_taller_than_wide():
    world = StaticWorld.build(OccupancyGrid.empty(3, 30, 0.1))
    r = FrameRenderer(world, width_px=800, legend=["robot"], title="corridor")
    assert r.height_px == 800
    left, right = r.world_to_pixel([[0.0, 15.0], [3.0, 15.0]])[:, 0]
    # centred in the map area left of the legend (its box lies 4 px inside that area)
    assert left == pytest.approx(r.legend_box[0] - 4.0 - right, abs=1.0)
    assert FrameRenderer(world, width_px=400, max_height_px=1200).height_px == 1200


def test_too_narrow_a_frame_for_the_legend_is_a_one_line_error():
    world = StaticWorld.build(OccupancyGrid.empty(4, 4, 0.1))
    with pytest.raises(ConfigError, match=r"width_px 120 is too narrow for a legend of 16 entries"):
        FrameRenderer(world, width_px=120, legend=True)
    with pytest.raises(ConfigError, match=r"max_height_px must lie in \[16, 8000\]"):
        FrameRenderer(world, max_height_px=4)


def test_a_long_title_is_shortened_to_fit():
    world = StaticWorld.build(OccupancyGrid.empty(4, 4, 0.1))
    r = FrameRenderer(world, width_px=200, title="a very long title " * 6)
    assert r.title.endswith("\u2026") and len(r.title) < 60
    assert _texts_inside(r, (0, 0, 200, r.height_px)) == []


def test_scans_robots_and_people_never_cover_the_legend():
    world = StaticWorld.build(OccupancyGrid.empty(4, 4, 0.1))
    r = FrameRenderer(world, lidar_specs=[SPEC], width_px=400, legend=["robot", "lidar"])
    c0, r0, c1, r1 = (round(v) for v in r.legend_box)
    plain = r.render(_state(xy=(-50.0, -50.0), scan=1.0))
    # a 30 m scan from the map's right edge reaches far into the legend column
    busy = r.render(_state(step=1, xy=(3.9, 0.5), scan=30.0, people=(1,)))
    assert np.array_equal(busy[r0:r1, c0:c1], plain[r0:r1, c0:c1])
    assert not np.array_equal(busy[:, : c0 - 1], plain[:, : c0 - 1])


def test_the_scale_bar_sits_above_the_legend_where_it_fits():
    renderer_of = {
        size: FrameRenderer(StaticWorld.build(OccupancyGrid.empty(*size, 0.1)), width_px=800,
                            legend=["robot", "goal", "walking"])
        for size in [(20, 20), (40, 3)]
    }
    for size, r in renderer_of.items():
        label = next(t for t in r._ax.texts if t.get_text().endswith(" m"))
        ext = label.get_window_extent(r._canvas.get_renderer())
        right_of_map = r.world_to_pixel([[float(size[0]), 0.0]])[0, 0]
        if size == (20, 20):  # room above the legend: in its column, off the map
            assert ext.x0 >= right_of_map and r.height_px - ext.y0 <= r.legend_box[1]
        else:  # a wide map's frame is no taller than the legend: the bottom-left corner
            assert ext.x1 < r.legend_box[0] and r.height_px - ext.y0 > r.legend_box[1]
