"""Scenes and helpers shared by ``test_pysocial.py`` and ``test_pysocial_behaviour.py``."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from arena.crowd.base import CrowdFrame, RobotView
from arena.crowd.models.pysocial.model import PySocialModel
from arena.crowd.neighbors import find_neighbors
from arena.crowd.state import CrowdState
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import AgentSpawn
from arena.scene.state import Obstacle, StaticWorld

# The model with nothing but the force terms: no cutoff, no robot, forces unscaled.
EXACT = {"cutoff": math.inf, "robot_factor": 0.0, "force_scale": 1.0}


# -- scenes ---------------------------------------------------------------------------------------
def box(name: str, x: float, y: float, theta: float, half_w: float, half_h: float) -> Obstacle:
    """A rotated rectangular obstacle (its four edges are obstacle lines)."""
    fp = np.array([[-half_w, -half_h], [half_w, -half_h], [half_w, half_h], [-half_w, half_h]])
    return Obstacle(name, "cuboid", np.array([x, y, theta]), fp)


def make_state(
    pos: np.ndarray,
    vel: np.ndarray,
    *,
    vmax: np.ndarray | float = 1.2,
    groups: np.ndarray | None = None,
    radii: float = 0.3,
) -> CrowdState:
    """A crowd at ``pos`` with velocities ``vel`` (waypoints are irrelevant to the model)."""
    n = len(pos)
    spawn = AgentSpawn(
        positions=np.asarray(pos, dtype=np.float64),
        radii=np.full(n, radii),
        vmax=np.broadcast_to(np.asarray(vmax, dtype=np.float64), (n,)).copy(),
        waypoints=np.asarray(pos, dtype=np.float64)[:, None, :].copy(),
        num_waypoints=np.ones(n, dtype=np.int64),
        waypoint_mode=np.zeros(n, dtype=np.int64),
        kinds=np.zeros(n, dtype=np.int64),
        groups=None if groups is None else np.asarray(groups, dtype=np.int64),
    )
    state = CrowdState.from_spawn(spawn)
    state.velocities = np.array(vel, dtype=np.float64).reshape(n, 2)
    return state


def random_scene(
    seed: int, n: int, *, size: tuple[float, float] = (16.0, 12.0), min_side: float = 0.3
) -> tuple[StaticWorld, CrowdState, np.ndarray]:
    """A walled room with rotated boxes and a long thin wall; ``n`` agents, groups of 2-4."""
    rng = np.random.default_rng(seed)
    w, h = size
    obstacles = [
        box(
            f"b{k}",
            *rng.uniform([3, 3], [w - 3, h - 3]),
            rng.uniform(-3, 3),
            *rng.uniform(min_side / 2, 1.0, 2),
        )
        for k in range(3)
    ]
    obstacles.append(box("wall", w / 2, h / 2, rng.uniform(-3, 3), 3.0, min_side / 2))
    world = StaticWorld.build(OccupancyGrid.empty(w, h, 0.1), tuple(obstacles))
    pos = rng.uniform([0.4, 0.4], [w - 0.4, h - 0.4], (n, 2))
    groups = np.full(n, -1)
    order = rng.permutation(n)
    i = gid = 0
    while i < n:  # random runs of 1-4 agents; runs of 2+ are groups
        k = int(rng.integers(1, 5))
        if k > 1 and i + 1 < n:
            groups[order[i : i + k]] = gid
            gid += 1
        i += k
    state = make_state(
        pos, rng.normal(0.0, 0.8, (n, 2)), vmax=rng.uniform(0.5, 1.8, n), groups=groups
    )
    state.vmax_factor = rng.choice([0.5, 1.0, 2.0], n)
    dest = rng.uniform([1, 1], [w - 1, h - 1], (n, 2))
    near = rng.choice(n, 3, replace=False)  # some inside the goal threshold (brake branch)
    dest[near] = pos[near] + rng.uniform(-0.1, 0.1, (3, 2))
    return world, state, dest


def make_frame(
    state: CrowdState,
    dest: np.ndarray,
    *,
    active: np.ndarray | None = None,
    robots: RobotView | None = None,
    search: float = math.inf,
) -> CrowdFrame:
    """The frame the simulator would build (neighbours found within ``search``)."""
    n = len(state)
    return CrowdFrame(
        state=state,
        destinations=np.asarray(dest, dtype=np.float64),
        active=np.ones(n, dtype=bool) if active is None else np.asarray(active, dtype=bool),
        robots=robots or RobotView.empty(),
        walls_a=np.zeros((0, 2)),
        walls_b=np.zeros((0, 2)),
        neighbors=find_neighbors(state.positions, search),
        dt=0.1,
        rng=np.random.default_rng(0),
    )


def ours(world: StaticWorld | None, frame: CrowdFrame, **params: Any) -> Any:
    """Our model's output for ``frame`` (``world`` None: no obstacles)."""
    model = PySocialModel(PySocialModel.Params(**params))
    if world is not None:
        model.reset(frame.state, world, np.random.default_rng(0))
    return model.compute(frame)
