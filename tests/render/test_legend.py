import numpy as np

from arena.crowd.state import SocialState
from arena.maps.grid import OccupancyGrid
from arena.render import FrameRenderer, style
from arena.sim.state import AgentStates, Collisions, RobotStates, SimState, StaticWorld


def test_state_names_match_social_state_codes():
    assert tuple(s.name.lower() for s in SocialState) == style.AGENT_STATE_NAMES
    assert len(style.AGENT_STATE_COLORS) >= len(SocialState)
    # Distinct colours for every state.
    assert len(set(style.AGENT_STATE_COLORS[: len(SocialState)])) == len(SocialState)


def _state():
    robots = RobotStates(("r",), ("burger",), np.array([[2.0, 2.0, 0.0]]), np.zeros((1, 3)),
                         np.zeros((1, 3)), np.array([0.2]), (None,), (np.zeros(0),))
    return SimState(0.0, 0, robots, AgentStates.empty(), Collisions.none(1))


def test_legend_is_drawn_bottom_right_beside_the_map():
    world = StaticWorld.build(OccupancyGrid.empty(10, 10, 0.1))
    plain_r = FrameRenderer(world, width_px=400)
    legend_r = FrameRenderer(world, width_px=400, legend=True)
    plain, legend = plain_r.render(_state()), legend_r.render(_state())
    h, w, _ = legend.shape
    assert legend.shape[1] == plain.shape[1] == 400
    corner = (slice(h - h // 4, h), slice(w - w // 6, w))
    # The walking colour appears in the legend.
    walk = (np.array(style.AGENT_STATE_COLORS[SocialState.WALKING]) * 255).round()
    assert np.any(np.all(np.abs(legend[corner].astype(int) - walk) < 6, axis=-1))
    # The map ends left of the legend column: its right edge maps inside the frame, short of it.
    right = legend_r.world_to_pixel([[10.0, 0.0]])[0, 0]
    assert right < w - 40
    assert legend_r.scale < plain_r.scale


def test_legend_fits_a_long_narrow_map():
    # 30 m x 3 m: the frame grows to hold the legend and the title strip.
    world = StaticWorld.build(OccupancyGrid.empty(30, 3, 0.1))
    r = FrameRenderer(world, width_px=480, legend=True, title="corridor")
    frame = r.render(_state())
    assert frame.shape[0] > 3 * r.scale  # taller than the map alone
    # Every map corner lies inside the frame and left of the legend column.
    px = r.world_to_pixel([[0.0, 0.0], [30.0, 3.0]])
    assert px[:, 0].min() >= 0 and px[:, 0].max() < 480 - 40
    assert px[:, 1].min() >= 0 and px[:, 1].max() <= frame.shape[0]
