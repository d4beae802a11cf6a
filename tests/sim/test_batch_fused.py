"""BatchSim.step (one fused kernel per step) equals its stages called one by one, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from arena.maps.grid import OccupancyGrid
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.sim.batch import BatchSim
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator


@pytest.fixture(scope="module")
def episodes(tmp_path_factory: pytest.TempPathFactory) -> list[Episode]:
    """Six 10 x 10 m episodes with a wall, obstacles and 8 pedestrians (random waypoints)."""
    from arena.maps.io import save_map

    occ = np.zeros((200, 200), dtype=bool)
    occ[:2, :] = occ[-2:, :] = occ[:, :2] = occ[:, -2:] = True
    occ[100:104, 0:120] = True
    path = tmp_path_factory.mktemp("maps") / "m.yaml"
    save_map(OccupancyGrid.from_occupied(occ, 0.05), path)
    task = TaskConfig(
        robots={"type": "random", "min_goal_distance": 2.0, "clearance": 1.0},
        obstacles={"type": "random", "static": 3, "dynamic": 8},
    )
    gen = TaskGenerator(
        task, map_spec={"type": "file", "path": str(path)}, robots=[load_robot("jackal")], seed=5
    )
    return [gen.episode(i) for i in range(6)]


def _staged_step(sim: BatchSim, cmd: np.ndarray, dt: float) -> None:
    """The step as the separate stage kernels compute it (the order step() documents)."""
    sim._crowd(dt)
    new_p, new_t, new_s = sim._kinematics(cmd, dt)
    old = sim._poses
    sim._poses = new_p
    sim._contacts(sweep=True, previous=old)
    if sim.params.collision_response == "stop":
        blocked = sim._wall | (sim._obstacle >= 0) | (sim._agent >= 0)
        new_p[blocked] = old[blocked]
        new_t[blocked] = 0.0
        new_s[blocked] = sim._steer[blocked]
    sim._twists, sim._steer = new_t, new_s
    sim._time += dt
    sim._step += 1
    sim._scan(sim._time - sim._last_scan >= 1.0 / sim.lidar_spec.update_rate - 1e-9)


@pytest.mark.parametrize(
    ("pedestrians", "response", "parallel_min_worlds", "chunk"),
    [
        ("social_force", "stop", 1, 1),
        ("social_force", "stop", 1, 0),
        ("social_force", "record", 100, 1),
        ("static", "stop", 1, 1),
    ],
)
def test_fused_step_equals_stages(
    episodes: list[Episode], pedestrians: str, response: str, parallel_min_worlds: int,
    chunk: int,
) -> None:
    params = BatchSim.Params(
        pedestrians=pedestrians, collision_response=response,
        parallel_min_worlds=parallel_min_worlds, parallel_chunksize=chunk,
    )
    fused = BatchSim(len(episodes), params)
    staged = BatchSim(len(episodes), params)
    fused.reset(episodes, np.random.default_rng(4))
    staged.reset(episodes, np.random.default_rng(4))
    rng = np.random.default_rng(8)
    # Pedestrians 0 and 1 of world 0 start on one spot: the coincident-pair branch.
    for sim in (fused, staged):
        sim._pos[0, 1] = sim._pos[0, 0]
    for _ in range(60):
        cmd = np.zeros((len(episodes), 3))
        cmd[:, 0] = rng.uniform(-0.5, 2.0, len(episodes))  # fast enough to hit things
        cmd[:, 2] = rng.uniform(-2.0, 2.0, len(episodes))
        s = fused.step(cmd, 0.1)
        _staged_step(staged, cmd, 0.1)
        ref = staged._snapshot()
        for name in ("poses", "twists", "scans", "collision_kind", "obstacle", "agent",
                     "ped_positions", "ped_velocities", "ped_headings", "time", "step"):
            np.testing.assert_array_equal(getattr(s, name), getattr(ref, name), err_msg=name)
        np.testing.assert_array_equal(fused._wp_idx, staged._wp_idx)
        np.testing.assert_array_equal(fused._rand_k, staged._rand_k)
    assert fused._step[0] == 60
