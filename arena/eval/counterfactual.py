"""The counterfactual crowd: an episode's pedestrians replayed without the robot.

How much did the robot disturb the people? Proximity metrics (minimum distance, personal-space
time) say how close it came, not what it changed. Here the episode is simulated a second time
with the same map, obstacles, pedestrian spawn, crowd model and random stream, but without any
robot, for the same number of steps; the difference between where each person actually was and
where they would have been is the robot's effect on them (metrics ``cf_*`` in
:mod:`arena.eval.metrics.social`).

Exact replay needs the crowd's random draws to be independent of the robot's sensors: every
backend splits its generator with :func:`~arena.sim.backend.split_rng` and gives the
pedestrians their own stream, which :func:`replay_crowd` re-creates. With a crowd model that
ignores robots, the counterfactual equals the recorded crowd exactly (tested).

What the robot changes besides the people's paths is included on purpose: pedestrians whose
start is triggered by a nearby robot (scenario ``start_zone``) never start in the replay.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from arena.crowd.driver import build_driver
from arena.scene.state import RobotStates, StaticWorld
from arena.sim.backend import split_rng

if TYPE_CHECKING:
    from arena.crowd.simulator import PedestrianConfig
    from arena.scene.episode import Episode

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True, eq=False)
class CrowdTrack:
    """Pedestrian positions per step, long format (``K`` rows).

    Attributes:
        row: ``(K,)`` step index (0 = the state after reset).
        ids: ``(K,)`` pedestrian id.
        positions: ``(K, 2)`` m.
    """

    row: IntArray
    ids: IntArray
    positions: FloatArray


def no_robots() -> RobotStates:
    """An empty :class:`~arena.scene.state.RobotStates` (what the crowd sees in the replay)."""
    return RobotStates(
        names=(), models=(), poses=np.zeros((0, 3)), twists=np.zeros((0, 3)),
        commands=np.zeros((0, 3)), radii=np.zeros(0), footprints=(), scans=(),
    )


def replay_crowd(
    crowd_config: dict[str, Any],
    pedestrian_config: PedestrianConfig,
    episode: Episode,
    steps: int,
    dt: float,
    rng: np.random.Generator,
) -> CrowdTrack:
    """Simulate the episode's pedestrians alone for ``steps`` steps of ``dt`` s.

    Args:
        crowd_config: the experiment's ``crowd`` block (model type and parameters).
        pedestrian_config: the experiment's ``pedestrians`` block
            (:class:`~arena.crowd.simulator.PedestrianConfig`).
        episode: the :class:`~arena.scene.episode.Episode` as it was run.
        steps: number of steps after reset (the record has ``steps + 1`` rows).
        dt: s, the simulation step.
        rng: the generator the backend's ``reset`` received for this episode (it is split the
            same way, so the crowd gets the same stream).

    Returns:
        The positions of every pedestrian at rows ``0 … steps``.
    """
    crowd = build_driver(crowd_config, pedestrian_config)
    crowd_rng, _ = split_rng(rng)
    world = StaticWorld.build(episode.grid, episode.obstacles)
    agents = crowd.reset(episode.agents, world, crowd_rng)
    robots = no_robots()
    rows, ids, pos = [], [], []
    for k in range(steps + 1):
        if k:
            agents = crowd.step(robots, dt)
        n = len(agents)
        rows.append(np.full(n, k, dtype=np.int64))
        ids.append(np.asarray(agents.ids, dtype=np.int64))
        pos.append(np.asarray(agents.positions, dtype=np.float64).reshape(n, 2))
    return CrowdTrack(np.concatenate(rows), np.concatenate(ids), np.concatenate(pos))


def align(row: IntArray, ids: IntArray, track: CrowdTrack) -> FloatArray:
    """The counterfactual position of each recorded pedestrian row.

    Args:
        row: ``(K,)`` step of each recorded pedestrian row (``EpisodeRecord.ped_row``).
        ids: ``(K,)`` pedestrian id of each row (``EpisodeRecord.ped_id``).
        track: the replay.

    Returns:
        ``(K, 2)`` m; NaN where the replay has no pedestrian with that id at that step.
    """
    out = np.full((row.shape[0], 2), np.nan)
    if not row.size or not track.row.size:
        return out
    lo = int(min(ids.min(), track.ids.min()))
    span = int(max(ids.max(), track.ids.max())) - lo + 1
    key = track.row * span + (track.ids - lo)
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    want = row * span + (ids - lo)
    at = np.clip(np.searchsorted(sorted_key, want), 0, sorted_key.size - 1)
    hit = sorted_key[at] == want
    out[hit] = track.positions[order[at[hit]]]
    return out
