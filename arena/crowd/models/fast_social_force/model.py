"""``fast_social_force``: a simplified Helbing social force that moves its pedestrians itself.

Born as the batched RL environment's crowd, now an ordinary crowd model usable everywhere
(``crowd: {type: fast_social_force}`` in ``arena run``, ``arena bench``, the environments), so a
policy can be trained and evaluated on the same crowd. Acceleration of pedestrian ``a``::

    (vmax·e_goal − v)/τ                              goal attraction
    + Σ_b A_p·exp((r_a + r_b − d)/B_p)·n_ba           other pedestrians within ``cutoff``
    + Σ_j A_r·exp((r_a + R_j − d)/B_r)·n_ja           each robot, a circle of radius R_j
    + A_w·exp((r_a − d_w)/B_w)·∇d_w                   walls, from the map's distance transform
    + Σ_s A_w·exp((r_a − d_s)/B_w)·n_s                obstacle edges within ``cutoff``

then semi-implicit Euler with the speed capped at ``max_speed_factor·vmax``. A move that would
put the centre on a blocking cell (or off the map), or bring the body deeper into a wall it
already touches, is cancelled (the pedestrian stops), so nobody walks into a wall. Within
``goal_radius`` of its waypoint a pedestrian takes the next one (loop mode), or any other one
drawn from a table of uniforms refilled from the crowd's generator (random mode).

It is fast because it is a whole :class:`~arena.sim.backend.PedestrianDriver` of its own, one
compiled kernel per step, not a model inside :class:`~arena.crowd.simulator.CrowdSimulator`.
What that leaves out, on purpose: no social states (everyone is always walking:
``SocialState.WALKING``), no groups, no start-up modes (everyone walks from t = 0), no per-kind
speed profiles (elders walk at their own ``vmax``); of the ``pedestrians:`` block
it reads nothing (a warning says so when social states or groups are asked for).
"""

from __future__ import annotations

import functools
import warnings
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS
from arena.crowd.models.fast_social_force.kernels import edge_run_boxes, step_crowd
from arena.crowd.models.fast_social_force.params import FastSocialForceParams
from arena.crowd.state import CrowdState, StartupMode
from arena.maps.distance import grid_memo
from arena.scene.state import AgentStates, RobotStates, StaticWorld

if TYPE_CHECKING:
    from arena.crowd.simulator import PedestrianConfig
    from arena.maps.grid import OccupancyGrid
    from arena.scene.episode import AgentSpawn

#: Uniforms for random waypoint choices drawn at a time; redrawn once half are used.
RAND_TABLE = 256


@CROWD_MODELS.register("fast_social_force", tags=("fast",))
class FastSocialForceModel:
    """Simplified Helbing social force, one kernel per step (no social states, groups)."""

    Params = FastSocialForceParams

    def __init__(self, params: FastSocialForceParams | None = None) -> None:
        self.params = params or FastSocialForceParams()

    def make_driver(self, pedestrians: PedestrianConfig | None = None) -> FastSocialForceDriver:
        """The driver that moves an episode's pedestrians (see the module docstring).

        Args:
            pedestrians: the config's ``pedestrians:`` block; none of it applies, and a warning
                names the parts asked for that are ignored.
        """
        if pedestrians is not None:
            asked = [
                f"pedestrians.{name}"
                for name, on in (
                    ("social_states", pedestrians.social_states),
                    ("group_fraction", pedestrians.group_fraction > 0),
                )
                if on
            ]
            if asked:
                warn_once(
                    f"crowd 'fast_social_force' has no social states and no groups: "
                    f"{' and '.join(asked)} ignored"
                )
        return FastSocialForceDriver(self.params)


@functools.cache
def warn_once(text: str) -> None:
    """Warn with ``text`` once per process (a run builds a driver per episode)."""
    warnings.warn(text, UserWarning, stacklevel=3)


class FastSocialForceDriver:
    """Moves one world's pedestrians with :func:`.kernels.step_crowd`; a ``PedestrianDriver``.

    Args:
        params: the model's parameters.
    """

    def __init__(self, params: FastSocialForceParams | None = None) -> None:
        self.params = params or FastSocialForceParams()
        self._prm = self.params.as_array()
        self._state: CrowdState | None = None

    @property
    def state(self) -> CrowdState:
        """The crowd (read it, do not modify it); ``vmax · vmax_factor`` is the speed cap."""
        if self._state is None:
            raise RuntimeError("FastSocialForceDriver used before reset()")
        return self._state

    def reset(self, spawn: AgentSpawn, world: StaticWorld, rng: np.random.Generator) -> AgentStates:
        """Place the episode's pedestrians at rest, walking to their first waypoints.

        Groups and start-up modes of the spawn are ignored (everyone walks alone, at once; a
        warning says so once).
        """
        ignored = [
            what
            for what, given in (
                ("groups", spawn.groups is not None and bool(np.any(spawn.groups >= 0))),
                ("start-up modes",
                 spawn.startup_mode is not None and bool(np.any(spawn.startup_mode != 0))),
            )
            if given
        ]
        if ignored:
            warn_once(
                f"crowd 'fast_social_force' has no groups and no start-up modes: the episode's "
                f"pedestrian {' and '.join(ignored)} ignored"
            )
        s = CrowdState.from_spawn(spawn)
        n = len(s)
        s.vmax_factor = np.full(n, self.params.max_speed_factor)
        s.startup_mode = np.full(n, int(StartupMode.DEFAULT), dtype=np.int64)
        s.started = np.ones(n, dtype=bool)
        s.group = np.full(n, -1, dtype=np.int64)
        s.leader = np.arange(n, dtype=np.int64)
        self._state = s
        self._rng = rng
        grid = world.grid
        self._distg = grid_memo(grid, "fast social force distance", lambda: _cell_distance(grid))
        self._res = float(grid.resolution)
        self._gx0, self._gy0 = float(grid.origin[0]), float(grid.origin[1])
        self._seg_a = np.ascontiguousarray(world.segments_a, dtype=np.float64)
        self._seg_b = np.ascontiguousarray(world.segments_b, dtype=np.float64)
        self._run_box = edge_run_boxes(self._seg_a, self._seg_b)
        self._rand = rng.random(RAND_TABLE)
        self._rand_k = 0
        return self._snapshot()

    def step(self, robots: RobotStates, dt: float) -> AgentStates:
        """Advance the pedestrians by ``dt`` s, seeing every robot as a circle of its radius."""
        s = self.state
        if len(s):
            out_pos = np.empty_like(s.positions)
            out_vel = np.empty_like(s.velocities)
            out_dest = np.empty_like(s.destinations)
            self._rand_k = step_crowd(
                s.positions, s.velocities, s.headings, s.radii, s.vmax, s.waypoints,
                s.num_waypoints, s.waypoint_mode, s.waypoint_index, self._rand, self._rand_k,
                self._distg, self._res, self._gx0, self._gy0, self._seg_a, self._seg_b,
                self._run_box, np.ascontiguousarray(robots.poses[:, :2]),
                np.ascontiguousarray(robots.radii, dtype=np.float64), self._prm, float(dt),
                out_pos, out_vel, out_dest,
            )
            s.positions, s.velocities, s.destinations = out_pos, out_vel, out_dest
            if self._rand_k > RAND_TABLE // 2:
                self._rand = self._rng.random(RAND_TABLE)
                self._rand_k = 0
        s.time += dt
        return self._snapshot()

    def _snapshot(self) -> AgentStates:
        s = self.state
        return AgentStates(
            ids=s.ids.copy(),
            positions=s.positions.copy(),
            velocities=s.velocities.copy(),
            headings=s.headings.copy(),
            radii=s.radii.copy(),
            kinds=s.kinds.copy(),
            states=s.social_state.copy(),
        )


def _cell_distance(grid: OccupancyGrid) -> NDArray[np.float32]:
    """The map's distance transform in cells, float32, capped (as the lidar binds it), frozen."""
    cap = float(grid.width + grid.height + 4)
    d = np.minimum(np.asarray(grid.distance) / grid.resolution, cap).astype(np.float32)
    d.setflags(write=False)
    return d
