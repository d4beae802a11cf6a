import math

import numpy as np
import pytest

from arena.core.errors import SimulationError
from arena.core.geometry import rectangle
from arena.crowd.models.walker import WaypointWalker
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig
from arena.maps.grid import OccupancyGrid
from arena.robots.presets import load_robot
from arena.scene.state import Obstacle
from arena.sim.contacts import Footprint, hits_grid
from arena.sim.native2d import Native2DBackend
from tests.conftest import make_episode, standing_agents

DT = 0.1


def walker():
    return CrowdSimulator(WaypointWalker(), PedestrianConfig(social_states=False, group_fraction=0))


def drive(backend, cmd, steps, dt=DT):
    states = []
    for _ in range(steps):
        states.append(backend.step(np.atleast_2d(np.asarray(cmd, dtype=float)), dt))
    return states


def test_reset_snapshot_shapes(room):
    jackal = load_robot("jackal")
    ep = make_episode(
        room, [(jackal, (2, 5, 0), (8, 5, 0))], agents=standing_agents([[5, 8], [6, 2]])
    )
    b = Native2DBackend()
    s = b.reset(ep, None, np.random.default_rng(0))
    assert s.time == 0.0 and s.step == 0
    assert s.robots.poses.shape == (1, 3)
    assert s.robots.scans[0].shape == (jackal.laser.num_beams,)
    assert len(s.agents) == 2
    assert not s.collisions.any[0]
    assert s.robots.footprints[0] is not None  # the jackal is a rectangle


def test_straight_drive_follows_kinematics(room):
    burger = load_robot("burger")
    b = Native2DBackend()
    b.reset(make_episode(room, [(burger, (2, 5, 0), (8, 5, 0))]), None, np.random.default_rng(0))
    states = drive(b, [0.22, 0, 0], 50)
    poses = np.array([s.robots.poses[0] for s in states])
    assert np.all(np.diff(poses[:, 0]) >= 0)
    assert np.allclose(poses[:, 1], 5.0) and np.allclose(poses[:, 2], 0.0)
    assert states[-1].robots.twists[0, 0] == pytest.approx(0.22)
    assert states[-1].time == pytest.approx(5.0)


def test_wall_stops_robot_and_is_reported(room):
    burger = load_robot("burger")
    b = Native2DBackend()
    b.reset(make_episode(room, [(burger, (9.0, 5, 0), (1, 5, 0))]), None, np.random.default_rng(0))
    states = drive(b, [0.22, 0, 0], 60)
    hits = [s.collisions.wall[0] for s in states]
    assert any(hits)
    fp = Footprint.make(burger.footprint_polygon(), burger.circumscribed_radius)
    # With collision_response=stop the robot is never left overlapping the wall.
    for s in states:
        assert not hits_grid(room, fp, s.robots.poses[0])
    assert states[-1].robots.twists[0, 0] == 0.0


def test_fast_robot_cannot_tunnel_through_thin_wall():
    occ = np.zeros((200, 200), dtype=bool)
    occ[:, 100] = True  # a single-cell wall at x = 5.0 .. 5.05
    grid = OccupancyGrid.from_occupied(occ, 0.05)
    rto = load_robot("rto")
    b = Native2DBackend()
    b.reset(make_episode(grid, [(rto, (3.0, 5, 0), (8, 5, 0))]), None, np.random.default_rng(0))
    states = drive(b, [2.78, 0, 0], 30, dt=0.5)  # 1.39 m per step
    assert any(s.collisions.wall[0] for s in states)
    assert all(s.robots.poses[0, 0] < 5.0 for s in states)


def test_polygon_footprint_is_exact_near_walls(room):
    # A jackal (0.42 x 0.33 m) parallel to a wall: its circumscribed circle would touch the wall,
    # the rectangle does not.
    jackal = load_robot("jackal")
    half_width = 0.33 / 2
    y = 10.0 - 0.05 - half_width - 0.02  # 2 cm from the top wall
    b = Native2DBackend()
    s = b.reset(
        make_episode(room, [(jackal, (5, y, 0), (1, 1, 0))]), None, np.random.default_rng(0)
    )
    assert jackal.circumscribed_radius > half_width + 0.02
    assert not s.collisions.wall[0]
    # Turned by 90 degrees the long side points at the wall: collision.
    s = b.reset(
        make_episode(room, [(jackal, (5, y, math.pi / 2), (1, 1, 0))]),
        None,
        np.random.default_rng(0),
    )
    assert s.collisions.wall[0]


def test_obstacle_agent_and_robot_contacts(room):
    burger = load_robot("burger")
    box = Obstacle("box", "cuboid", np.array([3.0, 5.0, 0.3]), rectangle(0.6, 0.6))
    ep = make_episode(
        room,
        [
            (burger, (2.45, 5, 0), (9, 5, 0)),
            (burger, (5, 2.0, 0), (5, 9, 0)),
            (burger, (5, 2.2, 0), (5, 9, 0)),
        ],
        obstacles=[box],
        agents=standing_agents([[7.0, 7.0], [7.3, 7.1]]),
    )
    b = Native2DBackend()
    s = b.reset(ep, None, np.random.default_rng(0))
    assert s.collisions.obstacle.tolist() == [-1, -1, -1]
    assert s.collisions.robot.tolist() == [-1, 2, 1]
    states = drive(b, np.array([[0.22, 0, 0], [0, 0, 0], [0, 0, 0]]), 20)
    assert any(s.collisions.obstacle[0] == 0 for s in states)
    assert all(s.robots.poses[0, 0] < 2.7 for s in states)  # held in front of the box
    # Put a robot on a pedestrian.
    ep2 = make_episode(
        room, [(burger, (7.1, 7.0, 0), (1, 1, 0))], agents=standing_agents([[7.0, 7.0], [2.0, 2.0]])
    )
    s = b.reset(ep2, None, np.random.default_rng(0))
    assert s.collisions.agent[0] == 0


def test_record_response_passes_through(room):
    burger = load_robot("burger")
    box = Obstacle("box", "cuboid", np.array([3.0, 5.0, 0.0]), rectangle(0.3, 2.0))
    b = Native2DBackend(Native2DBackend.Params(collision_response="record"))
    b.reset(
        make_episode(room, [(burger, (2.5, 5, 0), (9, 5, 0))], obstacles=[box]),
        None,
        np.random.default_rng(0),
    )
    states = drive(b, [0.22, 0, 0], 60)
    assert any(s.collisions.obstacle[0] == 0 for s in states)
    assert states[-1].robots.poses[0, 0] > 3.5


def test_lidar_sees_pedestrian_exactly(room):
    jackal = load_robot("jackal")
    ep = make_episode(
        room, [(jackal, (3.0, 5.0, 0.0), (9, 5, 0))], agents=standing_agents([[5.0, 5.0]], 0.3)
    )
    b = Native2DBackend()
    s = b.reset(ep, None, np.random.default_rng(0))
    angles = jackal.laser.angles() + jackal.laser.mount[2]
    k = int(np.argmin(np.abs(angles)))
    mount_x = jackal.laser.mount[0]
    expected = 2.0 - 0.3 - mount_x
    if abs(angles[k]) < 1e-9:
        assert s.robots.scans[0][k] == pytest.approx(expected, abs=1e-6)
    assert s.robots.scans[0].min() == pytest.approx(expected, abs=0.01)
    blind = Native2DBackend(Native2DBackend.Params(pedestrians_block_lidar=False))
    s2 = blind.reset(ep, None, np.random.default_rng(0))
    assert s2.robots.scans[0].min() > expected + 1.0


def test_pedestrians_move_with_driver(room):
    burger = load_robot("burger")
    agents = standing_agents([[5.0, 8.0]])
    agents = type(agents)(
        positions=agents.positions,
        radii=agents.radii,
        vmax=np.array([1.0]),
        waypoints=np.array([[[8.0, 8.0]]]),
        num_waypoints=agents.num_waypoints,
        waypoint_mode=agents.waypoint_mode,
        kinds=agents.kinds,
    )
    b = Native2DBackend()
    b.reset(
        make_episode(room, [(burger, (2, 2, 0), (3, 3, 0))], agents=agents),
        walker(),
        np.random.default_rng(0),
    )
    s = drive(b, [0, 0, 0], 30)[-1]
    assert s.agents.positions[0, 0] > 6.0
    assert np.linalg.norm(s.agents.velocities[0]) <= 1.0 + 1e-9


def test_determinism_with_noise(room):
    buddy = load_robot("buddy")  # has lidar noise
    assert buddy.laser.noise_std > 0
    ep = make_episode(room, [(buddy, (3, 5, 0), (8, 5, 0))], agents=standing_agents([[6, 5]]))

    def rollout():
        b = Native2DBackend()
        b.reset(ep, walker(), np.random.default_rng(42))
        return drive(b, [0.3, 0.1, 0.2], 20)

    a, c = rollout(), rollout()
    for sa, sc in zip(a, c, strict=True):
        assert np.array_equal(sa.robots.poses, sc.robots.poses)
        assert np.array_equal(sa.robots.scans[0], sc.robots.scans[0])
    assert not np.array_equal(a[0].robots.scans[0], a[1].robots.scans[0])  # noise is drawn


def test_bad_usage_raises(room):
    b = Native2DBackend()
    with pytest.raises(SimulationError, match="before reset"):
        b.step(np.zeros((1, 3)), 0.1)
    with pytest.raises(SimulationError):
        _ = b.world
    b.reset(
        make_episode(room, [(load_robot("burger"), (2, 2, 0), (3, 3, 0))]),
        None,
        np.random.default_rng(0),
    )
    with pytest.raises(SimulationError, match="shape"):
        b.step(np.zeros(3), 0.1)
    with pytest.raises(SimulationError, match="finite"):
        b.step(np.array([[np.nan, 0, 0]]), 0.1)
    with pytest.raises(SimulationError, match="dt"):
        b.step(np.zeros((1, 3)), 0.0)


def test_snapshots_are_not_mutated_later(room):
    b = Native2DBackend()
    b.reset(
        make_episode(room, [(load_robot("burger"), (2, 5, 0), (8, 5, 0))]),
        None,
        np.random.default_rng(0),
    )
    s1 = b.step(np.array([[0.2, 0, 0]]), DT)
    kept = s1.robots.poses.copy()
    b.step(np.array([[0.2, 0, 0]]), DT)
    assert np.array_equal(s1.robots.poses, kept)


def test_lidar_sees_two_legs(room):
    jackal = load_robot("jackal")
    ep = make_episode(
        room, [(jackal, (3.0, 5.0, 0.0), (9, 5, 0))], agents=standing_agents([[6.0, 5.0]], 0.3)
    )
    legs = Native2DBackend(Native2DBackend.Params(pedestrian_body="legs"))
    s = legs.reset(ep, None, np.random.default_rng(0))
    body = Native2DBackend().reset(ep, None, np.random.default_rng(0))
    scan_legs, scan_body = s.robots.scans[0], body.robots.scans[0]
    angles = jackal.laser.angles() + jackal.laser.mount[2]
    mount = jackal.laser.mount[0]
    # Standing pedestrian facing +x (heading 0): legs at y = 5 ± 0.1, x = 6, radius 0.07.
    k = int(np.argmin(np.abs(angles)))
    assert abs(angles[k]) < 0.01
    # The beam straight ahead passes between the legs (gap 0.2 - 2·0.07 = 6 cm) and hits the wall.
    assert scan_legs[k] > 6.0 - mount
    assert scan_body[k] == pytest.approx(3.0 - 0.3 - mount, abs=0.01)
    hits = np.abs(scan_legs - (3.0 - 0.07 - mount)) < 0.05
    assert hits.sum() >= 2  # both legs are seen
    # Contacts still use the body circle.
    assert not s.collisions.any[0]


def test_footprints_are_reused_across_resets(room):
    """The same robot model keeps its prepared footprint; another model gets its own."""
    jackal, burger = load_robot("jackal"), load_robot("burger")
    b = Native2DBackend()
    b.reset(make_episode(room, [(jackal, (2, 5, 0), (8, 5, 0))]), None, np.random.default_rng(0))
    first = b.engine.footprints[0]
    want = Footprint.make(jackal.footprint_polygon(), jackal.circumscribed_radius)
    assert first.polygon.tobytes() == want.polygon.tobytes() and first.radius == want.radius
    b.reset(make_episode(room, [(jackal, (3, 5, 0), (8, 5, 0))]), None, np.random.default_rng(1))
    assert b.engine.footprints[0] is first
    b.reset(make_episode(room, [(burger, (3, 5, 0), (8, 5, 0))]), None, np.random.default_rng(1))
    other = Footprint.make(burger.footprint_polygon(), burger.circumscribed_radius)
    got = b.engine.footprints[0]
    assert got is not first and got.radius == other.radius
    assert (got.polygon is None) == (other.polygon is None)
