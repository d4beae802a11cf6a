"""The RGB-D detector's golden frame ``tests/perception/data/rgbd_room.npz``, and its scene.

    python -m tests.perception.rgbd_golden     # writes it again (after a renderer change)

One frame of the training camera (:data:`~arena.perception.rgbd_data.CAMERA`) in a 10 x 6 m
room with a box and three people standing at known spots (:data:`PEOPLE`), rendered by the
MuJoCo backend's camera and shrunk as the detector sees it: the tests run the detector on it
without MuJoCo, and check with MuJoCo that the render still gives this frame.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from arena.maps.grid import OccupancyGrid
from arena.perception.rgbd_data import CAMERA, shrink
from arena.scene.episode import AgentSpawn
from arena.sensors.spec3d import RgbdFrame

GOLDEN = Path(__file__).parent / "data" / "rgbd_room.npz"
POSE = np.array([1.0, 3.0, 0.0])
"""The robot base pose (m, rad): at the left wall, looking along the room."""
PEOPLE = np.array([[4.0, 3.0], [6.0, 1.8], [7.5, 4.3]])
"""Where the people stand (m, world frame)."""
BOX = (5.0, 4.5, 0.6)
"""A 0.6 m cube's centre (x, y) and side (m): furniture the detector must not take for one."""


def render() -> RgbdFrame:
    """The golden scene's frame, rendered now (needs ``arena[3d]`` and a GL library)."""
    from arena.core.geometry import rectangle
    from arena.scene.state import Obstacle
    from arena.sim.mujoco.camera import RgbdCamera
    from arena.sim.mujoco.mjcf import compile_model, import_mujoco
    from arena.sim.mujoco.world import build_world

    n = len(PEOPLE)
    agents = AgentSpawn(PEOPLE.copy(), np.full(n, 0.3), np.ones(n), PEOPLE[:, None, :] + 1.0,
                        np.ones(n, np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64))
    box = Obstacle("box", "cuboid", np.array([BOX[0], BOX[1], 0.0]),
                   rectangle(BOX[2], BOX[2]))
    model = compile_model(build_world(OccupancyGrid.empty(10.0, 6.0, 0.1), (box,),
                                      agents=agents))
    mujoco = import_mujoco()  # the headless GL arena chooses
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    cam = RgbdCamera(model, CAMERA)
    try:
        return cam.render(data, POSE)
    finally:
        cam.close()


def main() -> None:
    """Render, shrink and save."""
    depth, rgb = shrink(render())
    GOLDEN.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(GOLDEN, depth=depth, rgb=np.round(rgb * 255).astype(np.uint8),
                        pose=POSE, people=PEOPLE)
    print(f"wrote {GOLDEN} ({GOLDEN.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
