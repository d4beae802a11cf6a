"""A small scene and its frames for the ROS message and bridge tests (two robots by default)."""

from __future__ import annotations

import numpy as np

from arena.live.frame import LiveFrame, LiveScene, circle_polygon
from arena.maps.grid import OccupancyGrid
from arena.scene.state import AgentStates
from arena.sensors.spec import LidarSpec

LASER = LidarSpec(angle_min=-1.0, angle_max=1.0, num_beams=5, range_max=8.0,
                  mount=(0.2, 0.0, 0.0))
REAR = LidarSpec(angle_min=-0.5, angle_max=0.5, num_beams=3, range_max=4.0, update_rate=5.0,
                 mount=(-0.3, 0.1, np.pi))


def sample_scene(robots: int = 2) -> LiveScene:
    data = np.zeros((4, 6), dtype=np.int8)
    data[0, :] = 100
    lidars = ({"laser": LASER, "rear": REAR}, {"laser": LASER})[:robots]
    return LiveScene(
        episode=0, label="", map_name="m", dt=0.1, time_limit=10.0,
        grid=OccupancyGrid(data, 0.5, (-1.0, 2.0)), obstacles=(),
        robot_names=tuple(f"r{i}" for i in range(robots)),
        robot_models=("jackal",) * robots, footprints=(circle_polygon(0.3),) * robots,
        lidar=LASER, lidars=lidars, primary_lidars=("laser",) * robots)


def sample_frame(step: int, robots: int = 2) -> LiveFrame:
    people = AgentStates(
        ids=np.array([4, 9]), positions=np.array([[1.0, 2.0], [3.0, -1.5]]),
        velocities=np.array([[0.5, 0.0], [0.0, -1.25]]), headings=np.array([0.0, -1.5]),
        radii=np.array([0.3, 0.25]), kinds=np.array([0, 2]), states=np.array([0, 1]))
    poses = np.array([[1.0 + step, 2.0, 0.5], [-3.0, 1.0, np.pi / 2]])[:robots]
    scans = ({"laser": np.full(5, 3.0 + step), "rear": np.full(3, 1.0 + step)},
             {"laser": np.full(5, 7.0)})[:robots]
    return LiveFrame(
        time=0.1 * step, step=step, poses=poses, twists=np.zeros((robots, 3)),
        goal=np.array([5.0, 5.0, 0.0]), plan=np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 1.0]]),
        local_path=np.zeros((0, 2)), subgoal=None, scan=scans[0]["laser"],
        scan_points=np.zeros((0, 2)), people=people, groups=np.array([-1, -1]),
        collision=np.zeros(robots, dtype=bool), commands=np.full((robots, 3), 0.25),
        lidar_scans=scans)
