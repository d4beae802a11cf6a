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


def test_legend_is_drawn_bottom_right():
    world = StaticWorld.build(OccupancyGrid.empty(10, 10, 0.1))
    robots = RobotStates(("r",), ("burger",), np.array([[2.0, 2.0, 0.0]]), np.zeros((1, 3)),
                         np.zeros((1, 3)), np.array([0.2]), (None,), (np.zeros(0),))
    state = SimState(0.0, 0, robots, AgentStates.empty(), Collisions.none(1))
    plain = FrameRenderer(world, width_px=400).render(state)
    legend = FrameRenderer(world, width_px=400, legend=True).render(state)
    h, w, _ = plain.shape
    corner = (slice(h - h // 4, h), slice(w - w // 4, w))
    assert not np.array_equal(plain[corner], legend[corner])
    top_left = (slice(0, h // 2), slice(0, w // 2))
    assert np.array_equal(plain[top_left], legend[top_left])
    # The walking colour appears in the legend.
    walk = (np.array(style.AGENT_STATE_COLORS[SocialState.WALKING]) * 255).round()
    assert np.any(np.all(np.abs(legend[corner].astype(int) - walk) < 6, axis=-1))
