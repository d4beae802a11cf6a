"""One episode's compiled MuJoCo world: :class:`MjWorld`, what the backend's stages and banks share.

Built from the episode's map, obstacles and robots (:func:`~arena.sim.mujoco.world.build_world`)
and the pedestrians as the crowd driver placed them, compiled once. Robots are bodies with a
free joint (MuJoCo filters contacts between bodies without degrees of freedom, so a mocap
robot would never touch a wall): their ``qpos`` is written directly and only kinematics and
collision detection run (no ``mj_step``, gravity plays no part). People are mocap bodies
posed by :func:`~arena.sim.mujoco.figures.pose_figures`. The floor is a visual plane only
(its contact bits are cleared: every body stands on it).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.scene.state import AgentStates, Obstacle
from arena.sim.mujoco.figures import figure_bodies, pose_figures
from arena.sim.mujoco.mjcf import compile_model, import_mujoco
from arena.sim.mujoco.scene import Body, WorldParams
from arena.sim.mujoco.world import RobotPlacement, build_world

if TYPE_CHECKING:
    from arena.maps.grid import OccupancyGrid

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
B1 = NDArray[np.bool_]

NOTHING, WALL, OBSTACLE, PERSON, ROBOT = range(5)
"""What a geom belongs to (:attr:`MjWorld.geom_kind`)."""

HIGH_Z = 0.5
"""m: geoms whose lowest point is above this height (table tops, the people's upper bodies)
are in :data:`HIGH_GROUP`; a horizontal scan plane below it leaves them out of its ray cast."""

HIGH_GROUP = 1
"""Geom group of the geoms entirely above :data:`HIGH_Z` (when people are seen: theirs too)."""

PERSON_GROUP = 2
"""Geom group of the people's geoms below :data:`HIGH_Z` (their legs); when the lidar does not
see people, of all their geoms. Groups 0-2 are all visible in MuJoCo's default render options."""


class MjWorld:
    """A compiled episode world and its index maps.

    Attributes:
        model: the ``mujoco.MjModel``.
        data: its ``mujoco.MjData`` (poses of the latest :meth:`place_robots` /
            :meth:`place_people`, after :meth:`forward`).
        robot_body: ``(R,)`` MuJoCo body id of each robot row.
        robot_height: ``(R,)`` m, each robot body's height.
        num_people: pedestrians the world has figures for.
        geom_kind: ``(ngeom,)`` :data:`WALL`, :data:`OBSTACLE`, :data:`PERSON`, :data:`ROBOT`
            or :data:`NOTHING` (the floor).
        geom_index: ``(ngeom,)`` the obstacle index (into the episode's obstacles), pedestrian
            index (agent row) or robot row of the geom; ``-1`` for walls and the floor.
        person_of_geom: ``(ngeom,)`` pedestrian index of person geoms, ``-1`` elsewhere (the
            per-pixel person ids of a camera).
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        obstacles: Sequence[Obstacle],
        robots: Sequence[RobotPlacement],
        agents: AgentStates,
        params: WorldParams,
        *,
        name: str = "arena",
        source: str = "map",
        people_in_lidar: bool = True,
    ) -> None:
        mujoco = import_mujoco()
        self._mj = mujoco
        scene = build_world(grid, obstacles, robots=robots, params=params, name=name,
                            source=source)
        people: list[Body] = []
        for i in range(len(agents)):
            x, y = (float(v) for v in agents.positions[i])
            people += figure_bodies(i, int(agents.kinds[i]), x, y, float(agents.headings[i]))
        scene = replace(
            scene,
            robots=tuple(replace(b, mocap=False, free=True) for b in scene.robots),
            people=tuple(people),
        )
        self.scene = scene
        self.model = model = compile_model(scene)
        self.data = mujoco.MjData(model)
        floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
        if floor >= 0:  # visual only: everything stands on it
            model.geom_contype[floor] = 0
            model.geom_conaffinity[floor] = 0
        body_kind = np.zeros(model.nbody, dtype=np.int64)
        body_index = np.full(model.nbody, -1, dtype=np.int64)
        for k, body in enumerate(scene.static):
            b = model.body(body.name).id
            if body.kind == "wall":
                body_kind[b] = WALL
            else:  # the obstacles, in the episode's order after the walls
                body_kind[b], body_index[b] = OBSTACLE, k - 1
        self.robot_body = np.array([model.body(b.name).id for b in scene.robots], dtype=np.int64)
        body_kind[self.robot_body] = ROBOT
        body_index[self.robot_body] = np.arange(len(self.robot_body))
        self.robot_height = np.array([m.height for _, m, _ in robots], dtype=np.float64)
        self._qpos = np.array(
            [model.jnt_qposadr[model.body_jntadr[b]] for b in self.robot_body], dtype=np.int64
        )
        self.num_people = n = len(agents)
        mocap = np.zeros((n, 3), dtype=np.int64)
        for i in range(n):
            for j, part in enumerate(("", "/leg_l", "/leg_r")):
                b = model.body(f"person/{i}{part}").id
                mocap[i, j] = model.body_mocapid[b]
                body_kind[b], body_index[b] = PERSON, i
        self.geom_kind = body_kind[model.geom_bodyid]
        self.geom_index = body_index[model.geom_bodyid]
        self.person_of_geom = np.where(self.geom_kind == PERSON, self.geom_index, -1)
        self._mocap = mocap.reshape(-1)
        self._kinds = np.asarray(agents.kinds).copy()
        self._walked = np.zeros(n)
        self._last_xy: F64 | None = None
        # the per-robot qpos block [x, y, z, qw, qx, qy, qz] is written from the poses
        self._qidx = (self._qpos[:, None] + np.arange(7)[None, :]).reshape(-1)
        self._group_geoms(people_in_lidar)

    def _group_geoms(self, people_in_lidar: bool) -> None:
        """Geom groups for the ray casts (:data:`HIGH_GROUP`, :data:`PERSON_GROUP`).

        Heights are taken at the start poses: bodies only turn about z (a leg pitches, but
        hangs from the hip, below it), so a geom's lowest point stays where it is.
        """
        m, d = self.model, self.data
        self.forward()
        bottom = d.geom_xpos[:, 2] + m.geom_aabb[:, 2] - m.geom_aabb[:, 5]
        high = (bottom > HIGH_Z) & (self.geom_kind != ROBOT)
        person = self.geom_kind == PERSON
        m.geom_group[high] = HIGH_GROUP
        m.geom_group[person & (~high | (not people_in_lidar))] = PERSON_GROUP

    # -- placing -------------------------------------------------------------------------------
    def place_robots(self, poses: F64) -> None:
        """Write ``(R, 3)`` robot poses ``[x m, y m, yaw rad]`` into ``qpos`` (no kinematics)."""
        half = 0.5 * poses[:, 2]
        block = np.zeros((poses.shape[0], 7))
        block[:, :2] = poses[:, :2]
        block[:, 3] = np.cos(half)
        block[:, 6] = np.sin(half)
        self.data.qpos[self._qidx] = block.reshape(-1)

    def place_people(self, agents: AgentStates) -> None:
        """Pose the figures at the crowd's positions, legs swinging with the distance walked.

        The gait phase is the distance each person walked since the world was built, summed
        here step by step (the same person, the same phase on every rerun).
        """
        n = self.num_people
        if n == 0:
            return
        xy = agents.positions
        if self._last_xy is not None:
            self._walked = self._walked + np.hypot(*(xy - self._last_xy).T)
        self._last_xy = np.array(xy, dtype=np.float64)
        speed = np.hypot(agents.velocities[:, 0], agents.velocities[:, 1])
        pos, quat = pose_figures(xy, agents.headings, self._walked, speed, self._kinds)
        self.data.mocap_pos[self._mocap] = pos.reshape(-1, 3)
        self.data.mocap_quat[self._mocap] = quat.reshape(-1, 4)

    def forward(self) -> None:
        """Body and geom poses from ``qpos`` and the mocap poses (``mj_kinematics``)."""
        self._mj.mj_kinematics(self.model, self.data)

    # -- contacts ------------------------------------------------------------------------------
    def collide(self) -> tuple[B1, I64, I64, I64]:
        """MuJoCo's contacts at the current poses: ``(wall, obstacle, agent, robot)`` per robot.

        Runs :meth:`forward` and ``mj_collision``. ``(R,)`` each; an index is the smallest one
        the robot touches (``-1``: none). Only contacts with a robot are generated (people and
        the static world are bodies without degrees of freedom).
        """
        mj, m, d = self._mj, self.model, self.data
        mj.mj_kinematics(m, d)
        mj.mj_collision(m, d)
        r = len(self.robot_body)
        wall = np.zeros(r, dtype=bool)
        obstacle = np.full(r, -1, dtype=np.int64)
        agent = np.full(r, -1, dtype=np.int64)
        robot = np.full(r, -1, dtype=np.int64)
        if d.ncon == 0:  # the usual case
            return wall, obstacle, agent, robot
        pairs = d.contact.geom[: d.ncon]
        kind, index = self.geom_kind, self.geom_index
        for g1, g2 in pairs.tolist():
            for mine, other in ((g1, g2), (g2, g1)):
                if kind[mine] != ROBOT:
                    continue
                row, k, j = int(index[mine]), int(kind[other]), int(index[other])
                if k == WALL:
                    wall[row] = True
                elif k == OBSTACLE:
                    obstacle[row] = j if obstacle[row] < 0 else min(int(obstacle[row]), j)
                elif k == PERSON:
                    agent[row] = j if agent[row] < 0 else min(int(agent[row]), j)
                elif k == ROBOT:
                    robot[row] = j if robot[row] < 0 else min(int(robot[row]), j)
        return wall, obstacle, agent, robot

