"""RGB-D camera frames/s (and 3-D lidar scans/s) in a MuJoCo world, on one core.

    python benchmarks/mujoco_render.py [--seconds 3] [--width 320 --height 240] [--cpu 0]

The world: a 20 x 20 m map with walls around and two interior walls with doors, 10 library
obstacles, 20 walking people (legs swinging, moved every frame) and a jackal. A camera on the
jackal drives a loop through the room, so every frame differs. Printed: frames/s of
:class:`~arena.sim.mujoco.camera.RgbdCamera` with colour + depth only (one render pass) and with
per-pixel person ids (two passes); for reference, MuJoCo's stock ``mujoco.Renderer`` taking
colour and depth of the same view in two passes (with its default 4x multisampling); and
scans/s of a 16 x 1800 beam :class:`~arena.sim.mujoco.lidar3d.Lidar3D`. The process is pinned
to one core and llvmpipe (Mesa's software GL) rasterises in the calling thread
(``LP_NUM_THREADS=0`` unless set).
Goal (issue 19): >= 40 RGB-D frames/s at 320 x 240 on one core.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np


def world(mj):
    """``(model, data, people)`` of the benchmark world (``mj``: the mujoco module)."""
    from arena.maps.grid import OccupancyGrid
    from arena.maps.obstacles import make_obstacle
    from arena.robots.presets import load_robot
    from arena.scene.episode import AgentSpawn
    from arena.sim.mujoco.mjcf import compile_model
    from arena.sim.mujoco.world import build_world

    n = 200
    occ = np.zeros((n, n), dtype=bool)
    occ[[0, -1], :] = occ[:, [0, -1]] = True
    for k in (70, 140):  # interior walls with a 2 m door each
        occ[k : k + 3, :] = True
        occ[k : k + 3, 90:110] = False
    grid = OccupancyGrid.from_occupied(occ, 0.1)
    rng = np.random.default_rng(0)
    kinds = ["table", "chair", "shelf", "office_desk", "tree", "office_chair", "pallet",
             "warehouse_shelf", "separator", "cylinder"]
    spots = [(3, 3), (16, 3), (4, 10), (16, 11), (3, 17), (9, 17), (15, 16), (12, 5), (6, 5),
             (17, 8)]
    obstacles = [make_obstacle(f"o{i}", k, [x, y, rng.uniform(-3, 3)])
                 for i, (k, (x, y)) in enumerate(zip(kinds, spots, strict=True))]
    m = 20
    pos = rng.uniform(2, 18, (m, 2))
    agents = AgentSpawn(pos, np.full(m, 0.3), np.full(m, 1.2), pos[:, None] + 1.0,
                        np.ones(m, np.int64), np.zeros(m, np.int64), rng.integers(0, 2, m))
    jackal = load_robot("jackal")
    model = compile_model(build_world(grid, obstacles, robots=[("jackal", jackal, [10, 3, 0])],
                                      agents=agents))
    data = mj.MjData(model)
    mj.mj_forward(model, data)
    return model, data, agents


def rate(fn: Callable[[int], object], seconds: float) -> float:
    """Calls of ``fn(k)`` per second over about ``seconds`` (after one warm-up call)."""
    fn(0)
    k, t0 = 1, time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        fn(k)
        k += 1
    return (k - 1) / (time.perf_counter() - t0)


def main() -> None:
    """Time the camera and the lidar."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--cpu", type=int, default=0, help="the core to pin to")
    args = ap.parse_args()
    os.sched_setaffinity(0, {args.cpu})
    os.environ.setdefault("LP_NUM_THREADS", "0")  # before the first GL context

    from arena.sensors.spec3d import Lidar3DSpec, RgbdSpec
    from arena.sim.mujoco.camera import RgbdCamera, camera_pose
    from arena.sim.mujoco.figures import pose_figures
    from arena.sim.mujoco.lidar3d import Lidar3D
    from arena.sim.mujoco.mjcf import import_mujoco

    mj = import_mujoco()
    model, data, agents = world(mj)
    m = len(agents)
    mocap = np.array([[model.body(f"person/{i}{s}").mocapid[0] for s in ("", "/leg_l", "/leg_r")]
                      for i in range(m)])
    robot = model.body("robot/jackal")
    heading = np.random.default_rng(1).uniform(-np.pi, np.pi, m)

    def step(k: int) -> np.ndarray:
        """Move the people and the jackal to frame ``k``; the jackal's pose."""
        t = 0.05 * k
        xy = agents.positions + 0.5 * np.stack([np.cos(heading), np.sin(heading)], 1) * np.sin(t)
        p, q = pose_figures(xy, heading, np.full(m, 1.2 * t), np.full(m, 1.2), agents.kinds)
        data.mocap_pos[mocap], data.mocap_quat[mocap] = p, q
        a = 0.3 * t
        # an ellipse through the middle room (y 7.3 .. 14 m), facing the way it drives
        pose = np.array([10 + 7 * np.cos(a), 10.6 + 2.5 * np.sin(a),
                         np.arctan2(2.5 * np.cos(a), -7 * np.sin(a))])
        data.mocap_pos[robot.mocapid[0]] = (pose[0], pose[1], 0.0)
        data.mocap_quat[robot.mocapid[0]] = (np.cos(pose[2] / 2), 0, 0, np.sin(pose[2] / 2))
        mj.mj_forward(model, data)
        return pose

    spec = RgbdSpec(width=args.width, height=args.height, fovy=58.0,
                    mount=(0.2, 0.0, 0.45, 0.0, 0.1))
    print(f"world: {model.ngeom} geoms (walls, 10 obstacles, 20 people, a jackal); "
          f"{args.width} x {args.height} px, pinned to core {args.cpu}, "
          f"LP_NUM_THREADS={os.environ['LP_NUM_THREADS']}")
    step_rate = rate(step, args.seconds)
    print(f"  {'moving the people and the robot + mj_forward':60} {step_rate:8.1f} /s")
    for seg in (False, True):
        cam = RgbdCamera(model, spec, segmentation=seg)
        if not seg:
            from OpenGL import GL

            print(f"  GL: {GL.glGetString(GL.GL_RENDERER).decode()}")
        fps = rate(lambda k, c=cam: c.render(data, step(k)), args.seconds)
        what = "colour + depth + person ids (2 passes)" if seg else "colour + depth (1 pass)"
        print(f"  {'RgbdCamera ' + what:60} {fps:8.1f} frames/s (step included)")
        cam.close()
    stock = mj.Renderer(model, args.height, args.width)
    free = mj.MjvCamera()

    free.type = mj.mjtCamera.mjCAMERA_FREE

    def two_pass(k: int) -> None:
        pos, forward, _ = camera_pose(spec, step(k))  # the same view as the RgbdCamera's
        free.lookat[:], free.distance = pos + forward, 1.0
        free.azimuth = np.degrees(np.arctan2(forward[1], forward[0]))
        free.elevation = -np.degrees(spec.mount[4])
        stock.update_scene(data, free)
        stock.disable_depth_rendering()
        stock.render()
        stock.enable_depth_rendering()
        stock.render()

    label = "mujoco.Renderer colour, then depth (2 passes, 4x MSAA)"
    print(f"  {label:60} {rate(two_pass, args.seconds):8.1f} frames/s (reference)")
    stock.close()
    lidar = Lidar3D(Lidar3DSpec(rings=16, num_beams=1800, range_max=30.0,
                                mount=(0.0, 0.0, 0.4, 0.0)))
    scans = rate(lambda k: lidar.scan(model, data, step(k), robot.id), args.seconds)
    print(f"  {'Lidar3D 16 x 1800 beams (mj_multiRay)':60} {scans:8.1f} scans/s (step included)")
    print(f"  {'3-D video frame 640 x 480 (chase, 20 people)':60} {video_rate(args.seconds):8.1f} "
          "frames/s")
    print("goal: >= 40 RGB-D frames/s at 320 x 240 on one core")


def video_rate(seconds: float) -> float:
    """Frames/s of :class:`~arena.render.video3d.Video3D` over a recorded native2d episode."""
    from arena.core.rng import derive_rng
    from arena.crowd.driver import build_driver
    from arena.render.video3d import Video3D
    from arena.robots.presets import load_robot
    from arena.sim.native2d import Native2DBackend
    from arena.tasks.config import TaskConfig
    from arena.tasks.generator import TaskGenerator

    task = TaskConfig(robots={"type": "random", "min_goal_distance": 6.0},
                      obstacles={"type": "random", "static": 10, "dynamic": 20})
    ep = TaskGenerator(task, map_spec={"type": "empty", "width": 20, "height": 20},
                       robots=[load_robot("jackal")], seed=0).episode(0)
    backend = Native2DBackend()
    states = [backend.reset(ep, build_driver({"type": "pysocial"}, {}), derive_rng(0, "v"))]
    for _ in range(60):
        states.append(backend.step(np.array([[0.5, 0.0, 0.2]]), 0.1))
    video = Video3D(ep, states[0], "chase", width=640, height=480)
    try:
        return rate(lambda k: video.frame(states[k % len(states)], "t"), seconds)
    finally:
        video.close()


if __name__ == "__main__":
    main()
