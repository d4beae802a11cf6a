"""Hand-made contact cases with known answers, one per kind of body and of contact.

Coordinates are binary fractions (resolution 0.5 m) so that "exactly touching" is exact.
"""

import math

import numpy as np
import pytest

from arena.core.geometry import rectangle
from arena.maps.grid import OccupancyGrid
from arena.scene.state import Obstacle, StaticWorld
from arena.sim.contacts import (
    ContactBank,
    Footprint,
    ObstacleIndex,
    first_agent_hit,
    first_obstacle_hit,
    footprints_overlap,
    hits_grid,
)

TRIANGLE = np.array([[0.5, 0.0], [-0.25, 0.25], [-0.25, -0.25]])


def one_cell_grid(row: int = 4, col: int = 4) -> OccupancyGrid:
    """10 × 10 cells of 0.5 m; cell (row, col) blocks, spanning [0.5 col, 0.5 col + 0.5] in x."""
    occ = np.zeros((10, 10), dtype=bool)
    occ[row, col] = True
    return OccupancyGrid.from_occupied(occ, 0.5)


def pose(x: float, y: float, th: float = 0.0) -> np.ndarray:
    return np.array([x, y, th])


@pytest.mark.parametrize(
    ("x", "hit"),
    [(1.75, False), (1.76, True), (1.5, False)],  # cell spans x [2.0, 2.5]; 1.75 touches
)
def test_circle_against_a_cell_touching_does_not_count(x, hit):
    assert hits_grid(one_cell_grid(), Footprint.make(None, 0.25), pose(x, 2.25)) is hit


@pytest.mark.parametrize(
    ("p", "hit"),
    [
        (pose(1.5, 2.25), False),  # right edge at x = 2.0: touches the cell
        (pose(1.51, 2.25), True),
        (pose(1.7, 2.25, math.pi / 2), False),  # turned: half length 0.25 along x
        (pose(1.8, 2.25, math.pi / 2), True),
    ],
)
def test_rectangle_against_a_cell(p, hit):
    fp = Footprint.make(rectangle(1.0, 0.5), 0.0)
    assert hits_grid(one_cell_grid(), fp, p) is hit


def test_rectangle_is_exact_where_its_bounding_circle_would_hit():
    """A 1.0 × 0.6 m box at (1.1, 1.1) clears the cell at [1.5, 2] × [1.5, 2] by 0.1 m in y."""
    grid = one_cell_grid(3, 3)
    box = Footprint.make(rectangle(1.0, 0.6), 0.0)
    assert box.radius == pytest.approx(math.hypot(0.5, 0.3))
    assert not hits_grid(grid, box, pose(1.1, 1.1))
    assert hits_grid(grid, Footprint.make(None, box.radius), pose(1.1, 1.1))
    assert hits_grid(grid, box, pose(1.1, 1.25))  # now its top edge reaches y = 1.55


def test_triangle_tip_reaches_the_cell_only_when_it_points_there():
    grid = one_cell_grid()  # cell x [2.0, 2.5], y [2.0, 2.5]
    tri = Footprint.make(TRIANGLE, 0.0)
    assert hits_grid(grid, tri, pose(1.6, 2.25))  # tip at x = 2.1
    assert not hits_grid(grid, tri, pose(1.6, 2.25, math.pi))  # tip away, back at x = 1.85


def test_off_map_counts_for_a_real_overhang_only():
    grid = OccupancyGrid.from_occupied(np.zeros((10, 10), dtype=bool), 0.5)  # [0, 5] m square
    box = Footprint.make(rectangle(1.0, 0.5), 0.0)
    assert not hits_grid(grid, box, pose(0.5, 2.0))  # left edge exactly on the border
    assert hits_grid(grid, box, pose(0.49, 2.0))
    assert not hits_grid(grid, box, pose(0.5, 2.0, math.pi / 2))  # turned: x [0.25, 0.75]
    assert hits_grid(grid, box, pose(0.2, 2.0, math.pi / 2))
    assert hits_grid(grid, Footprint.make(None, 0.3), pose(0.25, 2.0))
    assert hits_grid(grid, Footprint.make(None, 0.3), pose(-0.1, 2.0))  # centre off the map


def obstacle_world() -> StaticWorld:
    grid = OccupancyGrid.from_occupied(np.zeros((20, 20), dtype=bool), 0.5)
    obs = (
        Obstacle("a", "box", pose(2.0, 2.0), rectangle(1.0, 1.0)),  # [1.5, 2.5]²
        Obstacle("b", "box", pose(6.0, 2.0), rectangle(1.0, 1.0)),  # [5.5, 6.5] × [1.5, 2.5]
    )
    return StaticWorld.build(grid, obs)


def test_obstacles_touching_counts_and_the_first_index_is_reported():
    index = ObstacleIndex.build(obstacle_world())
    circle = Footprint.make(None, 0.5)
    assert first_obstacle_hit(index, circle, pose(3.0, 2.0)) == 0  # touches the edge x = 2.5
    assert first_obstacle_hit(index, circle, pose(3.01, 2.0)) == -1
    assert first_obstacle_hit(index, circle, pose(5.0, 2.0)) == 1
    box = Footprint.make(rectangle(3.0, 0.5), 0.0)  # x [2.5, 5.5]: touches both edges
    assert first_obstacle_hit(index, box, pose(4.0, 2.0)) == 0
    assert first_obstacle_hit(index, box, pose(4.25, 2.0)) == 1
    assert first_obstacle_hit(index, Footprint.make(rectangle(2.5, 0.5), 0.0), pose(4.0, 2.0)) == -1
    long_box = Footprint.make(rectangle(4.0, 0.5), 0.0)  # x [2, 6]: overlaps both
    assert first_obstacle_hit(index, long_box, pose(4.0, 2.0)) == 0
    assert first_obstacle_hit(index, Footprint.make(None, 0.2), pose(2.0, 2.0)) == 0  # inside


def test_agent_nearest_overlapping_circle_wins():
    box = Footprint.make(rectangle(1.0, 0.5), 0.0)
    pos = np.array([[0.8, 0.0], [0.0, 0.45], [0.0, 2.0]])
    radii = np.array([0.35, 0.25, 0.3])
    # agent 0 reaches x 0.45 < 0.5 (overlaps), agent 1 reaches y 0.2 < 0.25, nearer: 1 wins
    assert first_agent_hit(box, pose(0.0, 0.0), pos, radii) == 1
    assert first_agent_hit(box, pose(0.0, -0.1), pos, radii) == 0  # agent 1 now 0.55 away
    # a circle footprint: strict overlap (touching at 0.75 m does not count)
    one, r = np.array([[0.75, 0.0]]), np.array([0.25])
    assert first_agent_hit(Footprint.make(None, 0.5), pose(0.0, 0.0), one, r) == -1
    assert first_agent_hit(Footprint.make(None, 0.5), pose(0.01, 0.0), one, r) == 0


def test_robots_overlap_on_their_real_footprints():
    box = Footprint.make(rectangle(1.0, 0.5), 0.0)
    circle = Footprint.make(None, 0.25)
    assert footprints_overlap(box, pose(0.0, 0.0), box, pose(1.0, 0.0))  # edges touch
    assert not footprints_overlap(box, pose(0.0, 0.0), box, pose(1.01, 0.0))
    assert not footprints_overlap(box, pose(0.0, 0.0), box, pose(0.0, 0.6, 0.0))
    assert footprints_overlap(box, pose(0.0, 0.0), box, pose(0.0, 0.6, math.pi / 2))
    # the circle misses the box's corner although their bounding circles overlap
    assert math.hypot(0.63, 0.475) < box.radius + circle.radius
    assert not footprints_overlap(box, pose(0.0, 0.0), circle, pose(0.63, 0.475))
    assert footprints_overlap(circle, pose(0.7, 0.25), box, pose(0.0, 0.0))
    assert footprints_overlap(circle, pose(0.0, 0.0), circle, pose(0.49, 0.0))
    assert not footprints_overlap(circle, pose(0.0, 0.0), circle, pose(0.5, 0.0))


def test_the_sweep_catches_a_step_through_a_one_cell_wall():
    occ = np.zeros((40, 40), dtype=bool)
    occ[:, 10] = True  # x in [1.0, 1.1] at 0.1 m cells
    world = StaticWorld.build(OccupancyGrid.from_occupied(occ, 0.1))
    bank = ContactBank()
    bank.bind_world(0, world)
    circle = Footprint.make(None, 0.05)
    bank.set_robots(np.array([0]), [circle])
    before, after = np.array([[0.7, 2.0, 0.0]]), np.array([[1.4, 2.0, 0.0]])
    no_agents = (np.array([0, 0]), np.zeros((0, 2)), np.zeros(0))
    assert not hits_grid(world.grid, circle, after[0])
    assert not bank.test(after, None, *no_agents)[0][0]
    assert bank.test(after, before, *no_agents)[0][0]
    # a short step ends where it ends: nothing on the way
    assert not bank.test(np.array([[0.9, 2.0, 0.0]]), before, *no_agents)[0][0]
