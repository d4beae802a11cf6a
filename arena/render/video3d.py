"""3-D frames of an episode: the MuJoCo world seen by an overview or a chase camera.

:class:`Video3D` builds the episode's 3-D world once (:class:`~arena.sim.mujoco.sim.MjWorld`:
walls, obstacle models, robot bodies, human figures), then per recorded
:class:`~arena.scene.state.SimState` places the robots and people (legs swinging with the
distance walked) and renders a colour frame through the same
:class:`~arena.sim.mujoco.camera.RgbdCamera` the ``rgbd`` sensor uses. It needs only the
recorded states, so any episode (native2d or mujoco) can be filmed in 3-D after it ran.

What a frame shows:

* each person's torso and arms in the colour of their social state (the 2-D frames' palette,
  :data:`arena.render.style.AGENT_STATE_COLORS`: idle grey, walking orange, running red ...;
  the figure's size tells adults, elders and children apart);
* a robot in contact in the collision red of the 2-D frames;
* a text line (time, step, outcome at the end) at the top left.

Cameras: ``overview`` looks at the whole map from above at 55° from its south side, fixed;
``chase`` follows robot 0 from 3.5 m behind (closer where a wall or obstacle is nearer
behind it, so it never films a wall's outside) and 2.6 m above (over 2 m walls), its heading
smoothed over about a second so that turning on the spot does not whip the picture around.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw, ImageFont

from arena.core.types import wrap_angle_scalar
from arena.render import style
from arena.scene.episode import Episode
from arena.scene.state import SimState
from arena.sensors.spec3d import RgbdSpec
from arena.sim.mujoco.camera import RgbdCamera
from arena.sim.mujoco.scene import WorldParams
from arena.sim.mujoco.sim import MjWorld

Camera3D = Literal["overview", "chase"]

CHASE_BACK = 3.5
"""m behind robot 0 (chase camera)."""
CHASE_HEIGHT = 2.6
"""m above the floor (chase camera; above the default 2 m walls)."""
CHASE_PITCH = 0.6
"""rad the chase camera looks down."""
OVERVIEW_PITCH = math.radians(55.0)
"""rad the overview camera looks down."""
FOVY = 60.0
"""deg, vertical field of view of both cameras."""
YAW_SMOOTHING = 0.25
"""Share of the heading change the chase camera follows per frame (at 5 frames/s ~ 1 s)."""
_COLLISION_RGBA = (*style.COLLISION, 1.0)
_STATIC_GROUPS = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)  # walls, obstacles (not people)


class Video3D:
    """Frames of one episode's 3-D world (see the module docstring).

    Args:
        episode: the episode whose world is filmed.
        first: its first recorded state (the people the world holds figures for).
        camera: ``overview`` or ``chase``.
        width: frame width (px).
        height: frame height (px).
        params: how the 3-D world is built (wall height, colours); default: MuJoCo's backend's.

    Raises:
        ConfigError: mujoco missing, no working OpenGL, or a robot without ``height``.
    """

    def __init__(
        self, episode: Episode, first: SimState, camera: Camera3D = "chase", *,
        width: int = 640, height: int = 480, params: WorldParams | None = None,
    ) -> None:
        self.episode = episode
        self.camera = camera
        self.params = params or WorldParams()
        self.width, self.height = int(width), int(height)
        self._world = self._build(first)
        self._yaw: float | None = None
        x0, y0, x1, y1 = self._world.scene.bounds
        self._centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
        self._span = max(x1 - x0, y1 - y0, 1.0)
        far = min(1000.0, 3.0 * self._span + 20.0)
        if camera == "overview":
            # far enough back that the map's larger side fills about 90 % of the view
            dist = 0.55 * self._span / math.tan(math.radians(FOVY) / 2)
            mount = (0.0, 0.0, dist * math.sin(OVERVIEW_PITCH), 0.0, OVERVIEW_PITCH)
            self._overview_pose = np.array(
                [self._centre[0], self._centre[1] - dist * math.cos(OVERVIEW_PITCH), math.pi / 2]
            )
        else:
            mount = (0.0, 0.0, CHASE_HEIGHT, 0.0, CHASE_PITCH)  # placed by _pose
        self.spec = RgbdSpec(width=self.width, height=self.height, fovy=FOVY, near=0.05,
                             far=far, mount=mount)
        self._camera = RgbdCamera(self._world.model, self.spec, segmentation=False)

    def _build(self, state: SimState) -> MjWorld:
        ep = self.episode
        robots = [(r.name, r.model, r.start.as_array()) for r in ep.robots]
        world = MjWorld(ep.grid, ep.obstacles, robots, state.agents, self.params,
                        name=ep.map_name, source=f"map {ep.map_name!r}")
        m = world.model
        # person torso and arms take the social-state colour: their own rgba, not the material
        self._torso: list[NDArray[np.int64]] = []
        for i in range(world.num_people):
            ids = [m.geom(f"person/{i}/{part}").id for part in ("torso", "arm_l", "arm_r")]
            self._torso.append(np.array(ids, dtype=np.int64))
        if self._torso:
            m.geom_matid[np.concatenate(self._torso)] = -1
        # robots in their 2-D colours (robot i's), the collision red while in contact
        self._robot_geoms = [np.flatnonzero(m.geom_bodyid == b) for b in world.robot_body]
        self._robot_rgba = [(*style.robot_color(i), 1.0) for i in range(len(self._robot_geoms))]
        for g in self._robot_geoms:
            m.geom_matid[g] = -1
        return world

    def frame(self, state: SimState, text: str = "") -> NDArray[np.uint8]:
        """The ``(height, width, 3)`` uint8 frame of ``state`` (a new array), with ``text``."""
        if len(state.agents) != self._world.num_people:  # the crowd changed size: new figures
            self._world = self._build(state)
            self._camera.close()
            self._camera = RgbdCamera(self._world.model, self.spec, segmentation=False)
        world, m = self._world, self._world.model
        world.place_robots(np.asarray(state.robots.poses, dtype=np.float64))
        world.place_people(state.agents)
        colours = style.palette(style.AGENT_STATE_COLORS, state.agents.states)
        for ids, rgb in zip(self._torso, colours, strict=True):
            m.geom_rgba[ids] = (*rgb, 1.0)
        hit = np.asarray(state.collisions.any, dtype=bool).reshape(-1)
        for k, (g, rgba) in enumerate(zip(self._robot_geoms, self._robot_rgba, strict=True)):
            m.geom_rgba[g] = _COLLISION_RGBA if k < hit.size and hit[k] else rgba
        world.forward()
        rgb = self._camera.render(world.data, self._pose(state)).rgb
        return _annotate(rgb, text)

    def _pose(self, state: SimState) -> NDArray[np.float64]:
        """The camera's base pose: fixed (overview) or robot 0 with a smoothed heading."""
        if self.camera == "overview":
            return self._overview_pose
        x, y, yaw = (float(v) for v in state.robots.poses[0])
        if self._yaw is None or state.step == 0:
            self._yaw = yaw
        else:
            self._yaw += YAW_SMOOTHING * wrap_angle_scalar(yaw - self._yaw)
        # behind the robot, but never behind a wall: cast a ray backwards at 1 m height and
        # stop 0.3 m before what it hits (else the camera films the wall's outside)
        back = np.array([-math.cos(self._yaw), -math.sin(self._yaw), 0.0])
        world = self._world
        mj = world._mj
        geom = np.zeros(1, dtype=np.int32)
        hit = mj.mj_ray(world.model, world.data, np.array([x, y, 1.0]), back, _STATIC_GROUPS, 1,
                        int(world.robot_body[0]), geom)
        dist = CHASE_BACK if hit < 0 else min(CHASE_BACK, max(hit - 0.3, 0.0))
        # look down more when close, so that the robot stays in the lower third of the view
        below = math.atan2(CHASE_HEIGHT, max(dist, 1e-3))
        pitch = max(CHASE_PITCH, below - math.radians(FOVY) / 6)
        self._camera.remount((0.0, 0.0, CHASE_HEIGHT, 0.0, pitch))
        return np.array([x + dist * back[0], y + dist * back[1], self._yaw])

    def close(self) -> None:
        """Free the camera's GL context."""
        self._camera.close()


def _annotate(rgb: NDArray[np.uint8], text: str) -> NDArray[np.uint8]:
    """``rgb`` with ``text`` in a box at the top left."""
    if not text:
        return rgb
    img = Image.fromarray(rgb)
    draw = ImageDraw.Draw(img)
    font = ImageFont.load_default(size=max(12, rgb.shape[0] // 30))
    x0, y0, x1, y1 = draw.textbbox((10, 8), text, font=font)
    draw.rectangle((x0 - 5, y0 - 4, x1 + 5, y1 + 4), fill=(255, 255, 255))
    draw.text((10, 8), text, fill=(20, 20, 20), font=font)
    return np.asarray(img, dtype=np.uint8).copy()


def write_video_3d(
    episode: Episode, states: Sequence[SimState], texts: Sequence[str], path: str,
    *, camera: Camera3D, width: int, height: int, fps: float,
    params: WorldParams | None = None,
) -> NDArray[np.uint8]:
    """Render ``states`` (with their ``texts``) to the video ``path``; the last frame."""
    from arena.render.video import VideoWriter

    video = Video3D(episode, states[0], camera, width=width, height=height, params=params)
    frame = np.zeros((height, width, 3), dtype=np.uint8)
    try:
        with VideoWriter(path, fps=fps) as writer:
            for state, text in zip(states, texts, strict=True):
                frame = video.frame(state, text)
                writer.append(frame)
    finally:
        video.close()
    return frame
